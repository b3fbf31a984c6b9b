// Bottom-up construction of the per-node LOD data (see lod_bvh.h), YU §3.2 adapted to
// general meshes.
#include "trace/lod_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/error.h"
#include "core/sampling.h"

namespace speculum::trace {

namespace {

struct Sums {
  double area = 0.0;
  glm::dvec3 area_normal{0.0}, area_centroid{0.0}, area_radiance{0.0};
  void add(const Sums& o) {
    area += o.area;
    area_normal += o.area_normal;
    area_centroid += o.area_centroid;
    area_radiance += o.area_radiance;
  }
};

// Points whose projection spans a node's proxy: the corners of its quad, or of its box.
void proxy_points(const LodNode& n, const Aabb& box, std::vector<glm::vec3>& out) {
  if (n.quad) {
    out.push_back(n.origin);
    out.push_back(n.origin + n.edge_u);
    out.push_back(n.origin + n.edge_v);
    out.push_back(n.origin + n.edge_u + n.edge_v);
    return;
  }
  for (int c = 0; c < 8; ++c)
    out.push_back({(c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y,
                   (c & 4) ? box.hi.z : box.lo.z});
}

inline int grid_cell(float x) {
  return std::clamp(static_cast<int>(std::floor(x * kProxyGrid)), 0, kProxyGrid - 1);
}

// The coverage and radiance texture of inner quad proxy k: every triangle of its subtree
// (nodes k .. the end of the subtree, depth-first) projected along the normal onto the quad;
// the texels its projected bounds overlap are marked covered and share its area-weighted
// radiance evenly. Texels no triangle reaches keep the node's mean (never read: the
// traversal passes through them).
void fill_proxy(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance, LodBvh& lod,
                std::uint32_t k) {
  const auto& tn = bvh.threaded_nodes();
  const auto& tris = bvh.leaf_triangles();
  const auto& ids = bvh.triangle_ids();
  LodNode& node = lod.nodes[k];
  const std::uint32_t end = tn[k].miss == kThreadEnd ? static_cast<std::uint32_t>(tn.size()) : tn[k].miss;
  const float uu = glm::dot(node.edge_u, node.edge_u), vv = glm::dot(node.edge_v, node.edge_v);
  constexpr int kTexels = kProxyGrid * kProxyGrid;
  std::array<glm::dvec3, kTexels> sum{};
  std::array<double, kTexels> weight{};
  std::uint64_t coverage = 0;
  for (std::uint32_t j = k; j < end; ++j) {
    const ThreadedNode& leaf = tn[j];
    for (std::uint32_t i = leaf.first; i < leaf.first + leaf.count; ++i) {
      const LeafTriangle& t = tris[i];
      float lo_s = 3e38f, hi_s = -3e38f, lo_t = 3e38f, hi_t = -3e38f;
      for (const glm::vec3& p : {t.a, t.b, t.c}) {
        const glm::vec3 d = p - node.origin;
        const float s = uu > 0.0f ? glm::dot(d, node.edge_u) / uu : 0.5f;
        const float w = vv > 0.0f ? glm::dot(d, node.edge_v) / vv : 0.5f;
        lo_s = std::min(lo_s, s);
        hi_s = std::max(hi_s, s);
        lo_t = std::min(lo_t, w);
        hi_t = std::max(hi_t, w);
      }
      const int x0 = grid_cell(lo_s), x1 = grid_cell(hi_s), y0 = grid_cell(lo_t), y1 = grid_cell(hi_t);
      const double area = 0.5 * glm::length(glm::dvec3(glm::cross(t.b - t.a, t.c - t.a)));
      const double share = area / double((x1 - x0 + 1) * (y1 - y0 + 1));
      const glm::dvec3 radiance(triangle_radiance[ids[i]]);
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const int c = x + kProxyGrid * y;
          coverage |= std::uint64_t(1) << c;
          sum[c] += share * radiance;
          weight[c] += share;
        }
    }
  }
  node.coverage = coverage;
  if (node.texels == kNoTexels) return;
  for (int c = 0; c < kTexels; ++c) {
    lod.proxy_texels[node.texels + c] = weight[c] > 0.0 ? glm::vec3(sum[c] / weight[c]) : node.radiance;
  }
}

// Every inner quad proxy gets its coverage; those over at least kProxyGrid² triangles get a
// texture too (a smaller subtree has fewer triangles than texels: its mean is what a ray
// that stops there can tell apart, and the textures stay a fraction of the mesh's memory).
void build_proxy_textures(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance, LodBvh& lod,
                          par::Executor* executor) {
  const auto& tn = bvh.threaded_nodes();
  std::vector<std::uint32_t> subtree(tn.size(), 0);
  for (std::size_t k = tn.size(); k-- > 0;)
    subtree[k] = tn[k].count ? tn[k].count : subtree[tn[k].hit] + subtree[tn[tn[k].hit].miss];
  std::vector<std::uint32_t> proxies;
  std::size_t textures = 0;
  for (std::size_t k = 0; k < tn.size(); ++k)
    if (tn[k].count == 0 && lod.nodes[k].quad) {
      proxies.push_back(static_cast<std::uint32_t>(k));
      if (subtree[k] >= static_cast<std::uint32_t>(kProxyGrid * kProxyGrid))
        lod.nodes[k].texels = static_cast<std::uint32_t>(textures++ * kProxyGrid * kProxyGrid);
    }
  lod.proxy_texels.assign(textures * kProxyGrid * kProxyGrid, glm::vec3(0.0f));
  const auto fill = [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) fill_proxy(bvh, triangle_radiance, lod, proxies[p]);
  };
  if (executor) executor->parallel_for("lod_build.proxies", proxies.size(), 64, fill);
  else fill(0, proxies.size());
}

}  // namespace

bool LodBvh::proxy_covers(const LodNode& n, float s, float t) {
  return (n.coverage >> (grid_cell(s) + kProxyGrid * grid_cell(t))) & 1u;
}

namespace {

// Bilinear over the covered texels' centres of a textured proxy (weights renormalized over
// them); a covered texel whose bilinear neighbours carry no weight reads itself.
template <class T>
T covered_bilinear(const LodNode& n, const std::vector<T>& texels, float s, float t) {
  // Texel centres sit at (x + ½)/kProxyGrid: the four around (s, t), clamped at the border.
  const float fx = std::clamp(s * kProxyGrid - 0.5f, 0.0f, float(kProxyGrid - 1));
  const float fy = std::clamp(t * kProxyGrid - 0.5f, 0.0f, float(kProxyGrid - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, kProxyGrid - 1), y1 = std::min(y0 + 1, kProxyGrid - 1);
  const float tx = fx - x0, ty = fy - y0;
  T sum{};
  float total = 0.0f;
  const auto tap = [&](int x, int y, float w) {
    const int c = x + kProxyGrid * y;
    if (!((n.coverage >> c) & 1u) || !(w > 0.0f)) return;
    sum += w * texels[n.texels + c];
    total += w;
  };
  tap(x0, y0, (1.0f - tx) * (1.0f - ty));
  tap(x1, y0, tx * (1.0f - ty));
  tap(x0, y1, (1.0f - tx) * ty);
  tap(x1, y1, tx * ty);
  if (total > 0.0f) return sum / total;
  return texels[n.texels + grid_cell(s) + kProxyGrid * grid_cell(t)];
}

}  // namespace

glm::vec3 LodBvh::proxy_radiance(std::uint32_t node, float s, float t) const {
  const LodNode& n = nodes[node];
  if (n.texels == kNoTexels) return n.radiance;
  return covered_bilinear(n, proxy_texels, s, t);
}

LodBvh build_lod_bvh(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance,
                     par::Executor* executor) {
  if (triangle_radiance.size() != bvh.triangle_count())
    throw InputError("lod_bvh", "one radiance per triangle expected");
  const auto& tn = bvh.threaded_nodes();
  const auto& tris = bvh.leaf_triangles();
  const auto& ids = bvh.triangle_ids();
  LodBvh lod;
  lod.nodes.assign(tn.size(), LodNode{});
  lod.triangle_leaf.assign(bvh.triangle_count(), kThreadEnd);
  lod.triangle_area.assign(bvh.triangle_count(), 0.0f);
  std::vector<Sums> sums(tn.size());
  std::vector<glm::vec3> points;
  // Depth-first order puts children after their parent: a reverse pass sees children first.
  for (std::size_t k = tn.size(); k-- > 0;) {
    const ThreadedNode& n = tn[k];
    LodNode& out = lod.nodes[k];
    Sums s;
    points.clear();
    if (n.count) {
      for (std::uint32_t j = n.first; j < n.first + n.count; ++j) {
        const LeafTriangle& t = tris[j];
        const glm::vec3 cr = glm::cross(t.b - t.a, t.c - t.a);
        const double a2 = glm::length(glm::dvec3(cr));
        const double area = 0.5 * a2;
        const std::uint32_t id = ids[j];
        lod.triangle_leaf[id] = static_cast<std::uint32_t>(k);
        lod.triangle_area[id] = static_cast<float>(area);
        s.area += area;
        s.area_normal += 0.5 * glm::dvec3(cr);  // area × unit normal
        s.area_centroid += area * glm::dvec3(t.a + t.b + t.c) / 3.0;
        s.area_radiance += area * glm::dvec3(triangle_radiance[id]);
        points.push_back(t.a);
        points.push_back(t.b);
        points.push_back(t.c);
      }
    } else {
      const std::uint32_t left = n.hit, right = tn[n.hit].miss;
      for (const std::uint32_t c : {left, right}) {
        s.add(sums[c]);
        lod.nodes[c].parent = static_cast<std::uint32_t>(k);
        proxy_points(lod.nodes[c], tn[c].box, points);
      }
    }
    sums[k] = s;
    out.area = static_cast<float>(s.area);
    const glm::vec3 diag = n.box.hi - n.box.lo;
    out.box_solid_angle_k = n.box.empty() ? 0.0f : kPi * glm::dot(diag, diag) / 4.0f;
    if (s.area > 0.0) {
      out.radiance = glm::vec3(s.area_radiance / s.area);
      const glm::dvec3 mean_n = s.area_normal / s.area;
      const double len = glm::length(mean_n);
      if (len >= kPlanarity) {
        out.quad = true;
        out.normal = glm::vec3(mean_n / len);
        const glm::vec3 centroid(s.area_centroid / s.area);
        const Onb frame(out.normal);
        float lo_u = 3e38f, hi_u = -3e38f, lo_v = 3e38f, hi_v = -3e38f;
        for (const glm::vec3& p : points) {
          const glm::vec3 d = p - centroid;
          const float u = glm::dot(d, frame.t), v = glm::dot(d, frame.b);
          lo_u = std::min(lo_u, u);
          hi_u = std::max(hi_u, u);
          lo_v = std::min(lo_v, v);
          hi_v = std::max(hi_v, v);
        }
        out.origin = centroid + lo_u * frame.t + lo_v * frame.b;
        out.edge_u = (hi_u - lo_u) * frame.t;
        out.edge_v = (hi_v - lo_v) * frame.b;
      }
    }
  }
  build_proxy_textures(bvh, triangle_radiance, lod, executor);
  lod.stop_k.resize(lod.nodes.size());
  for (std::size_t k = 0; k < lod.nodes.size(); ++k)
    lod.stop_k[k] = lod.nodes[k].quad ? lod.nodes[k].box_solid_angle_k : std::numeric_limits<float>::quiet_NaN();
  return lod;
}

}  // namespace speculum::trace
