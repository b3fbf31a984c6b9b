// Assertions shared by the trace tests: every single-ray query of a BVH (both layouts,
// closest and any hit) returns the all-pairs oracle's answer, bit for bit.
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "trace/bvh.h"
#include "trace/traversal.h"

namespace speculum::trace::testing {

inline std::uint32_t bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  return b;
}

// Closest hit (triangle and exact t) and any hit of the wide and threaded layouts equal the
// oracle's for every ray; counters accumulate into c. Returns how many rays the oracle says
// hit, so callers can assert the case is not vacuous.
inline int expect_single_rays_match_oracle(const std::vector<glm::vec3>& positions,
                                           const std::vector<std::uint32_t>& indices, const Bvh& bvh,
                                           const std::vector<Ray>& rays, TraversalCounters& c) {
  int hits = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray& r = rays[i];
    const Hit o = closest_hit_oracle(positions, indices, r);
    const Hit w = closest_hit(bvh, r, &c);
    const Hit t = closest_hit_threaded(bvh, r, &c);
    EXPECT_EQ(o.triangle, w.triangle) << "wide, ray " << i;
    EXPECT_EQ(o.triangle, t.triangle) << "threaded, ray " << i;
    if (o.hit()) {
      ++hits;
      EXPECT_EQ(bits(o.t), bits(w.t)) << "wide, ray " << i;
      EXPECT_EQ(bits(o.t), bits(t.t)) << "threaded, ray " << i;
    }
    const bool oa = any_hit_oracle(positions, indices, r);
    EXPECT_EQ(oa, o.hit()) << "ray " << i;
    EXPECT_EQ(oa, any_hit(bvh, r, &c)) << "wide any, ray " << i;
  }
  return hits;
}

}  // namespace speculum::trace::testing
