// The LOD BVH and lod_trace of YU §3.2–3.4: LOD off is the threaded traversal bit for bit;
// LOD on does less work and approximates the hits; proxies and filtered radiance are
// fitted as documented in trace/lod_bvh.h; the stream kernel is thread-count independent.
#include <bit>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "trace/lod_bvh.h"
#include "trace/lod_trace.h"
#include "test_meshes.h"

namespace speculum::trace {
namespace {

using testing::Soup;

Soup sphere_and_soup() {
  Soup s = testing::uv_sphere(24, 48, glm::vec3(0.3f, -0.2f, 0.1f), 0.8f);
  const Soup r = testing::random_soup(400, 11);
  for (std::size_t t = 0; t < r.indices.size(); t += 3)
    s.add(r.positions[r.indices[t]], r.positions[r.indices[t + 1]], r.positions[r.indices[t + 2]]);
  return s;
}

std::vector<glm::vec3> area_radiance(const Soup& s) {
  std::vector<glm::vec3> L(s.indices.size() / 3);
  for (std::size_t t = 0; t < L.size(); ++t)
    L[t] = glm::vec3(testing::rnd(static_cast<std::uint32_t>(t), 0, 3), testing::rnd(static_cast<std::uint32_t>(t), 1, 3), 0.5f);
  return L;
}

Ray random_ray(std::uint32_t i, std::uint32_t seed) {
  Ray r;
  r.origin = testing::rnd3(i, seed, -3.0f, 3.0f);
  const glm::vec3 target = testing::rnd3(i, seed + 7, -0.8f, 0.8f);
  r.direction = glm::normalize(target - r.origin);
  return r;
}

TEST(YuLod, LodOffIsTheThreadedTraversalBitForBit) {
  par::Executor ex(2);
  const Soup s = sphere_and_soup();
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const LodBvh lod = build_lod_bvh(bvh, area_radiance(s));
  for (const LodOptions opt : {LodOptions{false, 10.0f}, LodOptions{true, 1e-6f}}) {
    int hits = 0;
    for (std::uint32_t i = 0; i < 3000; ++i) {
      const Ray r = random_ray(i, 5);
      TraversalCounters ca;
      LodCounters cl;
      const Hit a = closest_hit_threaded(bvh, r, &ca);
      const LodHit b = closest_hit_lod(bvh, lod, r, 0.01f, opt, &cl);
      ASSERT_EQ(a.triangle, b.triangle) << i;
      EXPECT_EQ(b.proxy, kNoHit);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(a.t), std::bit_cast<std::uint32_t>(b.t)) << i;
      EXPECT_EQ(std::bit_cast<std::uint32_t>(a.u), std::bit_cast<std::uint32_t>(b.u)) << i;
      EXPECT_EQ(std::bit_cast<std::uint32_t>(a.v), std::bit_cast<std::uint32_t>(b.v)) << i;
      EXPECT_EQ(ca.nodes_visited, cl.traversal.nodes_visited);
      EXPECT_EQ(ca.triangle_tests, cl.traversal.triangle_tests);
      EXPECT_EQ(cl.lod_stops, 0u);
      hits += a.hit();
    }
    EXPECT_GT(hits, 1000);  // the comparison covered hits, not only misses
  }
}

TEST(YuLod, LodOnDoesLessWorkAndApproximatesAFarSphere) {
  par::Executor ex(2);
  // A finely tessellated sphere (about 32K triangles) seen from far away with glossy-ray
  // solid angles: the LOD test stops high in the tree.
  const Soup s = testing::uv_sphere(128, 128, glm::vec3(0.0f), 1.0f);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const LodBvh lod = build_lod_bvh(bvh, area_radiance(s));
  const glm::vec3 eye(0.0f, 0.5f, 12.0f);
  const float omega = 2.0f * kPi / 30.0f * 1e-3f;
  LodCounters off_c, on_c;
  int agree = 0, total = 0, hits = 0;
  double t_err = 0.0;
  for (std::uint32_t i = 0; i < 4000; ++i) {
    Ray r;
    r.origin = eye;
    r.direction = glm::normalize(testing::rnd3(i, 9, -1.2f, 1.2f) - eye);
    const LodHit a = closest_hit_lod(bvh, lod, r, omega, LodOptions{false, 0.0f}, &off_c);
    const LodHit b = closest_hit_lod(bvh, lod, r, omega, LodOptions{true, 3.0f}, &on_c);
    ++total;
    agree += a.hit() == b.hit();
    if (a.hit() && b.hit()) {
      ++hits;
      t_err += std::fabs(a.t - b.t);
    }
  }
  EXPECT_GT(on_c.lod_stops, 0u);
  EXPECT_GT(on_c.proxy_hits, 0u);
  EXPECT_LT(on_c.traversal.nodes_visited, off_c.traversal.nodes_visited / 2);
  EXPECT_LT(on_c.traversal.triangle_tests, off_c.traversal.triangle_tests / 4);
  EXPECT_GT(static_cast<double>(agree) / total, 0.95);  // silhouettes may flip
  ASSERT_GT(hits, 500);
  EXPECT_LT(t_err / hits, 0.05);  // mean depth error small against the distance 12
}

TEST(YuLod, PlanarNodesGetAQuadInTheirPlaneAndRadianceIsAreaWeighted) {
  par::Executor ex(1);
  // A flat 32×32-cell grid in z = 0.5 facing +Z.
  Soup s;
  const int n = 32;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::vec3 a(x, y, 0.5f), b(x + 1, y, 0.5f), c(x + 1, y + 1, 0.5f), d(x, y + 1, 0.5f);
      s.add(a, b, c);
      s.add(a, c, d);
    }
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const std::vector<glm::vec3> L = area_radiance(s);
  const LodBvh lod = build_lod_bvh(bvh, L);
  ASSERT_EQ(lod.nodes.size(), bvh.threaded_nodes().size());
  glm::dvec3 mean(0.0);
  for (const glm::vec3& l : L) mean += glm::dvec3(l);
  mean /= static_cast<double>(L.size());  // equal areas
  EXPECT_NEAR(lod.nodes[0].area, n * n, 1e-3);
  EXPECT_NEAR(lod.nodes[0].radiance.x, mean.x, 1e-5);
  EXPECT_NEAR(lod.nodes[0].radiance.y, mean.y, 1e-5);
  for (std::size_t k = 0; k < lod.nodes.size(); ++k) {
    const LodNode& ln = lod.nodes[k];
    ASSERT_TRUE(ln.quad) << k;
    EXPECT_NEAR(std::fabs(ln.normal.z), 1.0f, 1e-6f);
    EXPECT_NEAR(ln.origin.z, 0.5f, 1e-5f);
    // The quad spans exactly the node's box in x and y (axis-aligned cells).
    const Aabb& box = bvh.threaded_nodes()[k].box;
    const glm::vec3 far = ln.origin + ln.edge_u + ln.edge_v;
    EXPECT_NEAR(std::min(ln.origin.x, far.x), box.lo.x, 1e-4f);
    EXPECT_NEAR(std::max(ln.origin.x, far.x), box.hi.x, 1e-4f);
    EXPECT_NEAR(std::min(ln.origin.y, far.y), box.lo.y, 1e-4f);
    EXPECT_NEAR(std::max(ln.origin.y, far.y), box.hi.y, 1e-4f);
    if (k != 0) {
      EXPECT_NE(ln.parent, kThreadEnd);
    }
  }
  // Every ray straight down hits the plane at the same t with or without LOD.
  for (std::uint32_t i = 0; i < 500; ++i) {
    Ray r;
    r.origin = glm::vec3(0.5f + 31.0f * testing::rnd(i, 0, 2), 0.5f + 31.0f * testing::rnd(i, 1, 2), 40.0f);
    r.direction = glm::vec3(0.0f, 0.0f, -1.0f);
    const LodHit a = closest_hit_lod(bvh, lod, r, 0.05f, LodOptions{false, 0.0f});
    const LodHit b = closest_hit_lod(bvh, lod, r, 0.05f, LodOptions{true, 10.0f});
    ASSERT_TRUE(a.hit() && b.hit()) << i;
    EXPECT_NE(b.proxy, kNoHit);
    EXPECT_NEAR(a.t, b.t, 1e-4f);
  }
}

// A flat grid in z = 0.5 facing +Z over the cells (x, y) with keep(x, y).
template <class Keep>
Soup flat_cells(int n, const Keep& keep) {
  Soup s;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (!keep(x, y)) continue;
      const glm::vec3 a(x, y, 0.5f), b(x + 1, y, 0.5f), c(x + 1, y + 1, 0.5f), d(x, y + 1, 0.5f);
      s.add(a, b, c);
      s.add(a, c, d);
    }
  return s;
}

Ray straight_down(float x, float y) {
  Ray r;
  r.origin = glm::vec3(x, y, 40.0f);
  r.direction = glm::vec3(0.0f, 0.0f, -1.0f);
  return r;
}

// A proxy's radiance texture follows what it stands for: radiance rising linearly across a
// flat grid is read back at a proxy hit within a few percent of the triangle under the hit,
// where the node's one mean misses by up to half the range; and the build with an executor
// gives the same texels as without.
TEST(YuLod, ProxyTextureFollowsARadianceGradient) {
  const int n = 32;
  const Soup s = flat_cells(n, [](int, int) { return true; });
  par::Executor ex1(1), ex2(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex1);
  std::vector<glm::vec3> L(s.indices.size() / 3);
  for (std::size_t t = 0; t < L.size(); ++t) {
    const glm::vec3 c = (s.positions[s.indices[3 * t]] + s.positions[s.indices[3 * t + 1]] +
                         s.positions[s.indices[3 * t + 2]]) / 3.0f;
    L[t] = glm::vec3(c.x / n, 1.0f - c.y / n, 0.5f);
  }
  const LodBvh lod = build_lod_bvh(bvh, L);
  const LodBvh lod2 = build_lod_bvh(bvh, L, &ex2);
  ASSERT_EQ(lod.proxy_texels.size(), lod2.proxy_texels.size());
  ASSERT_FALSE(lod.proxy_texels.empty());
  for (std::size_t i = 0; i < lod.proxy_texels.size(); ++i) ASSERT_EQ(lod.proxy_texels[i], lod2.proxy_texels[i]) << i;
  ASSERT_NE(lod.nodes[0].texels, kNoTexels);  // the root stands for 2048 triangles
  double texture_error = 0.0, mean_error = 0.0;
  int hits = 0;
  for (std::uint32_t i = 0; i < 400; ++i) {
    const float x = 2.0f + 28.0f * testing::rnd(i, 0, 5), y = 2.0f + 28.0f * testing::rnd(i, 1, 5);
    const LodHit h = closest_hit_lod(bvh, lod, straight_down(x, y), 0.05f, LodOptions{true, 1000.0f});
    ASSERT_EQ(h.proxy, 0u) << i;  // α large enough to stop at the root
    const glm::vec3 truth(x / n, 1.0f - y / n, 0.5f);
    texture_error = std::max(texture_error, double(glm::length(lod.proxy_radiance(h.proxy, h.u, h.v) - truth)));
    mean_error = std::max(mean_error, double(glm::length(lod.nodes[0].radiance - truth)));
    ++hits;
  }
  EXPECT_EQ(hits, 400);
  // Texels are 4 cells wide; bilinear between texel means reproduces a linear ramp inside
  // the outer half-texel, and each triangle's value sits at its centroid (≤ 1/2 cell off).
  EXPECT_LT(texture_error, 0.04);
  EXPECT_GT(mean_error, 0.5);
}

// Coverage: over a grid with its upper-right triangle removed, a ray through the empty
// corner of the root's quad passes the proxy (and misses, as without LOD), while rays over
// the cells still hit it.
TEST(YuLod, ProxyCoverageLetsRaysThroughWhereTheSurfaceIsNot) {
  const int n = 32;
  const Soup s = flat_cells(n, [&](int x, int y) { return x + y < n; });
  par::Executor ex(1);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const LodBvh lod = build_lod_bvh(bvh, area_radiance(s));
  ASSERT_TRUE(lod.nodes[0].quad);
  for (const glm::vec2 p : {glm::vec2(31.0f, 31.0f), glm::vec2(29.5f, 30.5f), glm::vec2(25.0f, 30.0f)}) {
    const LodHit off = closest_hit_lod(bvh, lod, straight_down(p.x, p.y), 0.05f, LodOptions{false, 0.0f});
    const LodHit on = closest_hit_lod(bvh, lod, straight_down(p.x, p.y), 0.05f, LodOptions{true, 1000.0f});
    EXPECT_FALSE(off.hit()) << p.x << "," << p.y;
    EXPECT_FALSE(on.hit()) << p.x << "," << p.y;
  }
  for (const glm::vec2 p : {glm::vec2(2.0f, 2.0f), glm::vec2(10.0f, 12.0f), glm::vec2(3.0f, 25.0f)}) {
    const LodHit on = closest_hit_lod(bvh, lod, straight_down(p.x, p.y), 0.05f, LodOptions{true, 1000.0f});
    EXPECT_EQ(on.proxy, 0u) << p.x << "," << p.y;
    EXPECT_NEAR(on.t, 39.5f, 1e-4f);
  }
}

TEST(YuLod, StreamKernelIsThreadCountIndependent) {
  const Soup s = sphere_and_soup();
  par::Executor ex1(1), ex2(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex1);
  const LodBvh lod = build_lod_bvh(bvh, area_radiance(s));
  RayStream rays;
  const std::size_t n = 5000;
  rays.resize(n);
  std::vector<float> omega(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    rays.set(i, random_ray(i, 3));
    omega[i] = 0.001f + 0.05f * testing::rnd(i, 4, 3);
  }
  std::vector<LodHit> h1, h2;
  LodCounters c1, c2;
  closest_hit_lod_stream(bvh, lod, rays, omega, LodOptions{true, 3.0f}, h1, ex1, &c1);
  closest_hit_lod_stream(bvh, lod, rays, omega, LodOptions{true, 3.0f}, h2, ex2, &c2);
  ASSERT_EQ(h1.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(std::bit_cast<std::uint32_t>(h1[i].t), std::bit_cast<std::uint32_t>(h2[i].t));
    EXPECT_EQ(h1[i].triangle, h2[i].triangle);
    EXPECT_EQ(h1[i].proxy, h2[i].proxy);
  }
  EXPECT_EQ(c1.traversal.nodes_visited, c2.traversal.nodes_visited);
  EXPECT_EQ(c1.lod_stops, c2.lod_stops);
  EXPECT_GT(c1.lod_stops, 0u);
}

}  // namespace
}  // namespace speculum::trace
