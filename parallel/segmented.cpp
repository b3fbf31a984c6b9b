// Segmented min/argmin and histogram (segmented.h), written once over Lanes<W> and
// instantiated for W = 1, 4, 8, 16.
#include "parallel/segmented.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "parallel/chunk_counts.h"
#include "parallel/lanes_stream.h"
#include "parallel/partition.h"

namespace speculum::par {

namespace {

// Segment ids in [b, e) are < segments and non-decreasing (also across b - 1 → b): W ids and
// their predecessors per lane compare; the violations are OR-ed and tested once.
template <int W>
bool segments_valid(const std::uint32_t* segment, std::size_t b, std::size_t e, std::uint32_t segments) {
  using L = Lanes<W>;
  using U = LaneU32<W>;
  bool ok = true;
  std::size_t i = b;
  if (i == 0 && i < e) ok = segment[i++] < segments;  // the first element has no predecessor
  typename U::mask_type bad(false);
  for (; i + W <= e; i += W) {
    const U id = L::load(segment + i);
    bad |= id >= segments || id < L::load(segment + i - 1);
  }
  for (; i < e; ++i) ok = ok && segment[i] < segments && segment[i - 1] <= segment[i];  // < W left
  return ok && L::none(bad);
}

// The minimum of segment s, whose elements start at i: scans W values at a time and returns
// the index past the segment. A group's lanes past the segment (or the stream) and NaN lanes
// never win; among the rest, the lowest lane equal to the group minimum is the group's
// candidate (ties, including -0 == +0, go to the lowest index), and it replaces the running
// best only if strictly smaller — or if nothing claimed the segment yet (so +inf can win).
// That is the serial rule of segmented.h applied to whole groups, hence the same bits for
// every W.
template <int W>
std::size_t segment_min(const std::uint32_t* segment, const float* value, std::size_t n, std::size_t i,
                        std::uint32_t s, float& best, std::uint32_t& best_i) {
  using L = Lanes<W>;
  using U = LaneU32<W>;
  using F = typename L::f32;
  constexpr float inf = std::numeric_limits<float>::infinity();
  best = inf;
  best_i = kNoIndex;
  while (i < n) {
    const int c = int(std::min<std::size_t>(W, n - i));
    // Ids are sorted, so the lanes of segment s are a prefix of the group (s + 1 fills the
    // lanes past the stream: never s, and no overflow since s < segments).
    const U id = c == W ? L::load(segment + i) : L::load_partial(segment + i, c, s + 1);
    const int m = L::count(id == s);
    if (m == 0) break;
    const F v = m == W ? L::load(value + i) : L::load_partial(value + i, m, std::numeric_limits<float>::quiet_NaN());
    const auto valid = v == v;  // false for NaN, including the fill past the segment
    if (L::any(valid)) {
      const F candidate = L::select(valid, v, F(inf));
      const int k = L::first_active(valid && candidate == L::hmin(candidate));
      const float x = value[i + k];  // the element's own bits (-0 vs +0)
      if (x < best || (best_i == kNoIndex && x == best)) {
        best = x;
        best_i = std::uint32_t(i + k);
      }
    }
    i += std::size_t(m);
    if (m < W) break;
  }
  return i;
}

}  // namespace

template <int W>
void segmented_min_sorted(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                          std::span<const float> value, std::uint32_t segments,
                          std::span<float> min_value, std::span<std::uint32_t> min_index) {
  const std::size_t n = segment.size();
  if (value.size() != n) throw std::invalid_argument("segmented_min: value and segment sizes differ");
  if (min_value.size() < segments || min_index.size() < segments)
    throw std::invalid_argument("segmented_min: output spans smaller than the segment count");
  // Validate order and range in parallel (one flag per chunk, combined serially).
  const bool ok = ex.parallel_reduce(
      launch_name(name, "validate"), n, kStreamChunk, true,
      [&](std::size_t b, std::size_t e) { return segments_valid<W>(segment.data(), b, e, segments); },
      [](bool a, bool b) { return a && b; });
  if (!ok) throw std::invalid_argument("segmented_min_sorted: segment ids unsorted or >= segment count");
  // Segments per chunk: enough to amortize the binary searches.
  ex.parallel_for(launch_name(name, "segment_min"), segments, 4096, [&](std::size_t s0, std::size_t s1) {
    std::size_t i = std::size_t(std::lower_bound(segment.begin(), segment.end(), std::uint32_t(s0)) - segment.begin());
    for (std::size_t s = s0; s < s1; ++s)
      i = segment_min<W>(segment.data(), value.data(), n, i, std::uint32_t(s), min_value[s], min_index[s]);
  });
}

void segmented_min_sorted(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                          std::span<const float> value, std::uint32_t segments,
                          std::span<float> min_value, std::span<std::uint32_t> min_index) {
  dispatch_lanes(ex.lanes(), [&](auto w) {
    segmented_min_sorted<w.value>(ex, name, segment, value, segments, min_value, min_index);
  });
}

template <int W>
void segmented_min(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                   std::span<const float> value, std::uint32_t segments,
                   std::span<float> min_value, std::span<std::uint32_t> min_index) {
  const std::size_t n = segment.size();
  if (value.size() != n) throw std::invalid_argument("segmented_min: value and segment sizes differ");
  std::vector<std::uint32_t> keys(segment.begin(), segment.end());
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  radix_sort<W>(ex, launch_name(name, "sort"), std::span(keys), std::span(order));
  std::vector<float> sorted_value(n);
  gather(ex, launch_name(name, "gather"), value, std::span<const std::uint32_t>(order), std::span(sorted_value));
  segmented_min_sorted<W>(ex, name, keys, sorted_value, segments, min_value, min_index);
  // Map positions in the sorted order back to element indices (stable sort keeps the
  // lowest original index first among equal values).
  ex.parallel_for(launch_name(name, "remap"), segments, kStreamChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t s = b; s < e; ++s)
      if (min_index[s] != kNoIndex) min_index[s] = order[min_index[s]];
  });
}

void segmented_min(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                   std::span<const float> value, std::uint32_t segments,
                   std::span<float> min_value, std::span<std::uint32_t> min_index) {
  dispatch_lanes(ex.lanes(), [&](auto w) { segmented_min<w.value>(ex, name, segment, value, segments, min_value, min_index); });
}

template <int W>
void histogram(Executor& ex, std::string_view name, std::span<const std::uint32_t> bin,
               std::span<std::uint64_t> count, std::size_t chunk) {
  const std::size_t bins = count.size();
  const std::size_t n = bin.size();
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  const std::vector<std::uint32_t> local =
      count_ids_per_chunk<W>(ex, name, "chunk_counts", bin, bins, chunk, "histogram", "bin");
  ex.parallel_for(launch_name(name, "sum_chunks"), bins, 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      std::uint64_t total = 0;
      for (std::size_t c = 0; c < chunks; ++c) total += local[c * bins + k];
      count[k] = total;
    }
  });
}

void histogram(Executor& ex, std::string_view name, std::span<const std::uint32_t> bin,
               std::span<std::uint64_t> count, std::size_t chunk) {
  dispatch_lanes(ex.lanes(), [&](auto w) { histogram<w.value>(ex, name, bin, count, chunk); });
}

#define SPECULUM_SEGMENTED_INSTANTIATE(W)                                                                     \
  template void segmented_min_sorted<W>(Executor&, std::string_view, std::span<const std::uint32_t>,        \
                                        std::span<const float>, std::uint32_t, std::span<float>,            \
                                        std::span<std::uint32_t>);                                          \
  template void segmented_min<W>(Executor&, std::string_view, std::span<const std::uint32_t>,               \
                                 std::span<const float>, std::uint32_t, std::span<float>,                   \
                                 std::span<std::uint32_t>);                                                 \
  template void histogram<W>(Executor&, std::string_view, std::span<const std::uint32_t>,                   \
                             std::span<std::uint64_t>, std::size_t);
SPECULUM_SEGMENTED_INSTANTIATE(1)
SPECULUM_SEGMENTED_INSTANTIATE(4)
SPECULUM_SEGMENTED_INSTANTIATE(8)
SPECULUM_SEGMENTED_INSTANTIATE(16)
#undef SPECULUM_SEGMENTED_INSTANTIATE

}  // namespace speculum::par
