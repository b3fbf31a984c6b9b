// The repeat wrap of sample_bilinear_repeat (core/shading.h repeat_index) against the
// modulo written out for every index: inside the side, across its edges, many periods away on
// either side and at the ends of the 64-bit range, on sides of one texel and of odd sizes.
#include <gtest/gtest.h>

#include <limits>

#include "core/shading.h"

namespace speculum {
namespace {

int modulo_wrap(long long i, int n) { return static_cast<int>(((i % n) + n) % n); }

TEST(TextureLookup, RepeatWrapGivesTheModuloForEveryIndex) {
  for (const int n : {1, 2, 3, 7, 16, 4096}) {
    for (long long i = -40LL * n - 3; i <= 40LL * n + 3; ++i) {
      ASSERT_EQ(repeat_index(i, n), modulo_wrap(i, n)) << i << " on " << n;
      // The bilinear lookup's next texel, wrapped from the first.
      const int a = repeat_index(i, n);
      ASSERT_EQ(a + 1 < n ? a + 1 : 0, modulo_wrap(i + 1, n)) << i << " on " << n;
    }
    for (const long long i : {std::numeric_limits<long long>::min() + 1, std::numeric_limits<long long>::max(),
                              -(1LL << 40), 1LL << 40, (1LL << 31) - 1, 1LL << 31, -(1LL << 31), -(1LL << 31) - 1})
      ASSERT_EQ(repeat_index(i, n), modulo_wrap(i, n)) << i << " on " << n;
  }
}

}  // namespace
}  // namespace speculum
