// The order in which the single-ray traversal pushes a node's entered children
// (wide::order_far_to_near): every entered lane exactly once, farthest first, for every
// set of entered lanes and entry distances of either sign, equal or a few ulps apart.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

#include "trace/wide_kernels.h"

namespace speculum::trace {
namespace {

// The distance's bits as an unsigned integer of the same order (what the keys compare).
std::uint32_t ordered_bits(float t) {
  std::uint32_t b;
  std::memcpy(&b, &t, sizeof b);
  return (b & 0x80000000u) ? ~b : (b | 0x80000000u);
}

TEST(ChildOrder, EnteredChildrenComeFarToNear) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> wide_range(-50.0f, 50.0f);
  for (int trial = 0; trial < 200; ++trial) {
    alignas(32) float tn[kWideArity];
    for (int k = 0; k < kWideArity; ++k) {
      tn[k] = wide_range(rng);
      if (trial % 4 == 1) tn[k] = static_cast<float>(static_cast<int>(tn[k]) % 3);  // many equal
      if (trial % 4 == 2) tn[k] = std::nextafter(1.0f, 2.0f * (k % 2));  // ulps apart
      if (trial % 4 == 3 && k % 3 == 0) tn[k] = -tn[k];
    }
    for (unsigned bits = 1; bits < 256; ++bits) {
      alignas(32) std::int32_t order[kWideArity];
      _mm256_store_si256(reinterpret_cast<__m256i*>(order),
                         wide::order_far_to_near(bits, _mm256_load_ps(tn)));
      const int hits = __builtin_popcount(bits);
      unsigned seen = 0;
      for (int i = 0; i < hits; ++i) {
        ASSERT_GE(order[i], 0);
        ASSERT_LT(order[i], kWideArity);
        ASSERT_TRUE(bits >> order[i] & 1u) << "lane " << order[i] << " was not entered";
        ASSERT_FALSE(seen >> order[i] & 1u) << "lane " << order[i] << " twice";
        seen |= 1u << order[i];
        if (i > 0) {
          // Farther first: a nearer child may precede a farther one only when their
          // distances agree in all but the 3 lowest bits (the lane's place in the key).
          const std::uint32_t prev = ordered_bits(tn[order[i - 1]]), cur = ordered_bits(tn[order[i]]);
          EXPECT_TRUE(prev >= cur || (prev >> 3) == (cur >> 3))
              << tn[order[i - 1]] << " before " << tn[order[i]] << " (bits " << bits << ")";
        }
      }
      EXPECT_EQ(seen, bits);
    }
  }
}

}  // namespace
}  // namespace speculum::trace
