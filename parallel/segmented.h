// Segmented min/argmin (the closest hit per ray) and histogram: two of the primitives
// through which alone kernels scatter (docs/architecture.md, "Stream constraints"). Ties go
// to the lowest element index, so results equal a serial loop for any thread count.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "parallel/stream.h"

namespace speculum::par {

// Elements are grouped by segment: segment[i] is non-decreasing (e.g. ray ids after a
// sort). For every segment s < segments: min_value[s] = the smallest value[i] of segment s
// and min_index[s] = its lowest index i; an empty segment gets +infinity and kNoIndex.
// NaN values never win (they compare false). Gather-only: each segment finds its range by
// binary search over `segment`. Throws std::invalid_argument on unsorted or out-of-range ids.
// The template validates W ids per lane compare and scans a segment W values at a time
// (Lanes<W>: NaN lanes masked out, the lowest lane holding the group minimum wins); every W
// gives the same bits. The plain functions below run at the executor's width, ex.lanes().
template <int W>
void segmented_min_sorted(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                          std::span<const float> value, std::uint32_t segments,
                          std::span<float> min_value, std::span<std::uint32_t> min_index);
void segmented_min_sorted(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                          std::span<const float> value, std::uint32_t segments,
                          std::span<float> min_value, std::span<std::uint32_t> min_index);

// Same result for segment ids in any order (e.g. candidate hits as produced): a stable
// radix sort of (segment, index) followed by segmented_min_sorted<W>.
template <int W>
void segmented_min(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                   std::span<const float> value, std::uint32_t segments,
                   std::span<float> min_value, std::span<std::uint32_t> min_index);
void segmented_min(Executor& ex, std::string_view name, std::span<const std::uint32_t> segment,
                   std::span<const float> value, std::uint32_t segments,
                   std::span<float> min_value, std::span<std::uint32_t> min_index);

// count[b] = number of i with bin[i] == b, for b < bins (count.size() == bins); per-chunk
// tables summed in chunk order. A bin id >= bins throws std::invalid_argument. The template
// counts through count_ids_per_chunk<W>.
template <int W>
void histogram(Executor& ex, std::string_view name, std::span<const std::uint32_t> bin,
               std::span<std::uint64_t> count, std::size_t chunk = kStreamChunk);
void histogram(Executor& ex, std::string_view name, std::span<const std::uint32_t> bin,
               std::span<std::uint64_t> count, std::size_t chunk = kStreamChunk);

}  // namespace speculum::par
