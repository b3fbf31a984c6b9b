// Ray hierarchy unit tests (ROGER §3.3.2–3.3.4): the eq.3.1 cone-sphere test is
// conservative against a brute force (incl. α >= π/2 and spheres behind the apex), every
// node encloses the rays below it, traversal runs exactly log2(side) level passes per batch,
// batched = unbatched and 1 thread = 2 threads, all equal to the all-pairs oracle.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>

#include "core/sampling.h"
#include "tests/trace/test_meshes.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/ray_triangle.h"

namespace speculum::trace {
namespace {

using testing::rnd;
using testing::rnd3;

glm::vec3 unit_vector(std::uint32_t i, std::uint32_t seed) {
  const float z = 2.0f * rnd(i, 0, seed) - 1.0f, ph = 2.0f * kPi * rnd(i, 1, seed);
  const float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {s * std::cos(ph), s * std::sin(ph), z};
}

// A direction within angle `alpha` of unit d (uniform on the cap; boundary when edge).
glm::vec3 cone_direction(const glm::vec3& d, float alpha, float u1, float u2, bool edge) {
  const float cos_t = edge ? std::cos(alpha) : 1.0f - u1 * (1.0f - std::cos(alpha));
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  const Onb onb(d);
  return onb.to_world(glm::vec3(sin_t * std::cos(2 * kPi * u2), sin_t * std::sin(2 * kPi * u2), cos_t));
}

// Does the ray o + t u (t >= 0, u unit) meet the ball (p, rho)? In double.
bool ray_meets_ball(glm::dvec3 o, glm::dvec3 u, glm::dvec3 p, double rho) {
  const double tc = std::max(0.0, glm::dot(p - o, u));
  const glm::dvec3 q = o + tc * u - p;
  return glm::dot(q, q) <= rho * rho;
}

TEST(RayHierarchy, ConeSphereTestNeverRejectsABruteForceHit) {
  int brute_hits = 0, rejected = 0, wide = 0, behind = 0;
  for (std::uint32_t c = 0; c < 3000; ++c) {
    ConeSphere n;
    n.c = rnd3(c, 11, -2.0f, 2.0f);
    n.r = (c % 5 == 0) ? 0.0f : 0.5f * rnd(c, 0, 12);
    n.d = unit_vector(c, 13);
    // α over [0, π], weighted towards small cones (the common case) with some >= π/2.
    const float u = rnd(c, 0, 14);
    n.alpha = (c % 7 == 0) ? kHalfPi + u * kHalfPi : (c % 3 == 0 ? 0.0f : u * u * 1.2f);
    wide += n.alpha >= kHalfPi;
    BoundingSphere s;
    s.rho = 0.01f + 0.4f * rnd(c, 1, 14);
    const float along = -3.0f + 9.0f * rnd(c, 2, 14);  // negative: behind the apex
    const glm::vec3 side = glm::normalize(glm::cross(n.d, unit_vector(c, 15)));
    const float lateral = (std::fabs(along) * std::tan(std::min(n.alpha, 1.4f)) + n.r + s.rho) *
                          (0.5f + 1.5f * rnd(c, 3, 14));
    s.p = n.c + along * n.d + lateral * side;
    behind += along < 0.0f;
    const bool accepted = cone_sphere_intersects(n, s);
    rejected += !accepted;
    bool hit = false;
    for (std::uint32_t k = 0; k < 600 && !hit; ++k) {
      const std::uint32_t id = c * 1000 + k;
      const bool edge = k % 2 == 0;
      // Origins in the ball (on its surface for half the samples, facing the sphere).
      glm::vec3 o = n.c;
      if (n.r > 0.0f) {
        const glm::vec3 towards = glm::normalize(s.p - n.c);
        const glm::vec3 v = (k % 4 == 0) ? towards : unit_vector(id, 16);
        o = n.c + n.r * (edge ? 1.0f : std::cbrt(rnd(id, 2, 17))) * v;
      }
      glm::vec3 u;
      if (k % 8 == 0) {
        // The cone's boundary direction in the plane of (d, P - C), towards the sphere.
        const glm::vec3 q = s.p - n.c;
        glm::vec3 h = q - glm::dot(q, n.d) * n.d;
        h = glm::length(h) > 0.0f ? glm::normalize(h) : side;
        const float a = std::min(n.alpha, kPi);
        u = std::cos(a) * n.d + std::sin(a) * h;
      } else {
        u = cone_direction(n.d, std::min(n.alpha, kPi), rnd(id, 0, 18), rnd(id, 1, 18), edge);
      }
      hit = ray_meets_ball(glm::dvec3(o), glm::normalize(glm::dvec3(u)), glm::dvec3(s.p), s.rho);
    }
    if (hit) {
      ++brute_hits;
      EXPECT_TRUE(accepted) << "case " << c << " alpha " << n.alpha << " r " << n.r;
    }
  }
  // The cases are not vacuous: many hits, many rejections, wide cones and spheres behind.
  EXPECT_GT(brute_hits, 500);
  EXPECT_GT(rejected, 300);
  EXPECT_GT(wide, 300);
  EXPECT_GT(behind, 500);
}

TEST(RayHierarchy, WideConeAlwaysIntersects) {
  ConeSphere n;
  n.c = glm::vec3(0);
  n.r = 0.0f;
  n.d = glm::vec3(0, 0, 1);
  n.alpha = kHalfPi;
  EXPECT_TRUE(cone_sphere_intersects(n, BoundingSphere{glm::vec3(0, 0, -100), 0.001f}));
  n.alpha = kHalfPi - 0.1f;
  EXPECT_FALSE(cone_sphere_intersects(n, BoundingSphere{glm::vec3(0, 0, -100), 0.001f}));
}

// Random rays on a w × h grid (some pixels empty).
RayStream random_rays(int w, int h, std::uint32_t seed, std::vector<std::uint8_t>& active, bool shared_origin) {
  RayStream rays;
  rays.resize(std::size_t(w) * h);
  active.assign(rays.size(), 0);
  for (std::uint32_t i = 0; i < rays.size(); ++i) {
    Ray r;
    r.origin = shared_origin ? glm::vec3(0.1f, 0.2f, 0.3f) : rnd3(i, seed, -1.0f, 1.0f);
    r.direction = unit_vector(i, seed + 1) * (0.5f + rnd(i, 3, seed));
    rays.set(i, r);
    active[i] = rnd(i, 4, seed) < 0.85f;
  }
  return rays;
}

TEST(RayHierarchy, EveryNodeEnclosesItsRays) {
  par::Executor ex(1);
  std::vector<std::uint8_t> active;
  const int w = 13, h = 9;  // padded to 16
  const RayStream rays = random_rays(w, h, 5, active, false);
  const RayHierarchy hi = build_ray_hierarchy(ex, rays, active, w, h);
  ASSERT_EQ(hi.side, 16);
  ASSERT_EQ(hi.levels, 4);
  for (int l = 0; l <= hi.levels; ++l) {
    const int n = 1 << l, span = hi.side / n;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const ConeSphere& node = hi.nodes[l][std::size_t(y) * n + x];
        bool any = false;
        for (int py = y * span; py < (y + 1) * span; ++py)
          for (int px = x * span; px < (x + 1) * span; ++px) {
            if (px >= w || py >= h || !active[std::size_t(py) * w + px]) continue;
            any = true;
            ASSERT_FALSE(node.empty());
            const Ray r = rays.get(std::size_t(py) * w + px);
            EXPECT_LE(glm::length(glm::dvec3(r.origin) - glm::dvec3(node.c)), double(node.r));
            const glm::dvec3 u = glm::normalize(glm::dvec3(r.direction)), d(node.d);
            const double angle = std::atan2(glm::length(glm::cross(u, d)), glm::dot(u, d));
            // A leaf's d is the float-normalized direction (α = 0 exactly, as the thesis);
            // its ~1e-7 rad rounding is covered by the margin of the eq.3.1 test.
            const double slack = l == hi.levels ? 1e-6 : 0.0;
            EXPECT_LE(angle, double(node.alpha) + slack) << "level " << l;
          }
        EXPECT_EQ(any, !node.empty());
      }
  }
}

struct TraceResult {
  HitStream hits;
  HierarchyTraverseStats stats;
};

TraceResult trace(int threads, const testing::Soup& soup, const RayStream& rays, const std::vector<std::uint8_t>& active,
                  int w, int h, std::size_t capacity, std::size_t block = 64) {
  par::Executor ex(threads);
  const RayHierarchy hi = build_ray_hierarchy(ex, rays, active, w, h);
  TraceResult r;
  HierarchyTraverseOptions opt;
  if (capacity != 0) opt.pair_capacity = capacity;  // 0: the default (2048² pairs)
  opt.block_size = block;
  hierarchy_closest_hits(ex, soup.positions, soup.indices, hi, rays, r.hits, opt, &r.stats);
  return r;
}

void expect_oracle(const testing::Soup& soup, const RayStream& rays, const std::vector<std::uint8_t>& active,
                   const HitStream& hits, int* hit_count = nullptr) {
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit o = active[i] ? closest_hit_oracle(soup.positions, soup.indices, rays.get(i)) : Hit{};
    ASSERT_EQ(hits.triangle[i], o.triangle) << "ray " << i;
    if (!o.hit()) continue;
    if (hit_count) ++*hit_count;
    EXPECT_EQ(std::memcmp(&hits.t[i], &o.t, sizeof(float)), 0) << "ray " << i;
    EXPECT_EQ(std::memcmp(&hits.u[i], &o.u, sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(&hits.v[i], &o.v, sizeof(float)), 0);
  }
}

TEST(RayHierarchy, RandomRaysEqualOracleWithLog2LevelPasses) {
  const testing::Soup soup = testing::random_soup(400, 21, 0.3f);
  std::vector<std::uint8_t> active;
  const int w = 20, h = 12;
  const RayStream rays = random_rays(w, h, 31, active, false);
  const TraceResult r = trace(1, soup, rays, active, w, h, 0);
  int hit_count = 0;
  expect_oracle(soup, rays, active, r.hits, &hit_count);
  EXPECT_GT(hit_count, 20);
  EXPECT_EQ(r.stats.batches, 1u);
  EXPECT_EQ(r.stats.level_passes, 5u);  // side 32
  ASSERT_EQ(r.stats.pairs_per_level.size(), 6u);
  EXPECT_EQ(r.stats.pairs_per_level[0], 400u);
  EXPECT_EQ(r.stats.cone_sphere_tests,
            4 * (r.stats.pairs_per_level[0] + r.stats.pairs_per_level[1] + r.stats.pairs_per_level[2] +
                 r.stats.pairs_per_level[3] + r.stats.pairs_per_level[4]));
  EXPECT_EQ(r.stats.candidates, r.stats.pairs_per_level[5]);
}

// A ray that starts in front of a triangle's plane and moves away from it (a reflected ray
// leaving its own triangle) is no candidate of that triangle; one that moves towards it is,
// and hits it. The quad below every ray: rays up leave it, rays down hit it (the oracle).
TEST(RayHierarchy, RaysLeavingATrianglesPlaneAreNoCandidatesOfIt) {
  testing::Soup soup;
  soup.add({-2, 0, -2}, {2, 0, -2}, {2, 0, 2});
  soup.add({-2, 0, -2}, {2, 0, 2}, {-2, 0, 2});
  const int w = 8, h = 8;
  for (const float up : {1.0f, -1.0f}) {
    SCOPED_TRACE(up);
    RayStream rays;
    rays.resize(std::size_t(w) * h);
    std::vector<std::uint8_t> active(rays.size(), 1);
    for (std::uint32_t i = 0; i < rays.size(); ++i) {
      Ray r;
      r.origin = {rnd(i, 0, 5) * 2.0f - 1.0f, 1e-3f, rnd(i, 1, 5) * 2.0f - 1.0f};
      r.direction = glm::normalize(glm::vec3(rnd(i, 2, 5) - 0.5f, up, rnd(i, 3, 5) - 0.5f));
      r.tmin = 0.0f;
      r.tmax = 1e30f;
      rays.set(i, r);
    }
    const TraceResult r = trace(2, soup, rays, active, w, h, 0);
    expect_oracle(soup, rays, active, r.hits);
    if (up > 0.0f) EXPECT_EQ(r.stats.candidates, 0u);
    else EXPECT_EQ(r.stats.hits, rays.size());
  }
}

TEST(RayHierarchy, ReversedShadowRaysShareOneOriginAndEqualOracle) {
  const testing::Soup soup = testing::random_soup(300, 41, 0.25f);
  std::vector<std::uint8_t> active;
  const int w = 16, h = 16;
  RayStream rays = random_rays(w, h, 51, active, true);
  for (std::size_t i = 0; i < rays.size(); ++i) rays.tmax[i] = 1.0f - 1e-4f;  // light → point
  const TraceResult r = trace(1, soup, rays, active, w, h, 0);
  expect_oracle(soup, rays, active, r.hits);
}

TEST(RayHierarchy, BatchedEqualsUnbatchedAndThreadsAgree) {
  const testing::Soup soup = testing::random_soup(900, 61, 0.3f);
  std::vector<std::uint8_t> active;
  const int w = 16, h = 16;
  const RayStream rays = random_rays(w, h, 71, active, false);
  const TraceResult whole = trace(1, soup, rays, active, w, h, 0);
  // 4·side² = 1024 pairs: the 900-triangle root level (3600 pairs) must be split.
  const TraceResult batched = trace(1, soup, rays, active, w, h, 1024, 16);
  const TraceResult two = trace(2, soup, rays, active, w, h, 1024, 16);
  EXPECT_EQ(whole.stats.overflow_batches, 0u);
  EXPECT_GT(batched.stats.overflow_batches, 0u);
  EXPECT_GT(batched.stats.batches, 1u);
  EXPECT_EQ(batched.stats.level_passes, 4u * batched.stats.batches);
  for (const TraceResult* r : {&batched, &two}) {
    EXPECT_EQ(r->hits.triangle, whole.hits.triangle);
    EXPECT_EQ(std::memcmp(r->hits.t.data(), whole.hits.t.data(), whole.hits.t.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(r->hits.u.data(), whole.hits.u.data(), whole.hits.u.size() * sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(r->hits.v.data(), whole.hits.v.data(), whole.hits.v.size() * sizeof(float)), 0);
  }
  EXPECT_EQ(batched.stats.candidates, two.stats.candidates);
  EXPECT_EQ(batched.stats.cone_sphere_tests, two.stats.cone_sphere_tests);
  expect_oracle(soup, rays, active, whole.hits);
}

TEST(RayHierarchy, TiesGoToTheLowerTriangle) {
  // Eight copies of one triangle (the later ones in later batches when batched): the oracle keeps the
  // lowest index; so must the segmented min and the batch merge.
  testing::Soup soup;
  for (int k = 0; k < 8; ++k) soup.add({-1, -1, 0}, {1, -1, 0}, {0, 1, 0});
  RayStream rays;
  rays.resize(4);
  std::vector<std::uint8_t> active(4, 1);
  for (int i = 0; i < 4; ++i) rays.set(i, Ray{glm::vec3(0.1f * i, 0, 2), glm::vec3(0, 0, -1)});
  const TraceResult r = trace(1, soup, rays, active, 2, 2, 0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(r.hits.triangle[i], 0u);
  const TraceResult b = trace(1, soup, rays, active, 2, 2, 16);  // 4·side² = 16: 32 root pairs split
  EXPECT_GT(b.stats.overflow_batches, 0u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(b.hits.triangle[i], 0u);
}

// The leaf test after the sphere test never drops a pair the exact watertight test accepts.
// Adversarial pairs: rays aimed at vertices, at points on edges and just inside/outside
// them, grazing rays nearly in the plane, axis-aligned triangles (boxes of zero thickness),
// slivers, triangles far from the origin (coordinates up to 1e3) and ranges [tmin, tmax]
// ending right at the hit. Non-vacuous: it rejects the triangles behind the origin, and
// most of the misses among rays through a triangle's bounding ball.
TEST(RayHierarchy, LeafTestKeepsEveryExactHit) {
  int exact_hits = 0, behind = 0, behind_kept = 0;
  for (std::uint32_t c = 0; c < 200000; ++c) {
    const float scale = (c % 5 == 0) ? 1000.0f : (c % 5 == 1 ? 0.01f : 1.0f);
    const glm::vec3 centre = rnd3(c, 81, -1.0f, 1.0f) * scale * 3.0f;
    glm::vec3 v[3];
    for (int k = 0; k < 3; ++k) v[k] = centre + rnd3(c, 82 + k, -1.0f, 1.0f) * scale * 0.3f;
    switch (c % 7) {
      case 0: v[0].y = v[1].y = v[2].y = centre.y; break;  // axis-aligned: a flat box
      case 1: v[2] = v[0] + (v[1] - v[0]) * 0.37f + rnd3(c, 85, -1e-4f, 1e-4f) * scale; break;  // sliver
      case 2: v[1].x = v[0].x, v[2].x = v[0].x; break;
      default: break;
    }
    // The target: a vertex, a point on an edge, or a point in or near the triangle.
    const float w1 = rnd(c, 0, 86), w2 = rnd(c, 1, 86);
    glm::vec3 target;
    switch (c % 4) {
      case 0: target = v[c % 3]; break;
      case 1: target = v[0] + w1 * (v[1] - v[0]); break;
      case 2: target = v[0] + w1 * (v[1] - v[0]) + w2 * (1.0f - w1) * (v[2] - v[0]); break;
      default: target = v[0] + (w1 * 1.2f - 0.1f) * (v[1] - v[0]) + (w2 * 1.2f - 0.1f) * (v[2] - v[0]); break;
    }
    glm::vec3 o;
    const glm::vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
    if (c % 9 == 0 && glm::length(n) > 0.0f) {
      // Grazing: the origin nearly in the plane, far from the target.
      const glm::vec3 in_plane = glm::normalize(glm::cross(n, rnd3(c, 87, -1.0f, 1.0f)));
      o = target + in_plane * scale * 2.0f + glm::normalize(n) * scale * 1e-4f * (rnd(c, 2, 86) - 0.5f);
    } else {
      o = target + rnd3(c, 88, -1.0f, 1.0f) * scale * (c % 3 == 0 ? 0.01f : 2.0f);
    }
    glm::vec3 d = target - o;
    const bool reversed = c % 11 == 0 && c % 9 != 0;
    if (reversed) d = -d;  // the triangle behind the origin
    if (!(glm::length(d) > 0.0f)) continue;
    d *= 0.5f + 2.0f * rnd(c, 3, 86);  // unnormalized directions, as the rays carry them
    float tmin = 0.0f, tmax = 1e30f;
    TriangleHit hit;
    const RayShear shear(o, d);
    if (c % 13 == 0 && intersect_triangle_watertight(shear, v[0], v[1], v[2], 0.0f, 1e30f, hit)) {
      tmax = hit.t;  // a range that ends exactly at the hit (shadow rays)
      tmin = c % 2 ? hit.t : 0.0f;
    }
    const TriangleLeafBounds lt = triangle_leaf_bounds(v[0], v[1], v[2]);
    const bool kept = leaf_may_hit(o, d, tmin, tmax, lt);
    if (intersect_triangle_watertight(shear, v[0], v[1], v[2], tmin, tmax, hit)) {
      ++exact_hits;
      ASSERT_TRUE(kept) << "case " << c;
      continue;
    }
    if (reversed) {
      ++behind;
      behind_kept += kept;
      continue;
    }
  }
  EXPECT_GT(exact_hits, 60000);
  EXPECT_GT(behind, 10000);
  EXPECT_LT(behind_kept, behind / 100);  // only origins within the tolerance of the plane
  // Typical pairs: rays through random points of the triangle's bounding ball, from random
  // origins; of those that meet the ball and miss the triangle, the test rejects many
  // (the rest cross the plane inside the box, outside the triangle).
  int sphere_misses = 0, sphere_misses_kept = 0;
  for (std::uint32_t c = 0; c < 20000; ++c) {
    glm::vec3 v[3];
    for (int k = 0; k < 3; ++k) v[k] = rnd3(c, 91 + k, -0.5f, 0.5f);
    const glm::vec3 centroid = (v[0] + v[1] + v[2]) / 3.0f;
    const float rho = std::max({glm::length(v[0] - centroid), glm::length(v[1] - centroid), glm::length(v[2] - centroid)});
    const glm::vec3 o = rnd3(c, 94, -3.0f, 3.0f);
    const glm::vec3 d = centroid + unit_vector(c, 95) * rho * std::cbrt(rnd(c, 0, 96)) - o;
    TriangleHit hit;
    const bool exact = intersect_triangle_watertight(RayShear(o, d), v[0], v[1], v[2], 0.0f, 1e30f, hit);
    const bool kept = leaf_may_hit(o, d, 0.0f, 1e30f, triangle_leaf_bounds(v[0], v[1], v[2]));
    if (exact) {
      EXPECT_TRUE(kept) << "typical case " << c;
    } else {
      ++sphere_misses;
      sphere_misses_kept += kept;
    }
  }
  EXPECT_GT(sphere_misses, 5000);
  EXPECT_LT(sphere_misses_kept, sphere_misses / 4);  // 17 % kept here
}

}  // namespace
}  // namespace speculum::trace
