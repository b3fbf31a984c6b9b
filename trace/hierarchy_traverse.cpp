// The ray-hierarchy traversal (see hierarchy_traverse.h; ROGER §3.3, §4.3).
#include "trace/hierarchy_traverse.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "parallel/compact.h"
#include "parallel/segmented.h"
#include "trace/ray_triangle.h"

namespace speculum::trace {

namespace {

constexpr std::size_t kPairChunk = 4096;
constexpr std::size_t kTriangleChunk = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();

std::vector<TriangleLeafBounds> triangle_leaf_bounds_all(par::Executor& ex, const std::vector<glm::vec3>& p,
                                         const std::vector<std::uint32_t>& idx) {
  std::vector<TriangleLeafBounds> out(idx.size() / 3);
  ex.parallel_for("hierarchy_leaf_triangles", out.size(), kTriangleChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) out[t] = triangle_leaf_bounds(p[idx[3 * t]], p[idx[3 * t + 1]], p[idx[3 * t + 2]]);
  });
  return out;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct Traversal {
  par::Executor& ex;
  const std::vector<glm::vec3>& positions;
  const std::vector<std::uint32_t>& indices;
  const RayHierarchy& h;
  const RayStream& rays;
  const std::vector<BoundingSphere>& spheres;
  const std::vector<TriangleLeafBounds>& leaf_tris;
  std::size_t capacity, block_size;
  HierarchyTraverseStats& stats;
  HitStream& best;  // merged over batches
  const CandidateConsumer* consume = nullptr;  // cone leaves: the pairs go here, not to the ray tests

  // Scratch reused across levels and batches.
  std::vector<std::uint32_t> node, tri, next_node, next_tri, kept, scratch;
  std::vector<std::uint8_t> keep;

  // Traverses triangles [t0, t1); false (nothing merged) when a level overflows.
  bool run_batch(std::uint32_t t0, std::uint32_t t1) {
    const std::size_t m0 = t1 - t0;
    if (4 * m0 > capacity) return false;
    node.assign(m0, 0u);
    tri.resize(m0);
    for (std::size_t k = 0; k < m0; ++k) tri[k] = t0 + std::uint32_t(k);
    std::vector<std::uint64_t> level_pairs(h.levels + 1, 0);
    std::uint64_t tests = 0;
    if (h.nodes[0][0].empty()) return true;  // no rays at all
    for (int l = 0; l < h.levels; ++l) {
      const std::size_t m = node.size();
      level_pairs[l] = m;
      if (4 * m > capacity) return false;
      tests += 4 * m;
      descend_level(l);
    }
    level_pairs[h.levels] = node.size();
    const std::size_t m = node.size();
    if (consume)
      (*consume)(std::span<const std::uint32_t>(node), std::span<const std::uint32_t>(tri));
    else
      exact_tests_and_merge();

    if (stats.pairs_per_level.size() < level_pairs.size()) stats.pairs_per_level.resize(level_pairs.size(), 0);
    for (std::size_t l = 0; l < level_pairs.size(); ++l) stats.pairs_per_level[l] += level_pairs[l];
    stats.cone_sphere_tests += tests;
    stats.candidates += m;
    stats.level_passes += std::uint64_t(h.levels);
    ++stats.batches;
    return true;
  }

  // The leaf test beyond the sphere (leaf_may_hit in the header).
  bool ray_can_reach(std::size_t leaf, std::uint32_t t) const {
    const std::size_t i = (leaf / std::size_t(h.side)) * std::size_t(h.width) + leaf % std::size_t(h.side);
    const glm::vec3 o(rays.ox[i], rays.oy[i], rays.oz[i]), d(rays.dx[i], rays.dy[i], rays.dz[i]);
    return leaf_may_hit(o, d, rays.tmin[i], rays.tmax[i], leaf_tris[t]);
  }

  // Level l -> l+1 of the descent: one kernel tests each (node, triangle) pair's sphere
  // against the node's 4 children, then the surviving (child, triangle) pairs replace
  // node/tri, compacted in order.
  void descend_level(int l) {
    const std::size_t m = node.size();
    const std::size_t n = std::size_t(1) << l, row = 2 * n;
    const auto& child = h.nodes[l + 1];
    const auto& sn = h.sin_alpha[l + 1];
    const auto& cs = h.cos_alpha[l + 1];
    keep.resize(4 * m);
    const bool leaves = l + 1 == h.levels;
    auto t_test = std::chrono::steady_clock::now();
    ex.parallel_for("hierarchy_level_" + std::to_string(l), m, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t x = node[k] % n, y = node[k] / n;
        const BoundingSphere& s = spheres[tri[k]];
        for (int j = 0; j < 4; ++j) {
          const std::size_t c = (2 * y + std::size_t(j >> 1)) * row + 2 * x + std::size_t(j & 1);
          keep[4 * k + j] = !child[c].empty() && cone_sphere_intersects(child[c], sn[c], cs[c], s) &&
                            (!leaves || child[c].r != 0.0f || child[c].alpha != 0.0f ||
                             ray_can_reach(c, tri[k]));
        }
      }
    });
    stats.tests_ms += ms_since(t_test);
    auto t_compact = std::chrono::steady_clock::now();
    kept.resize(4 * m);
    const std::size_t count = par::compact_hierarchical(ex, "hierarchy_compact_" + std::to_string(l),
                                                        keep, kept, block_size, &scratch);
    next_node.resize(count);
    next_tri.resize(count);
    ex.parallel_for("hierarchy_gather_" + std::to_string(l), count, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const std::size_t src = kept[i] / 4, j = kept[i] % 4;
        const std::size_t x = node[src] % n, y = node[src] / n;
        next_node[i] = std::uint32_t((2 * y + (j >> 1)) * row + 2 * x + (j & 1));
        next_tri[i] = tri[src];
      }
    });
    std::swap(node, next_node);
    std::swap(tri, next_tri);
    stats.compaction_ms += ms_since(t_compact);
  }

  // Exact tests of the surviving (leaf, triangle) pairs; the closest hit per ray by
  // segmented min, merged into `best`.
  void exact_tests_and_merge() {
    auto t_exact = std::chrono::steady_clock::now();
    const std::size_t m = node.size();
    const std::size_t side = std::size_t(h.side), width = std::size_t(h.width);
    std::vector<std::uint32_t> ray_of(m);
    std::vector<float> t(m), u(m), v(m);
    ex.parallel_for("hierarchy_exact_tests", m, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = (node[k] / side) * width + node[k] % side;
        ray_of[k] = std::uint32_t(i);
        const glm::vec3 o(rays.ox[i], rays.oy[i], rays.oz[i]), d(rays.dx[i], rays.dy[i], rays.dz[i]);
        const RayShear shear(o, d);
        const std::uint32_t* tr = &indices[3 * std::size_t(tri[k])];
        TriangleHit hit;
        if (intersect_triangle_watertight(shear, positions[tr[0]], positions[tr[1]], positions[tr[2]],
                                          rays.tmin[i], rays.tmax[i], hit)) {
          t[k] = hit.t;
          u[k] = hit.u;
          v[k] = hit.v;
        } else {
          t[k] = kInf;
        }
      }
    });
    const std::size_t nrays = rays.size();
    std::vector<float> min_t(nrays);
    std::vector<std::uint32_t> min_k(nrays);
    // Candidates of one ray appear in ascending triangle order (the stream starts sorted by
    // triangle and every level keeps order), so the lowest-index tie is the lowest triangle.
    par::segmented_min(ex, "hierarchy_closest", ray_of, t, std::uint32_t(nrays), min_t, min_k);
    // Merge: a later batch holds only higher triangles, so it wins on strictly smaller t.
    ex.parallel_for("hierarchy_merge", nrays, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (min_k[i] == par::kNoIndex || !(min_t[i] < best.t[i])) continue;
        const std::uint32_t k = min_k[i];
        best.t[i] = min_t[i];
        best.u[i] = u[k];
        best.v[i] = v[k];
        best.triangle[i] = tri[k];
      }
    });
    stats.exact_ms += ms_since(t_exact);
  }

  void run(std::uint32_t t0, std::uint32_t t1) {
    if (t0 >= t1) return;
    if (run_batch(t0, t1)) return;
    ++stats.overflow_batches;
    const std::uint32_t mid = t0 + (t1 - t0) / 2;
    run(t0, mid);
    run(mid, t1);
  }
};

}  // namespace

TriangleLeafBounds triangle_leaf_bounds(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  TriangleLeafBounds q;
  q.a = a;
  // In double the edge differences and products of float coordinates are exact or nearly so,
  // so the rounded normal is accurate to a float ulp per component however thin the triangle.
  const glm::dvec3 n = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
  q.normal = glm::vec3(n);
  q.normal_length = float(glm::length(n));
  q.lo = glm::min(a, glm::min(b, c));
  q.hi = glm::max(a, glm::max(b, c));
  q.magnitude = std::max({1.0f, std::fabs(q.lo.x), std::fabs(q.lo.y), std::fabs(q.lo.z), std::fabs(q.hi.x),
                          std::fabs(q.hi.y), std::fabs(q.hi.z)});
  return q;
}

std::vector<BoundingSphere> triangle_bounding_spheres(par::Executor& ex, const std::vector<glm::vec3>& p,
                                                      const std::vector<std::uint32_t>& idx) {
  std::vector<BoundingSphere> s(idx.size() / 3);
  ex.parallel_for("hierarchy_spheres", s.size(), kTriangleChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      const glm::vec3 a = p[idx[3 * t]], bb = p[idx[3 * t + 1]], c = p[idx[3 * t + 2]];
      const glm::vec3 centre = (a + bb + c) / 3.0f;
      const float r = std::max({glm::length(a - centre), glm::length(bb - centre), glm::length(c - centre)});
      const float mag = std::max({std::fabs(centre.x), std::fabs(centre.y), std::fabs(centre.z)});
      s[t] = {centre, r * (1.0f + 4e-6f) + mag * 4e-7f};
    }
  });
  return s;
}

namespace {

void traverse(par::Executor& ex, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
              const RayHierarchy& hierarchy, const RayStream& rays, HitStream& hits,
              const HierarchyTraverseOptions& options, HierarchyTraverseStats* stats_out,
              const CandidateConsumer* consume) {
  HierarchyTraverseStats stats;
  for (const ConeSphere& leaf : hierarchy.nodes[hierarchy.levels]) stats.active_rays += !leaf.empty();
  const auto t_spheres = std::chrono::steady_clock::now();
  const std::vector<BoundingSphere> spheres = triangle_bounding_spheres(ex, positions, indices);
  const std::vector<TriangleLeafBounds> leaf_tris = triangle_leaf_bounds_all(ex, positions, indices);
  stats.tests_ms += ms_since(t_spheres);
  const std::size_t side = std::size_t(hierarchy.side);
  const std::size_t capacity = std::max(options.pair_capacity, 4 * side * side);
  Traversal tr{ex, positions, indices, hierarchy, rays, spheres, leaf_tris, capacity, std::max<std::size_t>(1, options.block_size),
               stats, hits, consume, {}, {}, {}, {}, {}, {}, {}};
  tr.run(0, std::uint32_t(indices.size() / 3));
  for (std::size_t i = 0; i < hits.triangle.size(); ++i) stats.hits += hits.triangle[i] != kNoHit;
  if (stats.pairs_per_level.empty()) stats.pairs_per_level.assign(hierarchy.levels + 1, 0);
  if (stats_out) *stats_out = stats;
}

}  // namespace

void hierarchy_closest_hits(par::Executor& ex, const std::vector<glm::vec3>& positions,
                            const std::vector<std::uint32_t>& indices, const RayHierarchy& hierarchy,
                            const RayStream& rays, HitStream& hits, const HierarchyTraverseOptions& options,
                            HierarchyTraverseStats* stats_out) {
  hits.resize(rays.size());
  std::fill(hits.t.begin(), hits.t.end(), kInf);
  std::fill(hits.u.begin(), hits.u.end(), 0.0f);
  std::fill(hits.v.begin(), hits.v.end(), 0.0f);
  std::fill(hits.triangle.begin(), hits.triangle.end(), kNoHit);
  traverse(ex, positions, indices, hierarchy, rays, hits, options, stats_out, nullptr);
}

void hierarchy_candidates(par::Executor& ex, const std::vector<glm::vec3>& positions,
                          const std::vector<std::uint32_t>& indices, const RayHierarchy& hierarchy,
                          const RayStream& rays, const CandidateConsumer& consume,
                          const HierarchyTraverseOptions& options, HierarchyTraverseStats* stats) {
  HitStream none;
  traverse(ex, positions, indices, hierarchy, rays, none, options, stats, &consume);
}

}  // namespace speculum::trace
