// lanes_stream.h: every op at every W against its scalar definition (the intrinsic paths
// must give the generic path's bits).
#include "parallel/lanes_stream.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <vector>

namespace speculum::par {
namespace {

template <int W>
void check_ops(std::mt19937& rng) {
  using V = LaneU32<W>;
  std::uniform_int_distribution<std::uint32_t> any;
  for (int trial = 0; trial < 200; ++trial) {
    std::uint32_t x[W];
    for (auto& v : x) v = trial < 100 ? any(rng) : any(rng) % 8;  // wrap-around and small values
    const V v(x, stdx::element_aligned);
    const V p = prefix_sum<W>(v);
    const V l = last_lane<W>(v);
    std::uint32_t running = 0;
    for (int i = 0; i < W; ++i) {
      running += x[i];
      ASSERT_EQ(std::uint32_t(p[i]), running) << "W=" << W << " lane " << i;
      ASSERT_EQ(std::uint32_t(l[i]), x[W - 1]) << "W=" << W;
    }

    alignas(64) std::uint32_t streamed[W];
    stream_store<W>(v, streamed);
    stream_fence();
    for (int i = 0; i < W; ++i) ASSERT_EQ(streamed[i], x[i]) << "W=" << W;

    std::uint32_t pairs[2 * W];
    for (auto& w : pairs) w = any(rng);
    const auto [even, odd] = deinterleave<W>(pairs);
    for (int i = 0; i < W; ++i) {
      ASSERT_EQ(std::uint32_t(even[i]), pairs[2 * i]) << "W=" << W;
      ASSERT_EQ(std::uint32_t(odd[i]), pairs[2 * i + 1]) << "W=" << W;
    }

    std::uint8_t flags[W];
    unsigned expect = 0;
    for (int k = 0; k < W; ++k) {
      flags[k] = std::uint8_t(any(rng) % 3 == 0 ? 0 : any(rng) % 255 + 1);
      expect |= unsigned(flags[k] != 0) << k;
    }
    ASSERT_EQ(nonzero_bits<W>(flags), expect) << "W=" << W;

    const std::uint32_t first = any(rng) % 1000000;
    const V packed = left_pack<W>(expect, first);
    int k = 0;
    for (int b = 0; b < W; ++b)
      if (expect >> b & 1) {
        ASSERT_EQ(std::uint32_t(packed[k++]), first + std::uint32_t(b)) << "W=" << W;
      }
    ASSERT_EQ(k, std::popcount(expect));
  }
}

TEST(LanesStream, EveryOpAtEveryWidthMatchesItsScalarDefinition) {
  std::mt19937 rng(20261124);
  check_ops<1>(rng);
  check_ops<4>(rng);
  check_ops<8>(rng);
  check_ops<16>(rng);
}

template <int W>
void check_every_left_pack_mask() {
  for (unsigned m = 0; m < (1u << W); ++m) {
    const auto packed = left_pack<W>(m, 100);
    int k = 0;
    for (unsigned b = 0; b < unsigned(W); ++b) {
      if (m >> b & 1) {
        ASSERT_EQ(std::uint32_t(packed[k++]), 100 + b) << "W=" << W << " mask " << m;
      }
    }
  }
}

TEST(LanesStream, LeftPackCoversEveryMask) {
  check_every_left_pack_mask<1>();
  check_every_left_pack_mask<4>();
  check_every_left_pack_mask<8>();
  check_every_left_pack_mask<16>();
}

}  // namespace
}  // namespace speculum::par
