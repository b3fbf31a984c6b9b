// The ray hierarchy build (see ray_hierarchy.h; ROGER §3.3.2).
#include "trace/ray_hierarchy.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace speculum::trace {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr std::size_t kNodeChunk = 1024;

bool finite3(float x, float y, float z) { return std::isfinite(x) && std::isfinite(y) && std::isfinite(z); }

}  // namespace

ConeSphere parent_cone_sphere(const ConeSphere* ch, int count) {
  ConeSphere out;
  glm::vec3 dsum(0.0f), csum(0.0f);
  int n = 0;
  for (int i = 0; i < count; ++i) {
    if (ch[i].empty()) continue;
    dsum += ch[i].d;
    csum += ch[i].c;
    ++n;
  }
  if (n == 0) return out;  // empty
  out.c = csum / float(n);
  const float dl = glm::length(dsum);
  float alpha = 0.0f;
  if (!(dl > 1e-6f)) {
    // Opposing directions: no useful axis, the cone is the whole sphere of directions.
    out.d = glm::vec3(0.0f, 0.0f, 1.0f);
    alpha = kPi;
  } else {
    out.d = dsum / dl;
    for (int i = 0; i < count; ++i) {
      if (ch[i].empty()) continue;
      const float angle = std::atan2(glm::length(glm::cross(out.d, ch[i].d)), glm::dot(out.d, ch[i].d));
      alpha = std::max(alpha, angle + ch[i].alpha);
    }
    // Widen by a few float ulps of the angle plus an absolute 1e-6 rad (the normalization
    // of d and the atan2 are accurate to a few ulps).
    alpha = std::min(kPi, alpha * (1.0f + 4e-6f) + 1e-6f);
  }
  float r = 0.0f;
  for (int i = 0; i < count; ++i) {
    if (ch[i].empty()) continue;
    r = std::max(r, glm::length(out.c - ch[i].c) + ch[i].r);
  }
  const float cmag = std::max({std::fabs(out.c.x), std::fabs(out.c.y), std::fabs(out.c.z)});
  out.r = r * (1.0f + 4e-6f) + cmag * 4e-7f;
  out.alpha = alpha;
  return out;
}

int hierarchy_side(int width, int height) {
  int side = 1;
  while (side < std::max(width, height)) side *= 2;
  return side;
}

RayHierarchy build_ray_hierarchy(par::Executor& ex, const RayStream& rays, const std::vector<std::uint8_t>& active,
                                 int width, int height, const std::vector<float>* leaf_radius,
                                 const std::vector<float>* leaf_alpha) {
  RayHierarchy h;
  h.width = width;
  h.height = height;
  h.side = hierarchy_side(width, height);
  while ((1 << h.levels) < h.side) ++h.levels;
  h.nodes.resize(h.levels + 1);
  h.sin_alpha.resize(h.levels + 1);
  h.cos_alpha.resize(h.levels + 1);

  const auto side = static_cast<std::size_t>(h.side);
  auto& leaves = h.nodes[h.levels];
  leaves.assign(side * side, ConeSphere{});
  ex.parallel_for("ray_hierarchy_leaves", side * side, kNodeChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::size_t x = k % side, y = k / side;
      if (x >= std::size_t(width) || y >= std::size_t(height)) continue;
      const std::size_t i = y * std::size_t(width) + x;
      if (!active[i]) continue;
      const glm::vec3 o(rays.ox[i], rays.oy[i], rays.oz[i]);
      const glm::vec3 d(rays.dx[i], rays.dy[i], rays.dz[i]);
      const float l = glm::length(d);
      if (!finite3(o.x, o.y, o.z) || !finite3(d.x, d.y, d.z) || !(l > 0.0f) || rays.tmin[i] > rays.tmax[i])
        continue;
      leaves[k].c = o;
      leaves[k].r = leaf_radius ? std::max((*leaf_radius)[i], 0.0f) : 0.0f;
      leaves[k].d = d / l;
      leaves[k].alpha = leaf_alpha ? std::clamp((*leaf_alpha)[i], 0.0f, kPi) : 0.0f;
    }
  });
  for (int l = h.levels - 1; l >= 0; --l) {
    const std::size_t n = std::size_t(1) << l;  // nodes per row at level l
    const auto& below = h.nodes[l + 1];
    auto& level = h.nodes[l];
    level.assign(n * n, ConeSphere{});
    ex.parallel_for("ray_hierarchy_level_" + std::to_string(l), n * n, kNodeChunk,
                    [&](std::size_t b, std::size_t e) {
                      for (std::size_t k = b; k < e; ++k) {
                        const std::size_t x = k % n, y = k / n, row = 2 * n;
                        const ConeSphere c[4] = {below[(2 * y) * row + 2 * x], below[(2 * y) * row + 2 * x + 1],
                                                 below[(2 * y + 1) * row + 2 * x],
                                                 below[(2 * y + 1) * row + 2 * x + 1]};
                        level[k] = parent_cone_sphere(c, 4);
                      }
                    });
  }
  for (int l = 0; l <= h.levels; ++l) {
    const auto& level = h.nodes[l];
    auto& s = h.sin_alpha[l];
    auto& c = h.cos_alpha[l];
    s.resize(level.size());
    c.resize(level.size());
    ex.parallel_for("ray_hierarchy_trig_" + std::to_string(l), level.size(), kNodeChunk,
                    [&](std::size_t b, std::size_t e) {
                      for (std::size_t k = b; k < e; ++k) {
                        s[k] = std::sin(level[k].alpha);
                        c[k] = std::cos(level[k].alpha);
                      }
                    });
  }
  return h;
}

}  // namespace speculum::trace
