// The lane width is a property of each Executor (`--lanes W` picks it per command): its
// resolution and validation, and two executors of different widths running the plain
// (width-less) primitives at the same time in one process, each matching the serial
// reference.
#include "parallel/executor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <exception>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "parallel/lanes.h"
#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

TEST(ExecutorLanes, WidthIsResolvedAndValidated) {
  EXPECT_EQ(Executor(1).lanes(), kNativeLanes);  // the default is the native widest
  EXPECT_EQ(Executor(1, 0).lanes(), kNativeLanes);
  for (int w : {1, 4, 8, 16}) EXPECT_EQ(Executor(2, w).lanes(), w);
  for (int bad : {-1, 2, 3, 5, 32}) EXPECT_THROW(Executor(1, bad), std::invalid_argument) << bad;

  Executor ex(1, 4);
  ex.set_lanes(16);
  EXPECT_EQ(ex.lanes(), 16);
  ex.set_lanes(0);
  EXPECT_EQ(ex.lanes(), kNativeLanes);
  ex.set_lanes(1);
  EXPECT_THROW(ex.set_lanes(7), std::invalid_argument);
  EXPECT_EQ(ex.lanes(), 1);  // a rejected width leaves the old one
}

// Everything a plain overload computes, for one executor.
struct PrimitiveResults {
  std::vector<std::uint32_t> scan;
  std::uint32_t scan_total = 0;
  std::vector<std::uint32_t> scattered, gathered;  // compact_scatter, compact_hierarchical
  std::vector<std::uint32_t> sorted_keys, sorted_order;
  std::vector<std::uint32_t> partitioned, bucket_begin;
  std::vector<std::uint64_t> histogram;
  std::vector<float> min_value;
  std::vector<std::uint32_t> min_index;
};

struct Inputs {
  static constexpr std::uint32_t kBuckets = 37, kBins = 100, kSegments = 500;
  std::vector<std::uint32_t> small, keys, bucket, bin, segment;
  std::vector<std::uint8_t> keep;
  std::vector<float> value;
};

Inputs make_inputs() {
  // Over one compaction chunk (the largest chunk of these primitives): several chunks each.
  const std::size_t n = kCompactChunk + 40000 + 17;
  Inputs in;
  in.keep = flags(n, 30, 5);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t h = hash32(i);
    in.small.push_back(h % 8);
    in.keys.push_back(h);
    in.bucket.push_back(hash32(i + n) % Inputs::kBuckets);
    in.bin.push_back(hash32(i + 2 * n) % Inputs::kBins);
    in.segment.push_back(hash32(i + 3 * n) % Inputs::kSegments);
    in.value.push_back(unit_float(i + 4 * n));
  }
  return in;
}

PrimitiveResults run_plain_primitives(Executor& ex, const Inputs& in) {
  const std::size_t n = in.keys.size();
  PrimitiveResults r;
  r.scan.resize(n);
  r.scan_total = exclusive_scan(ex, "scan", std::span<const std::uint32_t>(in.small), std::span(r.scan));
  r.scattered.resize(n);
  r.scattered.resize(compact_scatter(ex, "scatter", in.keep, r.scattered));
  r.gathered.resize(n);
  r.gathered.resize(compact_hierarchical(ex, "gather", in.keep, r.gathered, 16));
  r.sorted_keys = in.keys;
  r.sorted_order.resize(n);
  std::iota(r.sorted_order.begin(), r.sorted_order.end(), 0u);
  radix_sort(ex, "sort", std::span(r.sorted_keys), std::span(r.sorted_order));
  r.partitioned.resize(n);
  r.bucket_begin.resize(Inputs::kBuckets + 1);
  partition_stable(ex, "partition", in.bucket, Inputs::kBuckets, r.partitioned, r.bucket_begin);
  r.histogram.resize(Inputs::kBins);
  histogram(ex, "histogram", in.bin, r.histogram);
  r.min_value.resize(Inputs::kSegments);
  r.min_index.resize(Inputs::kSegments);
  segmented_min(ex, "closest", in.segment, in.value, Inputs::kSegments, r.min_value, r.min_index);
  return r;
}

PrimitiveResults serial_reference(const Inputs& in) {
  const std::size_t n = in.keys.size();
  PrimitiveResults r;
  for (std::uint32_t v : in.small) r.scan.push_back(r.scan_total), r.scan_total += v;
  for (std::size_t i = 0; i < n; ++i)
    if (in.keep[i]) r.scattered.push_back(std::uint32_t(i));
  r.gathered = r.scattered;
  r.sorted_order.resize(n);
  std::iota(r.sorted_order.begin(), r.sorted_order.end(), 0u);
  std::stable_sort(r.sorted_order.begin(), r.sorted_order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return in.keys[a] < in.keys[b]; });
  for (std::uint32_t i : r.sorted_order) r.sorted_keys.push_back(in.keys[i]);
  for (std::uint32_t d = 0; d < Inputs::kBuckets; ++d) {
    r.bucket_begin.push_back(std::uint32_t(r.partitioned.size()));
    for (std::size_t i = 0; i < n; ++i)
      if (in.bucket[i] == d) r.partitioned.push_back(std::uint32_t(i));
  }
  r.bucket_begin.push_back(std::uint32_t(n));
  r.histogram.assign(Inputs::kBins, 0);
  for (std::uint32_t b : in.bin) ++r.histogram[b];
  serial_segmented_min(in.segment, in.value, Inputs::kSegments, r.min_value, r.min_index);
  return r;
}

void expect_equal(const PrimitiveResults& a, const PrimitiveResults& ref, int lanes) {
  SCOPED_TRACE("lanes " + std::to_string(lanes));
  EXPECT_EQ(a.scan, ref.scan);
  EXPECT_EQ(a.scan_total, ref.scan_total);
  EXPECT_EQ(a.scattered, ref.scattered);
  EXPECT_EQ(a.gathered, ref.gathered);
  EXPECT_EQ(a.sorted_keys, ref.sorted_keys);
  EXPECT_EQ(a.sorted_order, ref.sorted_order);
  EXPECT_EQ(a.partitioned, ref.partitioned);
  EXPECT_EQ(a.bucket_begin, ref.bucket_begin);
  EXPECT_EQ(a.histogram, ref.histogram);
  EXPECT_EQ(a.min_index, ref.min_index);
  // Bitwise: the minima are copies of input values, never recomputed.
  ASSERT_EQ(a.min_value.size(), ref.min_value.size());
  EXPECT_EQ(0, std::memcmp(a.min_value.data(), ref.min_value.data(), ref.min_value.size() * sizeof(float)));
}

// Two executors with different widths in one process, launching concurrently from two
// threads: each runs its own width and both give the serial reference's results.
TEST(ExecutorLanes, DifferentWidthsSideBySideGiveTheSameResults) {
  const Inputs in = make_inputs();
  const PrimitiveResults ref = serial_reference(in);
  ASSERT_GT(ref.scattered.size(), in.keys.size() / 4);  // the compactions keep ~30 %
  ASSERT_LT(ref.scattered.size(), in.keys.size() / 3);
  for (const auto& [wa, wb] : {std::pair{1, 16}, std::pair{4, 8}}) {
    Executor a(2, wa), b(2, wb);
    PrimitiveResults ra, rb;
    std::exception_ptr ea, eb;  // rethrown here: an exception escaping a std::thread aborts
    std::thread ta([&] {
      try { ra = run_plain_primitives(a, in); } catch (...) { ea = std::current_exception(); }
    });
    std::thread tb([&] {
      try { rb = run_plain_primitives(b, in); } catch (...) { eb = std::current_exception(); }
    });
    ta.join();
    tb.join();
    if (ea) std::rethrow_exception(ea);
    if (eb) std::rethrow_exception(eb);
    EXPECT_EQ(a.lanes(), wa);
    EXPECT_EQ(b.lanes(), wb);
    expect_equal(ra, ref, wa);
    expect_equal(rb, ref, wb);
  }
}

}  // namespace
}  // namespace speculum::par
