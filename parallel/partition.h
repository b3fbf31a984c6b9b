// Stable partition into p buckets (ROGER §4.5 bucket sort = p compactions computed
// together) and stable radix sort of 32/64-bit keys with a payload, both built on one
// counting scatter: per-chunk bucket counts, offsets laid out bucket-major then chunk order
// (a serial pass), then each chunk writes its elements in order — deterministic and stable.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "parallel/page_buffer.h"
#include "parallel/stream.h"

namespace speculum::par {

// Radix sort and partition chunks are larger than kStreamChunk: each chunk carries a
// per-bucket count table, and bigger chunks keep the scatter's write streams long.
inline constexpr std::size_t kScatterChunk = 1 << 16;

// out[0, n) = the element indices grouped by bucket[i] (0 <= bucket[i] < p), each bucket in
// ascending index order; bucket_begin[0, p] receives the bucket boundaries (size p + 1).
// A bucket id >= p throws std::invalid_argument. The template range-checks and counts over
// Lanes<W> (count_ids_per_chunk<W>) and scatters W-groups lane by lane in element order (the
// scatter is per element); every W gives the same output. The plain function uses
// ex.lanes().
template <int W>
void partition_stable(Executor& ex, std::string_view name, std::span<const std::uint32_t> bucket,
                      std::uint32_t p, std::span<std::uint32_t> out,
                      std::span<std::uint32_t> bucket_begin, std::size_t chunk = kScatterChunk);
void partition_stable(Executor& ex, std::string_view name, std::span<const std::uint32_t> bucket,
                      std::uint32_t p, std::span<std::uint32_t> out,
                      std::span<std::uint32_t> bucket_begin, std::size_t chunk = kScatterChunk);

// Reusable buffers for radix_sort (pass one in to keep 16M-element sorts allocation-free).
template <class Key>
struct RadixSortScratch {
  std::vector<Key> keys;
  std::vector<std::uint32_t> payload;
  std::vector<std::uint32_t> counts;
  PageBuffer packed;  // 32-bit keys: (key, payload) packed in one word, huge-page backed
};

// Sorts keys ascending, carrying payload[i] along; stable (equal keys keep their order).
// Only the span of bits that differ between keys is sorted. 32-bit keys: one scatter on the
// top <= 11 of those bits into buckets (per-thread line buffers, streaming whole-line
// stores), then every bucket sorted in cache on the rest; a bucket over 2^18 elements
// (skewed keys) makes it fall back to the 64-bit keys' method: least-significant-digit
// passes of <= 11 bits over the whole array with write-combining scatters.
// payload may be empty (keys only); otherwise it must have keys.size() elements.
// radix_sort<W> runs its kernels at lane width W (1, 4, 8, 16); the plain overloads use
// ex.lanes(). The output does not depend on W.
template <int W>
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>* scratch = nullptr,
                std::size_t chunk = kScatterChunk);
template <int W>
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint64_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint64_t>* scratch = nullptr,
                std::size_t chunk = kScatterChunk);
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>* scratch = nullptr,
                std::size_t chunk = kScatterChunk);
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint64_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint64_t>* scratch = nullptr,
                std::size_t chunk = kScatterChunk);

}  // namespace speculum::par
