// Stream compaction in two forms: scan + scatter, and the gather-only hierarchical block
// algorithm of ROGER ch.4 (ROGER §4.3.2 Fig.4.7, §4.3.3 Fig.4.8).
// Both are stable (order-preserving) and return the indices of the kept elements; gather
// the payload streams with those indices (SoaStream::gather / par::gather).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "parallel/stream.h"

namespace speculum::par {

// Counters of one hierarchical compaction (every bounded loop's work is counted).
struct HierarchicalCompactStats {
  std::uint64_t blocks = 0;
  std::uint64_t search_steps = 0;  // psum probes of the Fig.4.7 search, summed over outputs
};

// Flags per chunk of compact_scatter: each chunk of the chained pass claims its work, waits
// on or reads its predecessor's link and restarts the hardware prefetchers, which measured
// about a microsecond per chunk with two threads; 2^18 flags (a 256 KiB read, at most 1 MiB
// of output) amortize that: 16M flags, 2 threads 1.61 ms at 2^14 → 0.81 ms at 2^18 (1 thread
// 1.81 → 1.67 ms).
inline constexpr std::size_t kCompactChunk = std::size_t(1) << 18;

// out[0, count) = indices i with keep[i] != 0, ascending; returns count. out.size() >= the
// number kept (n is always enough; a smaller span that is too small throws before anything
// is written). With out.size() >= n it is one chained pass (chained_pass.h, launch
// "<name>/chained_scatter"): each chunk counts, takes its offset by look-back and scatters;
// otherwise per-chunk counts, serial offsets and the size check, then the scatter. The template runs the count and the left-pack scatter over Lanes<W> (W = 1, 4, 8,
// 16 are instantiated; every W gives the same output); the plain function uses
// the executor's width, ex.lanes() (`--lanes W`).
template <int W>
std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk = kCompactChunk);
std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk = kCompactChunk);

// Same result, computed gather-only: blocks of `block_size` elements (s in ROGER; any s >= 1)
// get an inclusive count of empty elements pSum; output slot i of a block gathers the unique
// kept j with j - pSum[j] = i (the Fig.4.7 invariant) by a branch-free bisection; the block counts
// are scanned into block displacements and every output slot gathers from its block
// (concatenation, Fig.4.8). `scratch` holds the block-local results (resized to n rounded
// up to s); pass one in to avoid reallocating it each call. The template computes pSum with
// in-register prefix sums over W flags and searches W output slots at once (same output and
// search_steps for every W); the plain function uses ex.lanes().
template <int W>
std::size_t compact_hierarchical(Executor& ex, std::string_view name,
                                 std::span<const std::uint8_t> keep, std::span<std::uint32_t> out,
                                 std::size_t block_size, std::vector<std::uint32_t>* scratch = nullptr,
                                 HierarchicalCompactStats* stats = nullptr);
std::size_t compact_hierarchical(Executor& ex, std::string_view name,
                                 std::span<const std::uint8_t> keep, std::span<std::uint32_t> out,
                                 std::size_t block_size, std::vector<std::uint32_t>* scratch = nullptr,
                                 HierarchicalCompactStats* stats = nullptr);

// The within-block step alone (exposed for tests and teaching): for one block of flags,
// writes the kept positions (block-local) to out[0, count) by the Fig.4.7 search (as a
// branch-free bisection on j - pSum[j]) and returns count; `psum` receives the inclusive
// empty counts. `steps` accumulates psum probes.
template <int W>
std::size_t compact_block_gather(std::span<const std::uint8_t> block, std::span<std::uint32_t> psum,
                                 std::span<std::uint32_t> out, std::uint64_t& steps);

}  // namespace speculum::par
