// Stable partition, radix sort (32/64-bit keys with payload), segmented min/argmin and
// histogram against serial references for every size class and 1/2/8 threads.
#include "parallel/partition.h"
#include "parallel/segmented.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

TEST(Partition, StableBucketsEqualSerial) {
  for (std::size_t n : sizes())
    for (std::uint32_t p : {1u, 2u, 7u, 300u}) {
      std::vector<std::uint32_t> bucket(n);
      for (std::size_t i = 0; i < n; ++i) bucket[i] = hash32(i * 3 + p) % p;
      std::vector<std::uint32_t> ref, ref_begin;
      for (std::uint32_t d = 0; d < p; ++d) {
        ref_begin.push_back(std::uint32_t(ref.size()));
        for (std::size_t i = 0; i < n; ++i)
          if (bucket[i] == d) ref.push_back(std::uint32_t(i));
      }
      ref_begin.push_back(std::uint32_t(n));
      for (int t : kThreadCounts) {
        std::vector<std::uint32_t> out(n), begin(p + 1);
        partition_stable(executor(t), "partition", bucket, p, out, begin);
        ASSERT_EQ(out, ref) << n << " p=" << p << " t=" << t;
        ASSERT_EQ(begin, ref_begin);
      }
    }
  std::vector<std::uint32_t> bad = {0, 5}, out(2), begin(5);
  EXPECT_THROW(partition_stable(executor(2), "p", bad, 4, out, begin), std::invalid_argument);
}

template <class Key>
void check_radix(std::size_t n, Key mask, int threads) {
  std::vector<Key> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = (Key(hash32(i)) << (sizeof(Key) == 8 ? 29 : 0) ^ Key(hash32(i + 7))) & mask;
  std::vector<std::uint32_t> idx(n);
  std::iota(idx.begin(), idx.end(), 0u);
  auto ref = idx;
  std::stable_sort(ref.begin(), ref.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
  auto sorted = keys;
  radix_sort(executor(threads), "radix", std::span(sorted), std::span(idx));
  ASSERT_EQ(idx, ref) << n << " t=" << threads;
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(sorted[i], keys[ref[i]]);
  // Keys only (no payload): the 32-bit path scatters bare keys instead of packed pairs.
  auto bare = keys;
  radix_sort(executor(threads), "radix_keys", std::span(bare), {});
  auto ref_keys = keys;
  std::sort(ref_keys.begin(), ref_keys.end());
  ASSERT_EQ(bare, ref_keys) << n << " t=" << threads;
}

TEST(RadixSort, Keys32And64WithPayloadEqualStableSort) {
  for (std::size_t n : sizes())
    for (int t : kThreadCounts) {
      check_radix<std::uint32_t>(n, 0xffffffffu, t);
      check_radix<std::uint32_t>(n, 0x3ffu, t);  // many ties; constant high digits skipped
      check_radix<std::uint32_t>(n, 0xfff0u, t);  // varying bits not starting at bit 0
      check_radix<std::uint64_t>(n, ~std::uint64_t(0), t);
    }
  std::vector<std::uint32_t> k = {3, 1, 2};
  radix_sort(executor(1), "keys_only", std::span(k), {});
  EXPECT_EQ(k, (std::vector<std::uint32_t>{1, 2, 3}));
  std::vector<std::uint32_t> p(2);
  EXPECT_THROW(radix_sort(executor(1), "bad", std::span(k), std::span(p)), std::invalid_argument);
}

// Most keys share the top digit: one bucket would hold ~94 % of the array, so the sort
// takes its whole-array LSD path; the result is still the stable order.
TEST(RadixSort, SkewedTopDigitEqualsStableSort) {
  const std::size_t n = 300000;
  std::vector<std::uint32_t> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = i % 16 == 0 ? hash32(i) : hash32(i) & 0xffu;
  std::vector<std::uint32_t> ref(n);
  std::iota(ref.begin(), ref.end(), 0u);
  std::stable_sort(ref.begin(), ref.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
  for (int t : kThreadCounts) {
    auto sorted = keys;
    std::vector<std::uint32_t> idx(n);
    std::iota(idx.begin(), idx.end(), 0u);
    radix_sort(executor(t), "skewed", std::span(sorted), std::span(idx));
    ASSERT_EQ(idx, ref) << "t=" << t;
    auto bare = keys;
    radix_sort(executor(t), "skewed_keys", std::span(bare), {});
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(bare[i], keys[ref[i]]);
  }
}

// Past the streaming-store threshold (sorted buckets written with cache-bypassing stores),
// with key and payload spans one element off line alignment (unaligned bucket heads and
// tails): the stable order for 1, 2 and 8 threads.
TEST(RadixSort, StreamingOutputUnalignedSpansEqualStableSort) {
  const std::size_t n = (std::size_t(2) << 20) + 3;
  std::vector<std::uint32_t> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = hash32(i * 7) & 0x3fffffffu;
  std::vector<std::uint32_t> ref(n);
  std::iota(ref.begin(), ref.end(), 0u);
  std::stable_sort(ref.begin(), ref.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
  for (int t : kThreadCounts) {
    std::vector<std::uint32_t> kbuf(n + 1), pbuf(n + 2);
    const std::span<std::uint32_t> k(kbuf.data() + 1, n), p(pbuf.data() + 2, n);
    std::copy(keys.begin(), keys.end(), k.begin());
    std::iota(p.begin(), p.end(), 0u);
    radix_sort(executor(t), "radix_stream", k, p);
    ASSERT_TRUE(std::equal(p.begin(), p.end(), ref.begin())) << "t=" << t;
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(k[i], keys[ref[i]]) << i;
    std::copy(keys.begin(), keys.end(), k.begin());
    radix_sort(executor(t), "radix_stream_keys", k, {});
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(k[i], keys[ref[i]]) << i;
  }
}

TEST(RadixSort, SixteenMillion32BitKeys) {
  const std::size_t n = std::size_t(16) << 20;
  // 20-bit keys: many duplicates, stability is visible; 32-bit keys: two in-cache passes
  // per bucket after the top-digit scatter.
  for (std::uint32_t mask : {0xfffffu, 0xffffffffu}) {
    std::vector<std::uint32_t> keys(n), payload(n);
    for (std::size_t i = 0; i < n; ++i) {
      keys[i] = hash32(i) & mask;
      payload[i] = std::uint32_t(i);
    }
    const auto original = keys;
    RadixSortScratch<std::uint32_t> scratch;
    radix_sort(executor(2), "radix16M", std::span(keys), std::span(payload), &scratch);
    // Sorted, stable, and payload is a permutation mapping back to the original keys.
    std::vector<bool> seen(n, false);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(keys[i], original[payload[i]]);
      ASSERT_FALSE(seen[payload[i]]);
      seen[payload[i]] = true;
      if (i) {
        ASSERT_LE(keys[i - 1], keys[i]);
        if (keys[i - 1] == keys[i]) {
          ASSERT_LT(payload[i - 1], payload[i]);
        }
      }
    }
    auto bare = original;  // keys only: the same keys in the same order
    radix_sort(executor(2), "radix16M_keys", std::span(bare), {}, &scratch);
    ASSERT_EQ(bare, keys) << std::hex << mask;
  }
}

TEST(SegmentedMin, ClosestHitPerRayEqualsSerial) {
  for (std::size_t n : sizes()) {
    const std::uint32_t segments = std::uint32_t(n / 3 + 2);
    std::vector<std::uint32_t> seg(n);
    std::vector<float> t(n);
    for (std::size_t i = 0; i < n; ++i) {
      seg[i] = hash32(i) % segments;
      t[i] = float(hash32(i + 5) % 50);  // coarse values: many ties
    }
    std::vector<float> ref_v(segments, std::numeric_limits<float>::infinity());
    std::vector<std::uint32_t> ref_i(segments, kNoIndex);
    for (std::size_t i = 0; i < n; ++i)
      if (t[i] < ref_v[seg[i]]) ref_v[seg[i]] = t[i], ref_i[seg[i]] = std::uint32_t(i);
    auto sorted_seg = seg;
    std::sort(sorted_seg.begin(), sorted_seg.end());
    std::vector<float> ref_sv(segments, std::numeric_limits<float>::infinity());
    std::vector<std::uint32_t> ref_si(segments, kNoIndex);
    for (std::size_t i = 0; i < n; ++i)
      if (t[i] < ref_sv[sorted_seg[i]]) ref_sv[sorted_seg[i]] = t[i], ref_si[sorted_seg[i]] = std::uint32_t(i);
    for (int th : kThreadCounts) {
      std::vector<float> v(segments);
      std::vector<std::uint32_t> ix(segments);
      segmented_min(executor(th), "closest_hit", seg, t, segments, v, ix);
      ASSERT_EQ(v, ref_v);
      ASSERT_EQ(ix, ref_i) << n << " t=" << th;
      segmented_min_sorted(executor(th), "closest_hit_sorted", sorted_seg, t, segments, v, ix);
      ASSERT_EQ(v, ref_sv);
      ASSERT_EQ(ix, ref_si);
    }
  }
  std::vector<std::uint32_t> unsorted = {1, 0};
  std::vector<float> v(2), t = {1, 2};
  std::vector<std::uint32_t> ix(2);
  EXPECT_THROW(segmented_min_sorted(executor(1), "bad", unsorted, t, 2, v, ix), std::invalid_argument);
}

TEST(Histogram, CountsEqualSerial) {
  for (std::size_t n : sizes())
    for (std::size_t bins : {1u, 10u, 4096u}) {
      std::vector<std::uint32_t> bin(n);
      for (std::size_t i = 0; i < n; ++i) bin[i] = hash32(i) % bins;
      std::vector<std::uint64_t> ref(bins, 0);
      for (auto b : bin) ++ref[b];
      for (int t : kThreadCounts) {
        std::vector<std::uint64_t> count(bins);
        histogram(executor(t), "hist", bin, count);
        ASSERT_EQ(count, ref);
      }
    }
  std::vector<std::uint32_t> bad = {3};
  std::vector<std::uint64_t> count(3);
  EXPECT_THROW(histogram(executor(1), "h", bad, count), std::invalid_argument);
}

}  // namespace
}  // namespace speculum::par
