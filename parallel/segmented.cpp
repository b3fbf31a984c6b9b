// Segmented min/argmin and histogram (segmented.h).
#include "parallel/segmented.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "parallel/chunk_counts.h"
#include "parallel/partition.h"

namespace speculum::par {

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
      [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
          if (segment[i] >= segments || (i > 0 && segment[i] < segment[i - 1])) return false;
        return true;
      },
      [](bool a, bool b) { return a && b; });
  if (!ok) throw std::invalid_argument("segmented_min_sorted: segment ids unsorted or >= segment count");
  // Segments per chunk: enough to amortize the binary searches.
  ex.parallel_for(launch_name(name, "segment_min"), segments, 4096, [&](std::size_t s0, std::size_t s1) {
    std::size_t i = std::size_t(std::lower_bound(segment.begin(), segment.end(), std::uint32_t(s0)) - segment.begin());
    for (std::size_t s = s0; s < s1; ++s) {
      float best = std::numeric_limits<float>::infinity();
      std::uint32_t best_i = kNoIndex;
      for (; i < n && segment[i] == s; ++i)
        if (value[i] < best || (best_i == kNoIndex && value[i] == best)) {
          best = value[i];
          best_i = std::uint32_t(i);
        }
      min_value[s] = best;
      min_index[s] = best_i;
    }
  });
}

void segmented_min(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                   std::span<const float> value, std::uint32_t segments,
                   std::span<float> min_value, std::span<std::uint32_t> min_index) {
  const std::size_t n = segment.size();
  if (value.size() != n) throw std::invalid_argument("segmented_min: value and segment sizes differ");
  std::vector<std::uint32_t> keys(segment.begin(), segment.end());
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  radix_sort(ex, launch_name(name, "sort"), std::span(keys), std::span(order));
  std::vector<float> sorted_value(n);
  gather(ex, launch_name(name, "gather"), value, std::span<const std::uint32_t>(order), std::span(sorted_value));
  segmented_min_sorted(ex, name, keys, sorted_value, segments, min_value, min_index);
  // Map positions in the sorted order back to element indices (stable sort keeps the
  // lowest original index first among equal values).
  ex.parallel_for(launch_name(name, "remap"), segments, kStreamChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t s = b; s < e; ++s)
      if (min_index[s] != kNoIndex) min_index[s] = order[min_index[s]];
  });
}

void histogram(Executor& ex, std::string_view name, std::span<const std::uint32_t> bin,
               std::span<std::uint64_t> count, std::size_t chunk) {
  const std::size_t bins = count.size();
  const std::size_t n = bin.size();
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  const std::vector<std::uint32_t> local =
      count_ids_per_chunk(ex, name, "chunk_counts", bin, bins, chunk, "histogram", "bin");
  ex.parallel_for(launch_name(name, "sum_chunks"), bins, 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      std::uint64_t total = 0;
      for (std::size_t c = 0; c < chunks; ++c) total += local[c * bins + k];
      count[k] = total;
    }
  });
}

}  // namespace speculum::par
