// The ray-hierarchy traversal of ROGER §3.3.3 (with the pair buffer of §3.3.4) on the
// hierarchical stream reduction of ROGER §4.3 (parallel/compact.h): a stream of (node,
// triangle) pairs refined one quad-tree level per kernel, then exact watertight tests and
// the closest hit per ray by a segmented min. No scene structure: every triangle starts at
// the root.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "parallel/executor.h"
#include "trace/ray_hierarchy.h"
#include "trace/traversal.h"

namespace speculum::trace {

struct HierarchyTraverseOptions {
  // Fixed capacity of the pair buffer, counted in pairs of the 4-way expanded stream (the
  // thesis's 2048² texels). When a level would need more, the triangle batch is split in
  // two halves and each is traversed on its own; the closest hits are merged in triangle
  // order, so the result does not change. Raised to at least 4·side² (one triangle can
  // reach every leaf, so a single-triangle batch always fits).
  std::size_t pair_capacity = std::size_t(2048) * 2048;
  std::size_t block_size = 64;  // s of the hierarchical compaction (ROGER §4.3.2)
};

// Integer counters summed over batches (deterministic), and stage wall times (not).
struct HierarchyTraverseStats {
  std::vector<std::uint64_t> pairs_per_level;  // [l]: pairs entering level l's pass; [levels]: candidates
  std::uint64_t cone_sphere_tests = 0;         // 4 per pair per level pass
  std::uint64_t candidates = 0;                // pairs reaching the exact tests
  std::uint64_t active_rays = 0;               // non-empty leaves
  std::uint64_t level_passes = 0;              // level kernels launched (levels per finished batch)
  std::uint64_t batches = 0;                   // triangle batches traversed to the leaves
  std::uint64_t overflow_batches = 0;          // attempts abandoned on overflow (then split)
  std::uint64_t hits = 0;
  double tests_ms = 0, compaction_ms = 0, exact_ms = 0;
  double candidates_per_ray() const { return active_rays ? double(candidates) / double(active_rays) : 0.0; }
};

// Closest hit (t >= tmin, t <= tmax; ties to the lower triangle index, exactly as
// closest_hit_oracle) of every ray of `rays` (the rays the hierarchy was built over, row-
// major width × height) against the triangles (positions, indices). Rays that are empty
// leaves get Hit{} (no hit). Kernels: "hierarchy_spheres", per level
// "hierarchy_level_<l>" (tests) + compaction + "hierarchy_gather_<l>", then
// "hierarchy_exact_tests", the segmented min "hierarchy_closest" and "hierarchy_merge".
void hierarchy_closest_hits(par::Executor& executor, const std::vector<glm::vec3>& positions,
                            const std::vector<std::uint32_t>& indices, const RayHierarchy& hierarchy,
                            const RayStream& rays, HitStream& hits,
                            const HierarchyTraverseOptions& options = {},
                            HierarchyTraverseStats* stats = nullptr);

// The same descent, handing every batch's surviving (leaf, triangle) pairs to `consume`
// instead of testing them as rays: leaf[k] is the hierarchy leaf index y·side + x, triangle[k]
// its triangle; within a batch pairs come in ascending triangle order, and batches cover
// ascending triangle ranges. The leaf's plane test (a ray moving away from a triangle's
// plane cannot hit it) applies only to leaves that are rays (r = 0, α = 0). What cone
// tracing (ROGER §5.2.1) intersects with its cone leaves.
using CandidateConsumer =
    std::function<void(std::span<const std::uint32_t> leaf, std::span<const std::uint32_t> triangle)>;
void hierarchy_candidates(par::Executor& executor, const std::vector<glm::vec3>& positions,
                          const std::vector<std::uint32_t>& indices, const RayHierarchy& hierarchy,
                          const RayStream& rays, const CandidateConsumer& consume,
                          const HierarchyTraverseOptions& options = {}, HierarchyTraverseStats* stats = nullptr);

// What the leaf test reads of a triangle, built once per traversal (kernel
// "hierarchy_leaf_triangles"): a vertex, the normal (b−a)×(c−a) computed in double and
// rounded (so its direction is accurate even for slivers), its length, the axis-aligned
// box, and the largest coordinate magnitude of the vertices (at least 1), which scales the
// test's tolerances.
struct TriangleLeafBounds {
  glm::vec3 a{0.0f}, normal{0.0f};
  float normal_length = 0.0f, magnitude = 1.0f;
  glm::vec3 lo{0.0f}, hi{0.0f};
};
TriangleLeafBounds triangle_leaf_bounds(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// The test a (leaf, triangle) pair passes, after the leaf's eq.3.1 sphere test, to become a
// candidate of the exact test: the ray o + t d, t in [tmin, tmax], must come within a
// tolerance of the triangle's plane at some t where it is also inside the triangle's box.
// Every true hit lies in the plane and in the box, so this keeps every pair the exact
// (watertight) test accepts: the tolerances (1e-5 of the coordinates' magnitude, in the plane
// distance and around the box, and 1e-4 of the t range) are far above the rounding of both
// tests; only pairs are kept by them, never dropped. It removes what ROGER §3.3.3's sphere
// test keeps although the ray cannot reach the triangle: the triangles whose plane the ray
// leaves (a reflected ray and its own reflector's triangles), those whose plane lies behind
// the origin or beyond tmax, and those whose bounding sphere the ray passes but whose
// plane it crosses outside the box. ROGER §3.4 counts the triangles that remain after
// traversal as the polygons the ray intersects; this test brings the count close to that.
inline bool leaf_may_hit(const glm::vec3& o, const glm::vec3& d, float tmin, float tmax, const TriangleLeafBounds& tri) {
  const float scale = std::max({tri.magnitude, std::fabs(o.x), std::fabs(o.y), std::fabs(o.z)});
  // The t interval in which the ray is within `tolerance` of the plane.
  const float side = glm::dot(tri.normal, o - tri.a), towards = glm::dot(tri.normal, d);
  const float tolerance = 1e-5f * scale * tri.normal_length;
  float lo = tmin - 1e-4f * std::fabs(tmin), hi = tmax + 1e-4f * std::fabs(tmax);
  if (towards != 0.0f) {
    const float t1 = (-side - tolerance) / towards, t2 = (-side + tolerance) / towards;
    lo = std::max(lo, std::min(t1, t2));
    hi = std::min(hi, std::max(t1, t2));
  } else if (std::fabs(side) > tolerance) {
    return false;  // parallel to the plane and off it
  }
  // Slab test against the box grown by the margin, over that interval.
  const float margin = 1e-5f * scale;
  for (int k = 0; k < 3; ++k) {
    const float bl = tri.lo[k] - margin, bh = tri.hi[k] + margin;
    if (d[k] == 0.0f) {
      if (o[k] < bl || o[k] > bh) return false;
      continue;
    }
    const float t1 = (bl - o[k]) / d[k], t2 = (bh - o[k]) / d[k];
    lo = std::max(lo, std::min(t1, t2));
    hi = std::min(hi, std::max(t1, t2));
  }
  return lo <= hi;
}

// The bounding sphere of every triangle (kernel "hierarchy_spheres").
std::vector<BoundingSphere> triangle_bounding_spheres(par::Executor& executor,
                                                      const std::vector<glm::vec3>& positions,
                                                      const std::vector<std::uint32_t>& indices);

}  // namespace speculum::trace
