// Stable partition, radix sort (32/64-bit keys with payload), segmented min/argmin and
// histogram against serial references for every size class and 1/2/8 threads; the
// W-templated ones (partition, segmented min, histogram) at every kernel width W = 1, 4, 8, 16.
#include "parallel/partition.h"
#include "parallel/segmented.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

// partition_stable at every lane width × 1/2/8 threads against the serial stable partition:
// bucket by bucket in id order, each bucket's indices ascending, and the bucket boundaries.
void check_partition(const std::vector<std::uint32_t>& bucket, std::uint32_t p, const std::string& label) {
  const std::size_t n = bucket.size();
  std::vector<std::uint32_t> ref, ref_begin;
  for (std::uint32_t d = 0; d < p; ++d) {
    ref_begin.push_back(std::uint32_t(ref.size()));
    for (std::size_t i = 0; i < n; ++i)
      if (bucket[i] == d) ref.push_back(std::uint32_t(i));
  }
  ref_begin.push_back(std::uint32_t(n));
  for_each_lane_width([&](auto w) {
    for (int t : kThreadCounts) {
      std::vector<std::uint32_t> out(n, 0xdeadbeefu), begin(p + 1, 0xdeadbeefu);
      partition_stable<w.value>(executor(t), "partition", bucket, p, out, begin);
      ASSERT_EQ(out, ref) << label << " p=" << p << " W=" << w.value << " t=" << t;
      ASSERT_EQ(begin, ref_begin) << label << " p=" << p << " W=" << w.value << " t=" << t;
    }
  });
}

TEST(Partition, StableBucketsEqualSerial) {
  for (std::size_t n : sizes())
    for (std::uint32_t p : {1u, 2u, 7u, 300u}) {
      std::vector<std::uint32_t> bucket(n);
      for (std::size_t i = 0; i < n; ++i) bucket[i] = hash32(i * 3 + p) % p;
      check_partition(bucket, p, "n=" + std::to_string(n));
    }
  std::vector<std::uint32_t> bad = {0, 5}, out(2), begin(5);
  EXPECT_THROW(partition_stable(executor(2), "p", bad, 4, out, begin), std::invalid_argument);
  // An out-of-range id in any lane of a group (or in the tail) is caught at every W.
  for (std::size_t at : {0u, 3u, 8u, 16u, 18u}) {
    std::vector<std::uint32_t> ids(19, 1), o(19), bb(5);
    ids[at] = 4;
    for_each_lane_width([&](auto w) {
      EXPECT_THROW(partition_stable<w.value>(executor(2), "p", ids, 4, o, bb), std::invalid_argument)
          << "W=" << w.value << " at " << at;
    });
  }
}

// Every share 0..100 % of the elements in one bucket, at a size of four scatter chunks (the
// last one partial), so each chunk's offsets come from uneven per-chunk counts: p = 2 (the
// compaction split of ROGER §4.5, bucket 0 = the kept share), and p = 7 with that share in
// bucket 3, the rest spread over the others except bucket 5, which stays empty.
TEST(Partition, EveryBucketShareAcrossChunksEqualsSerial) {
  const std::size_t n = 3 * kScatterChunk + 7;
  constexpr std::uint32_t others[] = {0, 1, 2, 4, 6};
  std::vector<std::uint32_t> two(n), seven(n);
  for (int percent = 0; percent <= 100; percent += kPercentStep) {
    const auto in_share = flags(n, percent, n + std::size_t(percent));
    for (std::size_t i = 0; i < n; ++i) {
      two[i] = in_share[i] ? 0u : 1u;
      seven[i] = in_share[i] ? 3u : others[hash32(i * 5 + std::size_t(percent)) % 5];
    }
    ASSERT_NO_FATAL_FAILURE(check_partition(two, 2, std::to_string(percent) + "%"));
    ASSERT_NO_FATAL_FAILURE(check_partition(seven, 7, std::to_string(percent) + "%"));
  }
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

// 16M 32-bit keys (every W × 1/2/8 threads, one reference): radix_sort_width_test.cpp.

// Both segmented-min forms (ids as given, and sorted) at every lane width and thread count
// equal serial_segmented_min on the same ids.
void check_segmented_min(const std::vector<std::uint32_t>& seg, const std::vector<float>& value,
                         std::uint32_t segments, const std::string& label) {
  std::vector<float> ref_v, ref_sv;
  std::vector<std::uint32_t> ref_i, ref_si;
  serial_segmented_min(seg, value, segments, ref_v, ref_i);
  auto sorted_seg = seg;
  std::sort(sorted_seg.begin(), sorted_seg.end());
  serial_segmented_min(sorted_seg, value, segments, ref_sv, ref_si);
  for_each_lane_width([&](auto w) {
    for (int t : kThreadCounts) {
      std::vector<float> v(segments);
      std::vector<std::uint32_t> ix(segments);
      segmented_min<w.value>(executor(t), "closest_hit", seg, value, segments, v, ix);
      ASSERT_EQ(v, ref_v) << label << " W=" << w.value << " t=" << t;
      ASSERT_EQ(ix, ref_i) << label << " W=" << w.value << " t=" << t;
      segmented_min_sorted<w.value>(executor(t), "closest_hit_sorted", sorted_seg, value, segments, v, ix);
      ASSERT_EQ(v, ref_sv) << label << " W=" << w.value << " t=" << t;
      ASSERT_EQ(ix, ref_si) << label << " W=" << w.value << " t=" << t;
    }
  });
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
    check_segmented_min(seg, t, segments, "n=" + std::to_string(n));
  }
  std::vector<std::uint32_t> unsorted = {1, 0};
  std::vector<float> v(2), t = {1, 2};
  std::vector<std::uint32_t> ix(2);
  EXPECT_THROW(segmented_min_sorted(executor(1), "bad", unsorted, t, 2, v, ix), std::invalid_argument);
  // A descent or an out-of-range id in any lane of a W-group (or the tail) is caught at every W.
  for (std::size_t at : {1u, 5u, 8u, 15u, 17u}) {
    std::vector<std::uint32_t> ids(19);
    for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = std::uint32_t(i / 2);
    std::vector<float> vals(19, 1.f), mv(10);
    std::vector<std::uint32_t> mi(10);
    for_each_lane_width([&](auto w) {
      auto down = ids;
      down[at] = down[at - 1] - 1;
      EXPECT_THROW(segmented_min_sorted<w.value>(executor(2), "down", down, vals, 10, mv, mi), std::invalid_argument)
          << "W=" << w.value << " at " << at;
      auto high = ids;
      for (std::size_t i = at; i < high.size(); ++i) high[i] = 10;
      EXPECT_THROW(segmented_min_sorted<w.value>(executor(2), "high", high, vals, 10, mv, mi), std::invalid_argument)
          << "W=" << w.value << " at " << at;
    });
  }
}

// The documented edge semantics (segmented.h): an empty segment (leading, middle, trailing,
// past the largest id) gets +infinity and kNoIndex; NaN never wins, so a segment of only
// NaNs has no winner either (+infinity, kNoIndex); +infinity is a real value (a segment
// whose smallest value is +infinity reports its lowest index); ties, including -0 == +0,
// go to the lowest element index and report that element's bits.
TEST(SegmentedMin, NaNNeverWinsAndEmptySegmentsGetInfinityAndNoIndex) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const std::uint32_t segments = 10;
  // Sorted ids; segments 0, 3, 8 and 9 are empty.
  const std::vector<std::uint32_t> seg = {1, 1, 1, 1, 1, 2, 2, 4, 4, 4, 5, 5, 6, 6, 6, 7, 7};
  const std::vector<float> val = {nan, 3, nan, 2, 2, nan, nan, inf, nan, inf, nan, inf, 1, -0.f, 0.f, -inf, nan};
  const std::vector<float> want_v = {inf, 2, inf, inf, inf, inf, -0.f, -inf, inf, inf};
  const std::vector<std::uint32_t> want_i = {kNoIndex, 3, kNoIndex, kNoIndex, 7, 11, 13, 15, kNoIndex, kNoIndex};
  // The same elements in reverse order (ids now unsorted): element j is element 16 - j.
  const std::vector<std::uint32_t> rseg(seg.rbegin(), seg.rend());
  const std::vector<float> rval(val.rbegin(), val.rend());
  const std::vector<float> want_rv = {inf, 2, inf, inf, inf, inf, 0.f, -inf, inf, inf};  // +0 is now first
  const std::vector<std::uint32_t> want_ri = {kNoIndex, 12, kNoIndex, kNoIndex, 7, 5, 2, 1, kNoIndex, kNoIndex};
  auto bits = [](const std::vector<float>& v) {
    std::vector<std::uint32_t> b;
    for (float x : v) b.push_back(std::bit_cast<std::uint32_t>(x));
    return b;
  };
  for_each_lane_width([&](auto w) {
    for (int t : kThreadCounts) {
      std::vector<float> v(segments, 42.f);
      std::vector<std::uint32_t> ix(segments, 42);
      segmented_min_sorted<w.value>(executor(t), "edges_sorted", seg, val, segments, v, ix);
      EXPECT_EQ(bits(v), bits(want_v)) << "W=" << w.value << " t=" << t;
      EXPECT_EQ(ix, want_i) << "W=" << w.value << " t=" << t;
      v.assign(segments, 42.f);
      ix.assign(segments, 42);
      segmented_min<w.value>(executor(t), "edges", seg, val, segments, v, ix);
      EXPECT_EQ(bits(v), bits(want_v)) << "W=" << w.value << " t=" << t;
      EXPECT_EQ(ix, want_i) << "W=" << w.value << " t=" << t;
      v.assign(segments, 42.f);
      ix.assign(segments, 42);
      segmented_min<w.value>(executor(t), "edges_reversed", rseg, rval, segments, v, ix);
      EXPECT_EQ(bits(v), bits(want_rv)) << "W=" << w.value << " t=" << t;
      EXPECT_EQ(ix, want_ri) << "W=" << w.value << " t=" << t;
      EXPECT_THROW(segmented_min_sorted<w.value>(executor(t), "reversed", rseg, rval, segments, v, ix), std::invalid_argument);
      // No elements at all: every segment is empty.
      v.assign(3, 42.f);
      ix.assign(3, 42);
      segmented_min_sorted<w.value>(executor(t), "none_sorted", {}, {}, 3, v, ix);
      EXPECT_EQ(v, std::vector<float>(3, inf));
      EXPECT_EQ(ix, std::vector<std::uint32_t>(3, kNoIndex));
      v.assign(3, 42.f);
      ix.assign(3, 42);
      segmented_min<w.value>(executor(t), "none", {}, {}, 3, v, ix);
      EXPECT_EQ(v, std::vector<float>(3, inf));
      EXPECT_EQ(ix, std::vector<std::uint32_t>(3, kNoIndex));
      segmented_min<w.value>(executor(t), "zero_segments", {}, {}, 0, std::span<float>(), std::span<std::uint32_t>());
    }
  });
  // Out-of-range ids are rejected by both forms.
  const std::vector<std::uint32_t> high = {0, 1, 3};
  const std::vector<std::uint32_t> high_unsorted = {3, 0, 1};
  const std::vector<float> three = {1, 2, 3};
  std::vector<float> v(3);
  std::vector<std::uint32_t> ix(3);
  EXPECT_THROW(segmented_min_sorted(executor(2), "high", high, three, 3, v, ix), std::invalid_argument);
  EXPECT_THROW(segmented_min(executor(2), "high", high_unsorted, three, 3, v, ix), std::invalid_argument);
}

// Many more segments than elements, across the 4096-segment chunks of the per-segment pass:
// each chunk starts its search in a long run of empty segments; only the few occupied
// segments have a winner, every other one is +infinity / kNoIndex, for 1/2/8 threads.
TEST(SegmentedMin, SparseSegmentsAcrossChunksEqualSerial) {
  const std::uint32_t segments = 3 * 4096 + 17;
  const std::size_t n = 301;
  std::vector<std::uint32_t> seg(n);
  std::vector<float> val(n);
  for (std::size_t i = 0; i < n; ++i) {
    seg[i] = hash32(i * 31) % segments;
    val[i] = hash32(i + 1) % 5 == 0 ? std::numeric_limits<float>::quiet_NaN() : float(hash32(i + 2) % 8);
  }
  seg[0] = 4095, seg[1] = 4096, seg[2] = segments - 1;  // chunk edges and the last segment
  check_segmented_min(seg, val, segments, "sparse");
}

TEST(Histogram, CountsEqualSerial) {
  for (std::size_t n : sizes())
    for (std::size_t bins : {1u, 10u, 4096u}) {
      std::vector<std::uint32_t> bin(n);
      for (std::size_t i = 0; i < n; ++i) bin[i] = hash32(i) % bins;
      std::vector<std::uint64_t> ref(bins, 0);
      for (auto b : bin) ++ref[b];
      for_each_lane_width([&](auto w) {
        for (int t : kThreadCounts) {
          std::vector<std::uint64_t> count(bins);
          histogram<w.value>(executor(t), "hist", bin, count);
          ASSERT_EQ(count, ref) << n << " bins=" << bins << " W=" << w.value << " t=" << t;
        }
      });
    }
  std::vector<std::uint32_t> bad = {3};
  std::vector<std::uint64_t> count(3);
  EXPECT_THROW(histogram(executor(1), "h", bad, count), std::invalid_argument);
  for (std::size_t at : {0u, 5u, 8u, 16u, 18u}) {
    std::vector<std::uint32_t> ids(19, 2);
    ids[at] = 0xffffffffu;  // the largest id: out of range for any count table
    std::vector<std::uint64_t> c(3);
    for_each_lane_width([&](auto w) {
      EXPECT_THROW(histogram<w.value>(executor(2), "h", ids, c), std::invalid_argument) << "W=" << w.value << " at " << at;
    });
  }
  std::vector<std::uint64_t> none;
  EXPECT_THROW(histogram(executor(1), "h", bad, none), std::invalid_argument);  // ids but no bins
}

}  // namespace
}  // namespace speculum::par
