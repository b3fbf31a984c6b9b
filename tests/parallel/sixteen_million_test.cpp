// The large size class, kLargeSize (16M elements; 4M under a sanitizer), beside sizes 0, 1,
// odd and just over a chunk, for map, map_lanes, gather, reduce, float scan, stable
// partition, 64-bit radix sort with payload, segmented min/argmin and histogram: each
// against a serial loop written here, and identical (exact equality, floats bit for bit)
// for 1, 2 and 8 threads and, for the width-generic primitives, for every lane width
// W = 1, 4, 8, 16.
#include "parallel/partition.h"
#include "parallel/scan.h"
#include "parallel/segmented.h"
#include "parallel/stream.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

std::uint64_t hash64(std::uint64_t i) { return std::uint64_t(hash32(i)) << 32 | hash32(i ^ 0x5555555555ull); }

TEST(SixteenMillion, MapAndGatherEqualSerial) {
  const std::size_t n = kLargeSize + 3;  // a partial last chunk
  std::vector<float> in(n);
  std::vector<std::uint32_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) {
    in[i] = unit_float(i) * 200.f - 100.f;
    idx[i] = hash32(i + 11) % std::uint32_t(n);
  }
  auto f = [](float x) { return x * x * 0.5f - x / 3.f; };
  std::vector<float> map_ref(n), gather_ref(n);
  for (std::size_t i = 0; i < n; ++i) map_ref[i] = f(in[i]);
  for (std::size_t k = 0; k < n; ++k) gather_ref[k] = in[idx[k]];
  for (int t : kThreadCounts) {
    std::vector<float> out(n, -1.f);
    map(executor(t), "map16M", std::span<const float>(in), std::span(out), f);
    ASSERT_TRUE(same_bytes(out, map_ref)) << "map t=" << t;
    std::fill(out.begin(), out.end(), -1.f);
    gather(executor(t), "gather16M", std::span<const float>(in), std::span<const std::uint32_t>(idx), std::span(out));
    ASSERT_TRUE(same_bytes(out, gather_ref)) << "gather t=" << t;
  }
}

// The width-generic lanes_kernel (primitive_test_util.h) over 16M elements: every W and
// thread count gives the bits of the scalar loop.
TEST(SixteenMillion, MapLanesEveryWidthAndThreadCountEqualsScalarLoop) {
  const std::size_t n = kLargeSize + 5;  // a partial last lane group for every W > 1
  std::vector<float> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = unit_float(i) * 8.f - 4.f;
  std::vector<float> ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float v = x[i], sq = v * v;
    ref[i] = std::sqrt(std::fabs(v)) * 3.f + (sq < v ? sq : v);
  }
  for (int t : kThreadCounts)
    for (int w : {1, 4, 8, 16}) {
      const auto y = dispatch_lanes(w, [&](auto lw) { return lanes_kernel<lw.value>(executor(t), x); });
      ASSERT_TRUE(same_bytes(y, ref)) << "W=" << w << " t=" << t;
    }
}

// reduce: each chunk folded left to right from the identity, chunk results folded in chunk
// order from the identity (stream.h). Checked for the default chunk and an odd one.
TEST(SixteenMillion, ReduceFollowsChunkOrderAssociationForEveryThreadCount) {
  const std::size_t n = kLargeSize + 7;
  std::vector<float> in(n);
  std::vector<std::uint32_t> u(n);
  for (std::size_t i = 0; i < n; ++i) {
    in[i] = unit_float(i) * 1000.f - 499.f;
    u[i] = hash32(i * 5 + 1);
  }
  for (std::size_t chunk : {kStreamChunk, std::size_t(1000)}) {
    float oracle = 0.f;
    for (std::size_t b = 0; b < n; b += chunk) {
      float s = 0.f;
      for (std::size_t i = b; i < std::min(n, b + chunk); ++i) s = s + in[i];
      oracle = oracle + s;
    }
    float flat = 0.f;  // the plain serial fold: a different association
    for (float v : in) flat += v;
    // The data make the association visible, so the bit test below discriminates.
    EXPECT_NE(std::bit_cast<std::uint32_t>(oracle), std::bit_cast<std::uint32_t>(flat)) << chunk;
    std::uint64_t sum_ref = 0;
    std::uint32_t min_ref = 0xffffffffu;
    for (std::uint32_t v : u) {
      sum_ref += v;
      min_ref = v < min_ref ? v : min_ref;
    }
    for (int t : kThreadCounts) {
      const float r = reduce(executor(t), "fsum16M", std::span<const float>(in), 0.f, std::plus<float>(), chunk);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(r), std::bit_cast<std::uint32_t>(oracle)) << "chunk=" << chunk << " t=" << t;
      std::vector<std::uint64_t> wide(u.begin(), u.end());
      EXPECT_EQ(reduce(executor(t), "u64sum16M", std::span<const std::uint64_t>(wide), std::uint64_t(0),
                       std::plus<std::uint64_t>(), chunk),
                sum_ref)
          << chunk << " t=" << t;
      EXPECT_EQ(reduce(executor(t), "u32min16M", std::span<const std::uint32_t>(u), 0xffffffffu,
                       [](std::uint32_t a, std::uint32_t b) { return b < a ? b : a; }, chunk),
                min_ref)
          << chunk << " t=" << t;
    }
  }
}

// Float scans over 16M + a tail (1025 chunks, the last one partial: the chained scan's
// prefetch of the following chunk reaches a short chunk): the documented association, each
// chunk scanned from init ⊕ the preceding chunk sums folded in order, bit for bit, for every
// kernel width W (out of place, and in place for the inclusive scan) and thread count.
TEST(SixteenMillion, FloatScansMatchChunkAssociationForEveryThreadCount) {
  const std::size_t n = kLargeSize + 4099;
  std::vector<float> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = unit_float(i * 3) * 4.f - 1.9f;
  const float init = -2.5f;
  std::vector<float> ex_ref(n), in_ref(n);
  float running = init;
  for (std::size_t b = 0; b < n; b += kScanChunk) {
    const std::size_t e = std::min(n, b + kScanChunk);
    float sum = in[b];
    for (std::size_t i = b + 1; i < e; ++i) sum = sum + in[i];
    float acc = running;
    for (std::size_t i = b; i < e; ++i) {
      ex_ref[i] = acc;
      acc = acc + in[i];
      in_ref[i] = acc;
    }
    running = running + sum;
  }
  std::vector<float> out(n), inplace(n);
  for (int t : kThreadCounts)
    for_each_lane_width([&](auto w) {
      constexpr int W = w.value;
      std::fill(out.begin(), out.end(), 0.f);
      const float ex_total = exclusive_scan<W>(executor(t), "fex16M", std::span<const float>(in), std::span(out), init);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(ex_total), std::bit_cast<std::uint32_t>(running)) << "t=" << t << " W=" << W;
      ASSERT_TRUE(same_bytes(out, ex_ref)) << "exclusive t=" << t << " W=" << W;
      inplace = in;
      const float in_total =
          inclusive_scan<W>(executor(t), "fin16M", std::span<const float>(inplace), std::span(inplace), init);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(in_total), std::bit_cast<std::uint32_t>(running)) << "t=" << t << " W=" << W;
      ASSERT_TRUE(same_bytes(inplace, in_ref)) << "inclusive t=" << t << " W=" << W;
    });
}

// Stable partition: the serial counting scatter (count per bucket, offsets, then every
// element in index order). p = 2 with a 30 % / 70 % split, p = 300 uniform, p = 2048 skewed.
TEST(SixteenMillion, PartitionEqualsSerialCountingScatter) {
  const std::size_t n = kLargeSize + 1;
  std::vector<std::uint32_t> bucket(n);
  for (std::uint32_t p : {2u, 300u, 2048u}) {
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t h = hash32(i * 7 + p);
      bucket[i] = p == 2 ? (h % 100 < 30 ? 0u : 1u) : p == 300 ? h % p : (h & 1 ? 5u : (h >> 1) % p);
    }
    std::vector<std::uint32_t> ref_begin(p + 1, 0), ref(n);
    for (std::size_t i = 0; i < n; ++i) ++ref_begin[bucket[i] + 1];
    for (std::uint32_t d = 0; d < p; ++d) ref_begin[d + 1] += ref_begin[d];
    std::vector<std::uint32_t> cursor(ref_begin.begin(), ref_begin.end() - 1);
    for (std::size_t i = 0; i < n; ++i) ref[cursor[bucket[i]]++] = std::uint32_t(i);
    std::vector<std::uint32_t> out(n), begin(p + 1);
    for (int t : kThreadCounts)
      for_each_lane_width([&](auto w) {
        std::fill(out.begin(), out.end(), 0xdeadbeefu);
        partition_stable<w.value>(executor(t), "partition16M", bucket, p, out, begin);
        ASSERT_TRUE(out == ref) << "p=" << p << " t=" << t << " W=" << w.value;
        ASSERT_TRUE(begin == ref_begin) << "p=" << p << " t=" << t << " W=" << w.value;
      });
  }
}

// 64-bit keys varying in bits 20..63 (the high word sorted too, from a digit that does not
// start at bit 0) with a payload; every key occurs about three times at scattered
// positions, so stability is visible. Reference: a serial LSD counting sort of (key, index)
// on 8-bit digits over all 64 bits.
TEST(SixteenMillion, RadixSort64WithPayloadEqualsSerialStableSort) {
  const std::size_t n = kLargeSize + 9;
  const std::size_t distinct = n / 3;
  std::vector<std::uint64_t> keys(n);
  for (std::size_t i = 0; i < n; ++i) keys[i] = hash64(hash32(i) % distinct) & ~std::uint64_t(0xfffff);
  std::vector<std::uint64_t> ref_keys(keys), tmp_keys(n);
  std::vector<std::uint32_t> ref(n), tmp(n);
  std::iota(ref.begin(), ref.end(), 0u);
  for (int shift = 0; shift < 64; shift += 8) {
    std::size_t first[257] = {};
    for (std::size_t i = 0; i < n; ++i) ++first[((ref_keys[i] >> shift) & 0xff) + 1];
    for (int d = 0; d < 256; ++d) first[d + 1] += first[d];
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t to = first[(ref_keys[i] >> shift) & 0xff]++;
      tmp_keys[to] = ref_keys[i];
      tmp[to] = ref[i];
    }
    ref_keys.swap(tmp_keys);
    ref.swap(tmp);
  }
  std::vector<std::uint64_t> sorted(n);
  std::vector<std::uint32_t> payload(n);
  RadixSortScratch<std::uint64_t> scratch;
  for (int t : kThreadCounts)
    for_each_lane_width([&](auto w) {
      sorted = keys;
      std::iota(payload.begin(), payload.end(), 0u);
      radix_sort<w.value>(executor(t), "radix64_16M", std::span(sorted), std::span(payload), &scratch);
      ASSERT_TRUE(payload == ref) << "t=" << t << " W=" << w.value;
      ASSERT_TRUE(sorted == ref_keys) << "t=" << t << " W=" << w.value;
    });
}

// Closest hit per ray at 16M candidates over 4M rays (some rays with no candidate), values
// coarse (ties), with NaN (never wins) and +inf (wins only in a segment of +inf/NaN) mixed
// in. Reference: the documented rule as a serial loop — strictly smaller wins, and the
// first non-NaN value claims a segment that has no winner yet.
TEST(SixteenMillion, SegmentedMinEqualsSerialLoop) {
  const std::size_t n = kLargeSize;
  const std::uint32_t segments = std::uint32_t(n / 4);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<std::uint32_t> seg(n);
  std::vector<float> value(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t h = hash32(i + 3);
    seg[i] = hash32(i * 13) % segments;
    value[i] = h % 97 == 0 ? nan : h % 89 == 0 ? inf : float(h % 64);
  }
  std::vector<float> ref_v;
  std::vector<std::uint32_t> ref_i;
  serial_segmented_min(seg, value, segments, ref_v, ref_i);
  std::size_t empty = 0, inf_won = 0;
  for (std::uint32_t s = 0; s < segments; ++s) {
    empty += ref_i[s] == kNoIndex;
    inf_won += ref_i[s] != kNoIndex && ref_v[s] == inf;
  }
  ASSERT_GT(empty, 0u);  // the data exercise empty segments and +inf winners
  ASSERT_GT(inf_won, 0u);
  std::vector<std::uint32_t> sorted_seg(n);  // counting sort of the ids: the "sorted" input
  {
    std::vector<std::uint32_t> first(segments + 1, 0);
    for (auto s : seg) ++first[s + 1];
    for (std::uint32_t s = 0; s < segments; ++s) first[s + 1] += first[s];
    for (std::uint32_t s = 0; s < segments; ++s)
      std::fill(sorted_seg.begin() + first[s], sorted_seg.begin() + first[s + 1], s);
  }
  std::vector<float> ref_sv;
  std::vector<std::uint32_t> ref_si;
  serial_segmented_min(sorted_seg, value, segments, ref_sv, ref_si);
  std::vector<float> v(segments);
  std::vector<std::uint32_t> ix(segments);
  for (int t : kThreadCounts)
    for_each_lane_width([&](auto w) {
      constexpr int W = w.value;
      segmented_min<W>(executor(t), "closest16M", seg, value, segments, v, ix);
      ASSERT_TRUE(same_bytes(v, ref_v)) << "t=" << t << " W=" << W;
      ASSERT_TRUE(ix == ref_i) << "t=" << t << " W=" << W;
      segmented_min_sorted<W>(executor(t), "closest16M_sorted", sorted_seg, value, segments, v, ix);
      ASSERT_TRUE(same_bytes(v, ref_sv)) << "t=" << t << " W=" << W;
      ASSERT_TRUE(ix == ref_si) << "t=" << t << " W=" << W;
    });
}

TEST(SixteenMillion, HistogramEqualsSerialCounts) {
  const std::size_t n = kLargeSize + 1;
  std::vector<std::uint32_t> bin(n);
  for (std::size_t bins : {std::size_t(1), std::size_t(255), std::size_t(4096)}) {
    // Skewed: half the elements in bin bins/2.
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t h = hash32(i ^ bins);
      bin[i] = h & 1 ? std::uint32_t(bins / 2) : (h >> 1) % std::uint32_t(bins);
    }
    std::vector<std::uint64_t> ref(bins, 0);
    for (std::size_t i = 0; i < n; ++i) ++ref[bin[i]];
    for (int t : kThreadCounts)
      for_each_lane_width([&](auto w) {
        std::vector<std::uint64_t> count(bins, 12345);
        histogram<w.value>(executor(t), "hist16M", bin, count);
        ASSERT_TRUE(count == ref) << "bins=" << bins << " t=" << t << " W=" << w.value;
      });
  }
}

}  // namespace
}  // namespace speculum::par
