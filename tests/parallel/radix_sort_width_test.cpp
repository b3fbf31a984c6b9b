// Radix sort at every kernel width W = 1, 4, 8, 16 (W = 1 is the scalar reference) and at
// 1, 2 and 8 threads: the stable order of std::stable_sort on every path — in-cache buckets
// after the top-digit scatter, the whole-array LSD fallback for a skewed top digit, 64-bit
// keys, keys only, streaming output into unaligned spans, and 16M keys.
#include "parallel/partition.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <utility>
#include <vector>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

// The serial reference, computed once per key set: std::stable_sort of (key, index) pairs by
// key (pairs rather than indices compared through the key array: no random reads, which
// matters at 16M), split into the stable order and the sorted keys.
template <class Key>
struct StableOrder {
  std::vector<std::uint32_t> order;
  std::vector<Key> keys;
};
template <class Key>
StableOrder<Key> stable_order(const std::vector<Key>& keys) {
  std::vector<std::pair<Key, std::uint32_t>> pairs(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) pairs[i] = {keys[i], std::uint32_t(i)};
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  StableOrder<Key> ref;
  ref.order.reserve(keys.size());
  ref.keys.reserve(keys.size());
  for (const auto& [k, i] : pairs) {
    ref.keys.push_back(k);
    ref.order.push_back(i);
  }
  return ref;
}

// Sorts `keys` with payload and keys only at width W into spans `offset` elements past a
// buffer's start (unaligned outputs when offset > 0); both must give the stable order.
// `scratch`, when given, is reused across calls (the allocation-free form of 16M sorts).
template <int W, class Key>
void check_width(const std::vector<Key>& keys, const StableOrder<Key>& ref, int threads, std::size_t offset = 0,
                 RadixSortScratch<Key>* scratch = nullptr) {
  const std::size_t n = keys.size();
  std::vector<Key> kbuf(n + offset);
  std::vector<std::uint32_t> pbuf(n + offset);
  const std::span<Key> k(kbuf.data() + offset, n);
  const std::span<std::uint32_t> p(pbuf.data() + offset, n);
  std::copy(keys.begin(), keys.end(), k.begin());
  std::iota(p.begin(), p.end(), 0u);
  radix_sort<W>(executor(threads), "radix_w", k, p, scratch);
  ASSERT_TRUE(std::equal(p.begin(), p.end(), ref.order.begin())) << "n=" << n << " W=" << W << " t=" << threads;
  ASSERT_TRUE(std::equal(k.begin(), k.end(), ref.keys.begin())) << "n=" << n << " W=" << W << " t=" << threads;
  std::copy(keys.begin(), keys.end(), k.begin());
  radix_sort<W>(executor(threads), "radix_w_keys", k, {}, scratch);
  ASSERT_TRUE(std::equal(k.begin(), k.end(), ref.keys.begin()))
      << "n=" << n << " W=" << W << " t=" << threads << " keys only";
}

// Every kernel width × 1/2/8 threads against one reference.
template <class Key>
void check_every_width(const std::vector<Key>& keys, std::size_t offset = 0, RadixSortScratch<Key>* scratch = nullptr) {
  const auto ref = stable_order(keys);
  for (int t : kThreadCounts)
    for_each_lane_width([&](auto w) { check_width<w.value>(keys, ref, t, offset, scratch); });
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

// 16M 32-bit keys with payload (and keys only), every W × 1/2/8 threads, one scratch reused
// throughout. 20-bit keys: about 16 copies of each key, so stability is visible; 32-bit
// keys: two in-cache passes per bucket after the top-digit scatter.
TEST(RadixSortWidth, SixteenMillionKeysEqualStableSort) {
  std::vector<std::uint32_t> keys(kLargeSize);
  RadixSortScratch<std::uint32_t> scratch;
  for (std::uint32_t mask : {0xfffffu, 0xffffffffu}) {
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = hash32(i) & mask;
    ASSERT_NO_FATAL_FAILURE(check_every_width(keys, 0, &scratch)) << std::hex << mask;
  }
}

}  // namespace
}  // namespace speculum::par
