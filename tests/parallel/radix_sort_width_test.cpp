// Radix sort at every kernel width W = 1, 4, 8, 16 (W = 1 is the scalar reference) and at
// 1, 2 and 8 threads: the stable order of std::stable_sort on every path — in-cache buckets
// after the top-digit scatter, the whole-array LSD fallback for a skewed top digit, 64-bit
// keys, keys only, streaming output into unaligned spans, and 16M keys.
#include "parallel/partition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

template <class Key>
std::vector<std::uint32_t> stable_order(const std::vector<Key>& keys) {
  std::vector<std::uint32_t> ref(keys.size());
  std::iota(ref.begin(), ref.end(), 0u);
  std::stable_sort(ref.begin(), ref.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
  return ref;
}

// Sorts `keys` with payload and keys only at width W into spans `offset` elements past a
// buffer's start (unaligned outputs when offset > 0); both must give the stable order.
template <int W, class Key>
void check_width(const std::vector<Key>& keys, const std::vector<std::uint32_t>& ref, int threads,
                 std::size_t offset = 0) {
  const std::size_t n = keys.size();
  std::vector<Key> kbuf(n + offset);
  std::vector<std::uint32_t> pbuf(n + offset);
  const std::span<Key> k(kbuf.data() + offset, n);
  const std::span<std::uint32_t> p(pbuf.data() + offset, n);
  std::copy(keys.begin(), keys.end(), k.begin());
  std::iota(p.begin(), p.end(), 0u);
  radix_sort<W>(executor(threads), "radix_w", k, p);
  ASSERT_TRUE(std::equal(p.begin(), p.end(), ref.begin())) << "n=" << n << " W=" << W << " t=" << threads;
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(k[i], keys[ref[i]]) << i << " W=" << W;
  std::copy(keys.begin(), keys.end(), k.begin());
  radix_sort<W>(executor(threads), "radix_w_keys", k, {});
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(k[i], keys[ref[i]]) << i << " W=" << W << " keys only";
}

template <class Key>
void check_every_width(const std::vector<Key>& keys, std::size_t offset = 0) {
  const auto ref = stable_order(keys);
  for (int t : kThreadCounts)
    for_each_lane_width([&](auto w) { check_width<w.value>(keys, ref, t, offset); });
}

TEST(RadixSortWidth, EverySizeAndKeyWidthEqualsStableSort) {
  for (std::size_t n : sizes()) {
    std::vector<std::uint32_t> k32(n), ties(n);
    std::vector<std::uint64_t> k64(n);
    for (std::size_t i = 0; i < n; ++i) {
      k32[i] = hash32(i);
      ties[i] = hash32(i) & 0x3ffu;
      k64[i] = std::uint64_t(hash32(i)) << 29 ^ hash32(i + 7);
    }
    check_every_width(k32);
    check_every_width(ties);
    check_every_width(k64);
  }
}

// ~94 % of the keys share the top digit: the whole-array LSD path.
TEST(RadixSortWidth, SkewedTopDigitEqualsStableSort) {
  std::vector<std::uint32_t> keys(300000);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = i % 16 == 0 ? hash32(i) : hash32(i) & 0xffu;
  check_every_width(keys);
}

// Past the streaming-store threshold, outputs one element off line alignment.
TEST(RadixSortWidth, StreamingOutputUnalignedSpansEqualStableSort) {
  std::vector<std::uint32_t> keys((std::size_t(2) << 20) + 3);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = hash32(i * 7) & 0x3fffffffu;
  check_every_width(keys, 1);
}

TEST(RadixSortWidth, SixteenMillionKeysEqualStableSort) {
  std::vector<std::uint32_t> keys(std::size_t(16) << 20);
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = hash32(i);
  const auto ref = stable_order(keys);
  for_each_lane_width([&](auto w) { check_width<w.value>(keys, ref, 2); });
}

}  // namespace
}  // namespace speculum::par
