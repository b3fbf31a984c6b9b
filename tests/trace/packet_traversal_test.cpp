// Packet traversal tests (coherent ray streams): 8-ray packets return the
// oracle's (t, triangle) bit for bit on random, degenerate, closed and real meshes; the
// packet path is really taken for coherent rays and refused for incoherent ones; rays
// aimed at shared edges and vertices never leak; streams equal single rays for any
// thread count and any stream length (partial last packet), and a stream goes back to
// packets after incoherent rays.
#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include <algorithm>
#include <cstring>
#include <string>

#include "core/camera_rays.h"
#include "trace/bvh.h"
#include "trace/packet_traversal.h"
#include "trace/traversal.h"
#include "tests/trace/oracle_checks.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

using testing::Soup;

using testing::bits;

// Pinhole rays from `eye` through a `w` x `h` grid spanning `half_angle` (radians) around
// the direction to `target`, row by row: consecutive rays are neighbours (coherent).
std::vector<Ray> pinhole_rays(glm::vec3 eye, glm::vec3 target, int w, int h, float half_angle) {
  const glm::vec3 f = glm::normalize(target - eye);
  const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0.0f, 1.0f, 0.1f)));
  const glm::vec3 u = glm::cross(r, f);
  std::vector<Ray> rays;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float sx = (2.0f * (x + 0.5f) / w - 1.0f) * half_angle, sy = (2.0f * (y + 0.5f) / h - 1.0f) * half_angle;
      Ray ray;
      ray.origin = eye;
      ray.direction = f + sx * r + sy * u;
      rays.push_back(ray);
    }
  return rays;
}

// Two streams' hits are the same bits, ray by ray (`what` names the comparison).
void expect_same_hits(const HitStream& want, const HitStream& got, const std::string& what) {
  ASSERT_EQ(want.triangle.size(), got.triangle.size()) << what;
  for (std::size_t i = 0; i < want.triangle.size(); ++i) {
    ASSERT_EQ(want.triangle[i], got.triangle[i]) << "ray " << i << ", " << what;
    ASSERT_EQ(bits(want.t[i]), bits(got.t[i])) << "ray " << i << ", " << what;
    ASSERT_EQ(bits(want.u[i]), bits(got.u[i])) << "ray " << i << ", " << what;
    ASSERT_EQ(bits(want.v[i]), bits(got.v[i])) << "ray " << i << ", " << what;
  }
}

// Traces rays in packets of 8 and compares every ray with the oracle. Returns the number
// of hits; `packets_taken` counts packets that used the packet path.
int expect_packets_match_oracle(const Soup& s, const Bvh& bvh, const std::vector<Ray>& rays, int* packets_taken) {
  int hits = 0;
  *packets_taken = 0;
  TraversalCounters c;
  for (std::size_t i = 0; i < rays.size(); i += kPacketSize) {
    const int count = static_cast<int>(std::min<std::size_t>(kPacketSize, rays.size() - i));
    Hit h[kPacketSize];
    if (closest_hit_packet(bvh, &rays[i], count, h, &c)) ++*packets_taken;
    for (int k = 0; k < count; ++k) {
      const Hit o = closest_hit_oracle(s.positions, s.indices, rays[i + k]);
      EXPECT_EQ(o.triangle, h[k].triangle) << "ray " << i + k;
      EXPECT_EQ(bits(o.t), bits(h[k].t)) << "ray " << i + k;
      EXPECT_EQ(bits(o.u), bits(h[k].u)) << "ray " << i + k;
      EXPECT_EQ(bits(o.v), bits(h[k].v)) << "ray " << i + k;
      hits += o.hit() ? 1 : 0;
    }
  }
  EXPECT_EQ(c.stack_overflows, 0u);
  EXPECT_EQ(c.rays, rays.size());
  return hits;
}

TEST(PacketTraversal, CoherentRaysOnRandomSoupMatchOracle) {
  const Soup s = testing::random_soup(6000, 5);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  int taken = 0;
  const auto rays = pinhole_rays(glm::vec3(0.3f, 0.2f, 3.0f), glm::vec3(0.5f), 48, 40, 0.1f);
  EXPECT_GT(expect_packets_match_oracle(s, bvh, rays, &taken), 300);
  EXPECT_GT(taken, static_cast<int>(rays.size() / kPacketSize) / 2);  // the packet path is exercised
}

TEST(PacketTraversal, DegenerateSoupMatchesOracle) {
  // Zero-area, coplanar duplicates (ties go to the lower index) and huge/tiny triangles.
  Soup s = testing::random_soup(1500, 9);
  const std::size_t base = s.positions.size();
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 p = testing::rnd3(static_cast<std::uint32_t>(i), 99, 0.0f, 1.0f);
    s.positions.insert(s.positions.end(), {p, p + glm::vec3(0.1f, 0, 0), p + glm::vec3(0.2f, 0, 0)});  // collinear
    s.positions.insert(s.positions.end(), {p, p + glm::vec3(0.3f, 0.1f, 0), p + glm::vec3(0, 0.3f, 0)});
  }
  for (std::uint32_t i = 0; i < 200; ++i) {
    const auto v = static_cast<std::uint32_t>(base + 6 * i);
    s.indices.insert(s.indices.end(), {v, v + 1, v + 2, v + 3, v + 4, v + 5, v + 3, v + 4, v + 5});  // duplicate
  }
  const auto v = static_cast<std::uint32_t>(s.positions.size());
  s.positions.insert(s.positions.end(), {glm::vec3(-1e4f, -1e4f, 0.4f), glm::vec3(1e4f, -1e4f, 0.4f), glm::vec3(0, 1e4f, 0.4f),
                                         glm::vec3(0.5f), glm::vec3(0.5f + 1e-6f, 0.5f, 0.5f), glm::vec3(0.5f, 0.5f + 1e-6f, 0.5f)});
  s.indices.insert(s.indices.end(), {v, v + 1, v + 2, v + 3, v + 4, v + 5});
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  int taken = 0;
  const auto rays = pinhole_rays(glm::vec3(0.5f, 0.5f, -2.5f), glm::vec3(0.5f), 40, 40, 0.1f);
  EXPECT_GT(expect_packets_match_oracle(s, bvh, rays, &taken), 800);
  EXPECT_GT(taken, 0);
}

TEST(PacketTraversal, RealMeshMatchesOracle) {
  const Soup s = testing::read_off("/usr/share/assimp/models/OFF/Wuson.off");
  SPECULUM_REQUIRE(!s.indices.empty(), "the Debian package assimp-testmodels");
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  glm::vec3 lo(3e38f), hi(-3e38f);
  for (const glm::vec3& p : s.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 c = (lo + hi) * 0.5f;
  int taken = 0;
  const auto rays = pinhole_rays(c + glm::vec3(0.2f, 0.3f, 2.5f) * glm::length(hi - lo), c, 40, 32, 0.1f);
  EXPECT_GT(expect_packets_match_oracle(s, bvh, rays, &taken), 200);
  EXPECT_GT(taken, 0);
}

TEST(PacketTraversal, IncoherentPacketsFallBackAndStillMatch) {
  const Soup s = testing::random_soup(3000, 13);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  std::vector<Ray> rays;
  for (std::uint32_t i = 0; i < 800; ++i) rays.push_back(testing::random_ray(i, 61));
  int taken = 0;
  EXPECT_GT(expect_packets_match_oracle(s, bvh, rays, &taken), 100);
  EXPECT_EQ(taken, 0);  // random directions: signs differ within every packet
}

TEST(PacketTraversal, ClosedMeshIsWatertightAtEdgesAndVertices) {
  // Packets of 8 rays from one eye aimed at consecutive points along each edge (a narrow
  // fan): none may slip between the two triangles sharing the edge, or through a vertex.
  const glm::vec3 centre(0.3f, -0.2f, 0.1f);
  const Soup s = testing::uv_sphere(24, 48, centre, 1.3f);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  int misses = 0, taken = 0, rays_traced = 0;
  for (std::size_t t = 0; t < s.indices.size() / 3; t += 3)  // every third: the oracle is slow
    for (int e = 0; e < 3; ++e) {
      const glm::vec3 a = s.positions[s.indices[3 * t + e]], b = s.positions[s.indices[3 * t + (e + 1) % 3]];
      // The eye outside, facing the edge's midpoint (as in the single-ray watertight test).
      const glm::vec3 eye = centre + glm::normalize((a + b) * 0.5f - centre + glm::vec3(1e-3f, 2e-3f, 0)) * 5.0f;
      Ray rays[kPacketSize];
      for (int k = 0; k < kPacketSize; ++k) {
        rays[k].origin = eye;
        rays[k].direction = a + (b - a) * (static_cast<float>(k) / (kPacketSize - 1)) - eye;  // k = 0: the vertex
      }
      Hit h[kPacketSize];
      if (closest_hit_packet(bvh, rays, kPacketSize, h)) ++taken;
      for (int k = 0; k < kPacketSize; ++k) {
        misses += h[k].hit() ? 0 : 1;
        const Hit o = closest_hit_oracle(s.positions, s.indices, rays[k]);
        EXPECT_EQ(o.triangle, h[k].triangle);
        EXPECT_EQ(bits(o.t), bits(h[k].t));
        // The single-ray wide traversal too: rays at the seam's edges lie in the plane
        // z = centre.z (direction z exactly 0) with their origin on leaf box planes.
        const Hit w = closest_hit(bvh, rays[k]);
        EXPECT_EQ(o.triangle, w.triangle);
        EXPECT_EQ(bits(o.t), bits(w.t));
        ++rays_traced;
      }
    }
  EXPECT_EQ(misses, 0) << "of " << rays_traced << " rays";
  EXPECT_GT(taken, 500);
}

TEST(PacketTraversal, StreamEqualsSingleRaysForAnyThreadCount) {
  const Soup s = testing::random_soup(5000, 43);
  par::Executor ex2(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex2);
  // 1203 rays: a partial last packet and a partial last chunk; a few invalid rays too.
  const auto cam = pinhole_rays(glm::vec3(0.5f, 0.5f, 3.0f), glm::vec3(0.5f), 50, 24, 0.3f);
  RayStream rays;
  rays.resize(1203);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Ray r = i < cam.size() ? cam[i] : testing::random_ray(static_cast<std::uint32_t>(i), 5);
    if (i % 97 == 3) r.direction = glm::vec3(0.0f);
    if (i % 101 == 7) r.tmax = r.tmin - 1.0f;
    rays.set(i, r);
  }
  HitStream single;
  closest_hit_stream(bvh, rays, single, ex2);
  for (int threads : {1, 2, 8}) {
    par::Executor ex(threads);
    HitStream packed;
    TraversalCounters c;
    closest_hit_stream_packets(bvh, rays, packed, ex, &c);
    EXPECT_EQ(c.rays, rays.size());
    ASSERT_NO_FATAL_FAILURE(expect_same_hits(single, packed, std::to_string(threads) + " threads"));
  }
}

// A chunk that starts with incoherent rays traces them one by one and skips the coherence
// test on some of the packets after each refusal, but comes back to packets when the rays
// turn coherent: the same hits as single rays, and fewer nodes visited than single rays.
TEST(PacketTraversal, StreamReturnsToPacketsAfterIncoherentRays) {
  const Soup s = testing::random_soup(5000, 53);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const auto cam = pinhole_rays(glm::vec3(0.5f, 0.5f, 3.0f), glm::vec3(0.5f), 32, 16, 0.05f);
  RayStream rays;
  rays.resize(2 * kRayChunk);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    // Each chunk: 64 random rays (8 refused packets), then pinhole rays.
    const bool random = i % kRayChunk < 64;
    rays.set(i, random ? testing::random_ray(static_cast<std::uint32_t>(i), 71) : cam[i % cam.size()]);
  }
  HitStream single, packed;
  TraversalCounters single_counts, packed_counts;
  closest_hit_stream(bvh, rays, single, ex, &single_counts);
  closest_hit_stream_packets(bvh, rays, packed, ex, &packed_counts);
  ASSERT_NO_FATAL_FAILURE(expect_same_hits(single, packed, "back to packets"));
  EXPECT_GT(std::count_if(single.triangle.begin(), single.triangle.end(), [](std::uint32_t t) { return t != kNoHit; }),
            100);
  EXPECT_EQ(packed_counts.rays, rays.size());
  EXPECT_LT(packed_counts.nodes_visited, single_counts.nodes_visited);
}

// An image's rays in 4x4 pixel tiles of 16 (partial tiles at the right and bottom edges,
// invalid rays inside tiles): the same hits as single rays and as the oracle, bit for bit,
// for any thread count; the tiles take the packet path and visit fewer nodes per ray than
// runs of 8 in a row.
TEST(PacketTraversal, ImageTilesOfSixteenEqualSingleRaysAndOracle) {
  const Soup s = testing::random_soup(5000, 47);
  par::Executor ex2(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex2);
  const int w = 38, h = 27;  // neither a multiple of 4
  const auto cam = pinhole_rays(glm::vec3(0.4f, 0.6f, 3.0f), glm::vec3(0.3f), w, h, 0.2f);
  RayStream rays;
  rays.resize(cam.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Ray r = cam[i];
    if (i % 89 == 5) r.direction = glm::vec3(0.0f);
    if (i % 113 == 9) r.tmax = r.tmin - 1.0f;
    rays.set(i, r);
  }
  HitStream single;
  closest_hit_stream(bvh, rays, single, ex2);
  TraversalCounters runs;
  HitStream in_runs;
  closest_hit_stream_packets(bvh, rays, in_runs, ex2, &runs);
  int hits = 0;
  for (int threads : {1, 2, 8}) {
    par::Executor ex(threads);
    HitStream tiled;
    TraversalCounters c;
    closest_hit_stream_packets(bvh, rays, tiled, ex, &c, w);
    EXPECT_EQ(c.rays, rays.size());
    EXPECT_LT(c.nodes_visited, runs.nodes_visited);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(single.triangle[i], tiled.triangle[i]) << "ray " << i << ", " << threads << " threads";
      ASSERT_EQ(bits(single.t[i]), bits(tiled.t[i])) << "ray " << i;
      ASSERT_EQ(bits(single.u[i]), bits(tiled.u[i])) << "ray " << i;
      ASSERT_EQ(bits(single.v[i]), bits(tiled.v[i])) << "ray " << i;
      if (threads == 1) {
        const Hit o = closest_hit_oracle(s.positions, s.indices, rays.get(i));
        ASSERT_EQ(o.triangle, tiled.triangle[i]) << "ray " << i;
        ASSERT_EQ(bits(o.t), bits(tiled.t[i])) << "ray " << i;
        hits += o.hit();
      }
    }
  }
  EXPECT_GT(hits, 200);
  // One full tile through closest_hit_packet directly takes the packet path.
  Ray tile[kMaxPacketSize];
  for (int k = 0; k < kMaxPacketSize; ++k) tile[k] = cam[std::size_t(10 + k / 4) * w + 12 + k % 4];
  Hit out[kMaxPacketSize];
  EXPECT_TRUE(closest_hit_packet(bvh, tile, kMaxPacketSize, out));
  for (int k = 0; k < kMaxPacketSize; ++k) {
    const Hit o = closest_hit_oracle(s.positions, s.indices, tile[k]);
    EXPECT_EQ(o.triangle, out[k].triangle) << "lane " << k;
    EXPECT_EQ(bits(o.t), bits(out[k].t)) << "lane " << k;
  }
}

// A 16-ray packet whose rays share the shear goes against each leaf triangle in lanes;
// rays through the vertices and edges of a grid of unit squares (edge functions exactly
// zero, redone by the scalar test in double) still hit exactly the oracle's triangle, and
// rays between them too.
TEST(PacketTraversal, SixteenRaysInLanesAreWatertightAtGridVertices) {
  Soup s;
  for (int y = -4; y < 4; ++y)
    for (int x = -4; x < 4; ++x) {
      const glm::vec3 a(x, y, 0), b(x + 1, y, 0), c(x + 1, y + 1, 0), d(x, y + 1, 0);
      s.add(a, b, c);
      s.add(a, c, d);
    }
  par::Executor ex(1);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  int taken = 0;
  for (const float step : {1.0f, 0.5f, 0.25f}) {
    for (int tile = 0; tile < 4; ++tile) {
      Ray rays[kMaxPacketSize];
      for (int k = 0; k < kMaxPacketSize; ++k) {
        // Slightly tilted (no zero direction component: the packet path needs that), by
        // powers of two so the ray meets z = 0 exactly at the grid point and every edge
        // function through it is exactly zero.
        const glm::vec3 at(-2.0f + step * float(k % 4) + float(tile), -1.0f + step * float(k / 4), 0.0f);
        rays[k].direction = glm::vec3(0x1p-8f, 0x1p-7f, -1.0f);
        rays[k].origin = at - 3.0f * rays[k].direction;
      }
      Hit out[kMaxPacketSize];
      taken += closest_hit_packet(bvh, rays, kMaxPacketSize, out);
      for (int k = 0; k < kMaxPacketSize; ++k) {
        const Hit o = closest_hit_oracle(s.positions, s.indices, rays[k]);
        ASSERT_TRUE(o.hit());
        EXPECT_EQ(o.triangle, out[k].triangle) << "step " << step << " lane " << k;
        EXPECT_EQ(bits(o.t), bits(out[k].t));
        EXPECT_EQ(bits(o.u), bits(out[k].u));
        EXPECT_EQ(bits(o.v), bits(out[k].v));
      }
    }
  }
  EXPECT_EQ(taken, 12);
}

}  // namespace
}  // namespace speculum::trace
