// The screen-space ray hierarchy of ROGER §3.3 (build §3.3.2, traversal §3.3.3): a
// quad-tree of cone-spheres over one ray per pixel, built bottom-up one level per kernel,
// and the cone-sphere / bounding-sphere test of ROGER eq.3.1 that its traversal uses.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "parallel/executor.h"
#include "trace/traversal.h"

namespace speculum::trace {

// One node, 8 floats (ROGER §3.3.2): a sphere (c, r) bounding the ray origins and a cone
// (d unit, half-angle alpha <= π) bounding their directions. Leaves: r = 0, alpha = 0.
// An empty node (no ray below it) has r < 0.
struct ConeSphere {
  glm::vec3 c{0.0f};
  float r = -1.0f;
  glm::vec3 d{0.0f, 0.0f, 1.0f};
  float alpha = 0.0f;
  bool empty() const { return r < 0.0f; }
};
static_assert(sizeof(ConeSphere) == 8 * sizeof(float));

constexpr float kHalfPi = 1.57079632679f;

// A triangle's bounding sphere (centroid, radius to the farthest vertex, widened so float
// rounding never leaves a vertex outside).
struct BoundingSphere {
  glm::vec3 p{0.0f};
  float rho = 0.0f;
};

// ROGER eq.3.1 with CH = (P-C)·d, HP = |P - C - CH d|: the sphere (P, rho) can meet a ray
// of the node iff CH tanα + (rho + r)/cosα >= HP, written multiplied by cosα (> 0) as
// CH sinα + (rho + r) >= HP cosα; α >= π/2 always intersects. Eq.3.1 is the distance to
// the cone's slanted generatrix *line*; where P - C lies behind the apex beyond the
// generatrix's normal (CH cosα + HP sinα < 0) the true distance to the cone is |P - C|, so
// there the test is |P - C| <= rho + r. Together this is the exact distance from P to the
// Minkowski sum of the origin sphere and the cone (the union of the node's rays), hence
// conservative, and it drops spheres behind a ray's origin that the line test keeps (at a
// leaf, α = 0, eq.3.1 alone accepts every sphere the infinite line meets). A relative margin
// covers the rounding of the products.
inline bool cone_sphere_intersects(const ConeSphere& n, float sin_a, float cos_a, const BoundingSphere& s) {
  if (n.alpha >= kHalfPi) return true;
  const glm::vec3 q = s.p - n.c;
  const float ch = glm::dot(q, n.d);
  const glm::vec3 h = q - ch * n.d;
  const float hp = std::sqrt(glm::dot(h, h));
  const float R = s.rho + n.r;
  const float scale = std::fabs(ch) + hp + R +
                      std::fmax(std::fmax(std::fabs(n.c.x), std::fabs(n.c.y)), std::fabs(n.c.z)) * 0.1f;
  const float margin = 1e-5f * scale;
  if (ch * cos_a + hp * sin_a < -margin) {
    const float Rm = R + margin;
    return glm::dot(q, q) <= Rm * Rm;
  }
  return ch * sin_a + R + margin >= hp * cos_a;
}
inline bool cone_sphere_intersects(const ConeSphere& n, const BoundingSphere& s) {
  return cone_sphere_intersects(n, std::sin(n.alpha), std::cos(n.alpha), s);
}

// The parent of up to 4 children (ROGER §3.3.2, Fig.3.5, shows it but gives no formula):
// d = normalize(Σ d_i), α = min(π, max_i(∠(d, d_i) + α_i)), C = mean(C_i),
// r = max_i(|C - C_i| + r_i), over the non-empty children only (all empty → empty). Angles
// by atan2(|d×d_i|, d·d_i) (acos loses ~3e-4 rad near 0) and every bound widened slightly,
// so the parent encloses its children despite rounding.
ConeSphere parent_cone_sphere(const ConeSphere* children, int count);

// The quad-tree over a side × side grid of leaves (side a power of two), level 0 = root,
// level `levels` = leaves (side = 2^levels). Node (x, y) of level l is nodes[l][y·2^l + x];
// its children are (2x + i, 2y + j) of level l + 1. sin/cos of every α are stored beside
// the nodes (the traversal needs them for every test).
struct RayHierarchy {
  int width = 0, height = 0;  // the ray grid (pixels); leaves outside it are empty
  int side = 0;               // next power of two >= max(width, height): the padding
  int levels = 0;             // log2(side)
  std::vector<std::vector<ConeSphere>> nodes;
  std::vector<std::vector<float>> sin_alpha, cos_alpha;
};

// Smallest power of two >= max(width, height) (>= 1).
int hierarchy_side(int width, int height);

// Builds the hierarchy over `rays` (width × height, row-major; rays with active[i] == 0 or
// invalid values are empty leaves). Kernels "ray_hierarchy_leaves" then one
// "ray_hierarchy_level_<l>" per level, bottom-up. Width and height need not be powers of
// two: the grid is padded with empty leaves to side × side.
// Cone leaves (ROGER §5.2.1: "leaves are cones"): with `leaf_radius` and `leaf_alpha`
// (one value per ray, >= 0) leaf i is the sphere (origin, leaf_radius[i]) swept by the cone
// of half-angle leaf_alpha[i] about the ray's direction, which bounds a cone of that
// half-angle whose cross-section at the origin has that radius; the levels above are built
// the same way. Without them every leaf is a ray (r = 0, α = 0).
RayHierarchy build_ray_hierarchy(par::Executor& executor, const RayStream& rays,
                                 const std::vector<std::uint8_t>& active, int width, int height,
                                 const std::vector<float>* leaf_radius = nullptr,
                                 const std::vector<float>* leaf_alpha = nullptr);

}  // namespace speculum::trace
