// lanes_pack.h: nonzero_mask32 at every W against its scalar definition (the AVX2 path must
// give the group-wise definition's bits).
#include "parallel/lanes_pack.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

namespace speculum::par {
namespace {

template <int W>
void check_mask32(std::mt19937& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  for (int trial = 0; trial < 500; ++trial) {
    std::uint8_t flags[32];
    std::uint32_t expect = 0;
    for (int k = 0; k < 32; ++k) {
      // Mostly zero / nonzero mixes, with every byte value (incl. 0x80, 0xff) appearing.
      flags[k] = std::uint8_t(trial % 3 == 0 ? byte(rng) : (byte(rng) & 1 ? byte(rng) | 1 : 0));
      expect |= std::uint32_t(flags[k] != 0) << k;
    }
    ASSERT_EQ(nonzero_mask32<W>(flags), expect) << "W=" << W << " trial " << trial;
  }
}

TEST(LanesPack, NonzeroMask32EqualsScalarDefinitionAtEveryWidth) {
  std::mt19937 rng(7);
  check_mask32<1>(rng);
  check_mask32<4>(rng);
  check_mask32<8>(rng);
  check_mask32<16>(rng);
}

}  // namespace
}  // namespace speculum::par
