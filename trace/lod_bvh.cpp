// Bottom-up construction of the per-node LOD data (see lod_bvh.h), YU §3.2 adapted to
// general meshes.
#include "trace/lod_bvh.h"

#include <algorithm>
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

}  // namespace

LodBvh build_lod_bvh(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance) {
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
  lod.stop_k.resize(lod.nodes.size());
  for (std::size_t k = 0; k < lod.nodes.size(); ++k)
    lod.stop_k[k] = lod.nodes[k].quad ? lod.nodes[k].box_solid_angle_k : std::numeric_limits<float>::quiet_NaN();
  return lod;
}

}  // namespace speculum::trace
