// Fixed-size traversal stacks at their real size (overflow is counted, never undefined)
// for any hit, closest hit and the 8-ray packet kernel, single and streamed. No API shrinks
// those stacks, so the geometry overflows them: a "tunnel" of clusters of slanted
// triangles at geometrically growing distances along -x, each cluster box crossed by the
// probe rays (which pass beside every triangle), so the binned SAH builds a deep lopsided
// tree whose wide nodes all have several children on the ray.
// Whatever overflows, every answer is the oracle's unless an overflow was counted.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "trace/bvh.h"
#include "trace/packet_traversal.h"
#include "trace/traversal.h"
#include "tests/trace/oracle_checks.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

using testing::bits;

struct Tunnel {
  testing::Soup soup;
  Bvh bvh;
  std::vector<Ray> probes;
};

// Clusters i = 0..149 of 16 triangles over x in [-1.2·1.5^i, -1.5^i] (up to 2.3e26); each
// triangle spans y in [0, 1], z in [-1, 1] and misses the line y = z = 0.9. A backstop
// square at x = -1e27 catches rays that pass y = z = 0.9 and are not clipped.
Tunnel make_tunnel() {
  Tunnel t;
  for (int i = 0; i < 150; ++i) {
    const float x0 = -std::pow(1.5f, static_cast<float>(i));
    for (int j = 0; j < 16; ++j) {
      const float a = x0 * (1.0f + 0.2f * j / 16.0f), b = x0 * (1.0f + 0.2f * (j + 1) / 16.0f);
      t.soup.add({a, 0, -1}, {b, 1, 0}, {a, 0, 1});
    }
  }
  const float xb = -1e27f;
  t.soup.add({xb, 0.8f, 0.8f}, {xb, 0.8f, 1.0f}, {xb, 1.0f, 1.0f});
  t.soup.add({xb, 0.8f, 0.8f}, {xb, 1.0f, 1.0f}, {xb, 1.0f, 0.8f});
  par::Executor ex(1);
  BvhBuildOptions one_per_leaf;
  one_per_leaf.max_leaf_size = 1;
  t.bvh = Bvh::build(t.soup.positions, t.soup.indices, ex, one_per_leaf);
  // Axis-aligned probes through the tunnel: to the backstop (hit) or stopping short of it
  // (miss), and a few that hit a cluster triangle on the way (y = 0.2, z = 0).
  for (int k = 0; k < 8; ++k) {
    Ray r;
    r.origin = {0.0f, 0.85f + 0.01f * k, 0.9f};
    r.direction = {-1.0f, 0.0f, 0.0f};
    if (k % 2) r.tmax = 5e26f;  // short of the backstop
    t.probes.push_back(r);
  }
  for (int k = 0; k < 4; ++k) {
    Ray r;
    r.origin = {-3.0f * k, 0.2f, 0.0f};
    r.direction = {-1.0f, 0.0f, 0.0f};
    t.probes.push_back(r);
  }
  return t;
}

TEST(TraversalOverflow, AnyHitAndClosestHitCountOverflowsAtFullStackSize) {
  const Tunnel t = make_tunnel();
  std::uint64_t any_overflows = 0, closest_overflows = 0;
  int backstop_hits = 0;
  for (std::size_t i = 0; i < t.probes.size(); ++i) {
    const Ray& r = t.probes[i];
    const bool oa = any_hit_oracle(t.soup.positions, t.soup.indices, r);
    const Hit o = closest_hit_oracle(t.soup.positions, t.soup.indices, r);
    backstop_hits += o.triangle >= t.soup.indices.size() / 3 - 2 && o.hit();
    TraversalCounters ca, cc;
    const bool a = any_hit(t.bvh, r, &ca);
    const Hit h = closest_hit(t.bvh, r, &cc);
    any_overflows += ca.stack_overflows;
    closest_overflows += cc.stack_overflows;
    // Never silently wrong: a different answer only with a counted overflow.
    if (ca.stack_overflows == 0) {
      EXPECT_EQ(a, oa) << "any hit, probe " << i;
    }
    if (cc.stack_overflows == 0) {
      EXPECT_EQ(h.triangle, o.triangle) << "closest hit, probe " << i;
      if (o.hit()) {
        EXPECT_EQ(bits(h.t), bits(o.t)) << "probe " << i;
      }
    }
    // The threaded layout is stackless: always exact.
    EXPECT_EQ(closest_hit_threaded(t.bvh, r).triangle, o.triangle) << "threaded, probe " << i;
  }
  EXPECT_EQ(backstop_hits, 4);  // the probes really cross the whole tunnel
  EXPECT_GT(any_overflows, 0u);
  EXPECT_GT(closest_overflows, 0u);

  // The stream kernel adds the per-ray counts up.
  RayStream rays;
  rays.resize(t.probes.size());
  for (std::size_t i = 0; i < t.probes.size(); ++i) rays.set(i, t.probes[i]);
  par::Executor ex(2);
  HitStream hits;
  TraversalCounters cs;
  closest_hit_stream(t.bvh, rays, hits, ex, &cs);
  EXPECT_EQ(cs.stack_overflows, closest_overflows);
}

TEST(TraversalOverflow, PacketKernelCountsOverflowsAtFullStackSize) {
  const Tunnel t = make_tunnel();
  // A coherent packet down the tunnel: no zero direction components (those fall back to
  // single rays); the y/z drift of 2e-30 per unit is 2e-3 at the backstop.
  Ray rays[kPacketSize];
  for (int k = 0; k < kPacketSize; ++k) {
    rays[k].origin = {0.0f, 0.86f + 0.01f * k, 0.9f};
    rays[k].direction = {-1.0f, 2e-30f, 2e-30f};
    rays[k].tmax = (k % 2) ? 5e26f : 3.0e38f;
  }
  Hit h[kPacketSize];
  TraversalCounters c;
  ASSERT_TRUE(closest_hit_packet(t.bvh, rays, kPacketSize, h, &c)) << "the packet path was not taken";
  EXPECT_EQ(c.rays, static_cast<std::uint64_t>(kPacketSize));
  EXPECT_GT(c.stack_overflows, 0u);
  for (int k = 0; k < kPacketSize; ++k) {
    // The packet's overflow count is the packet's, so only a packet without overflow
    // could be checked exactly; at least every reported hit is a real intersection.
    if (!h[k].hit()) continue;
    Ray clipped = rays[k];
    clipped.tmax = h[k].t;
    clipped.tmin = h[k].t;
    const Hit o = closest_hit_oracle(t.soup.positions, t.soup.indices, clipped);
    EXPECT_EQ(o.triangle, h[k].triangle) << "ray " << k;
  }
  // Streamed: one chunk, one packet; the stream's counters carry the overflow.
  RayStream stream;
  stream.resize(kPacketSize);
  for (int k = 0; k < kPacketSize; ++k) stream.set(k, rays[k]);
  par::Executor ex(2);
  HitStream hits;
  TraversalCounters cs;
  closest_hit_stream_packets(t.bvh, stream, hits, ex, &cs);
  EXPECT_EQ(cs.stack_overflows, c.stack_overflows);
  for (int k = 0; k < kPacketSize; ++k) EXPECT_EQ(hits.triangle[k], h[k].triangle);
}

// A ray with a zero direction component must reach boxes at any distance along it: the
// oracle and the threaded layout find the far triangle; so must the 8-wide box test (it used
// to scale the zero component's slab by the clamped reciprocal 1e30, so the slab ended at
// (far plane - origin) * 1e30 and a box farther along the ray was culled).
TEST(Bvh, AxisAlignedRayReachesFarBoxes) {
  testing::Soup s;
  s.add({-1, 0, -1}, {-1.2f, 1, 0}, {-1, 0, 1});          // near, beside the ray
  s.add({-1e30f, 0.8f, 0.8f}, {-1e30f, 1, 0.8f}, {-1e30f, 0.8f, 1});  // far, across the ray
  par::Executor ex(1);
  BvhBuildOptions one_per_leaf;  // a box per triangle (else the root is one leaf, no box test)
  one_per_leaf.max_leaf_size = 1;
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex, one_per_leaf);
  Ray r;
  r.origin = {0.0f, 0.85f, 0.85f};  // 0.15 below the far box's upper planes: the slab ends at 1.5e29
  r.direction = {-1.0f, 0.0f, 0.0f};
  const Hit o = closest_hit_oracle(s.positions, s.indices, r);
  ASSERT_EQ(o.triangle, 1u);
  EXPECT_EQ(closest_hit_threaded(bvh, r).triangle, 1u);
  const Hit w = closest_hit(bvh, r);
  EXPECT_EQ(w.triangle, 1u);
  EXPECT_EQ(bits(w.t), bits(o.t));
  EXPECT_TRUE(any_hit(bvh, r));
  // Stopping short of the far triangle still misses it.
  r.tmax = 0.5e30f;
  EXPECT_FALSE(closest_hit(bvh, r).hit());
  EXPECT_FALSE(any_hit(bvh, r));
  // The same along every axis and both directions.
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      testing::Soup t;
      auto place = [&](float along, float u, float v) {
        glm::vec3 p(0.0f);
        p[axis] = along;
        p[(axis + 1) % 3] = u;
        p[(axis + 2) % 3] = v;
        return p;
      };
      t.add(place(sign * 1.0f, -1.0f, -1.0f), place(sign * 1.2f, 0.0f, 1.0f), place(sign * 1.0f, 1.0f, -1.0f));
      t.add(place(sign * 1e30f, 0.8f, 0.8f), place(sign * 1e30f, 1.0f, 0.8f), place(sign * 1e30f, 0.8f, 1.0f));
      const Bvh tb = Bvh::build(t.positions, t.indices, ex, one_per_leaf);
      Ray q;
      q.origin = place(0.0f, 0.85f, 0.85f);
      q.direction = place(sign, 0.0f, 0.0f);
      const Hit qo = closest_hit_oracle(t.positions, t.indices, q);
      ASSERT_EQ(qo.triangle, 1u) << "axis " << axis << " sign " << sign;
      EXPECT_EQ(closest_hit(tb, q).triangle, 1u) << "axis " << axis << " sign " << sign;
      EXPECT_TRUE(any_hit(tb, q)) << "axis " << axis << " sign " << sign;
    }
  }
}

}  // namespace
}  // namespace speculum::trace
