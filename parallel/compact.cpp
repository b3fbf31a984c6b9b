// Stream compaction: scan + scatter, and ROGER ch.4 hierarchical gather-only compaction
// (TECHNIQUES.md §4.3; ROGER Fig.4.7 search, Fig.4.8 block displacements).
#include "parallel/compact.h"

#include <algorithm>
#include <stdexcept>

namespace speculum::par {

std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk) {
  const std::size_t n = keep.size();
  if (chunk == 0) chunk = 1;
  std::vector<std::uint32_t> offset(Executor::chunk_count(n, chunk));
  ex.parallel_for(launch_name(name, "count"), n, chunk, [&](std::size_t b, std::size_t e) {
    std::uint32_t c = 0;
    for (std::size_t i = b; i < e; ++i) c += keep[i] != 0;
    offset[b / chunk] = c;
  });
  std::size_t total = 0;
  for (auto& o : offset) {
    const std::size_t c = o;
    o = std::uint32_t(total);
    total += c;
  }
  if (out.size() < total) throw std::invalid_argument("compact_scatter: output span too small");
  ex.parallel_for(launch_name(name, "scatter"), n, chunk, [&](std::size_t b, std::size_t e) {
    std::uint32_t* dst = out.data() + offset[b / chunk];
    // Branch-free up to the chunk's last kept element: store every index, advance only
    // past kept ones. Stores before that element land inside this chunk's output range.
    std::size_t last = e;
    while (last > b && !keep[last - 1]) --last;
    if (last == b) return;
    for (std::size_t i = b; i + 1 < last; ++i) {
      *dst = std::uint32_t(i);
      dst += keep[i] != 0;
    }
    *dst = std::uint32_t(last - 1);
  });
  return total;
}

std::size_t compact_block_gather(std::span<const std::uint8_t> block, std::span<std::uint32_t> psum,
                                 std::span<std::uint32_t> out, std::uint64_t& steps) {
  const std::size_t s = block.size();
  if (s == 0) return 0;
  std::uint32_t empties = 0;
  for (std::size_t j = 0; j < s; ++j) {
    empties += block[j] == 0;
    psum[j] = empties;
  }
  const std::size_t count = s - empties;
  // Fig.4.7: j - pSum[j] is non-decreasing and rises by one at each kept element, so the
  // kept element of rank i is the unique kept j with j - pSum[j] = i, inside
  // [i + pSum[i], i + pSum[s-1]]; halve the interval and tighten it by |j - pSum[j] - i|.
  for (std::size_t i = 0; i < count; ++i) {
    long lo = long(i + psum[i]);
    long hi = long(i + psum[s - 1]);
    long j = (lo + hi) / 2;
    long found = j - long(psum[j]) - long(i);
    std::size_t guard = 0;
    while ((found != 0 || block[j] == 0) && guard++ <= s) {
      if (found < 0) lo = j - found;
      else hi = j - std::max(1L, found);
      j = (lo + hi) / 2;
      found = j - long(psum[j]) - long(i);
    }
    steps += guard;
    out[i] = std::uint32_t(j);
  }
  return count;
}

std::size_t compact_hierarchical(Executor& ex, std::string_view name,
                                 std::span<const std::uint8_t> keep, std::span<std::uint32_t> out,
                                 std::size_t block_size, std::vector<std::uint32_t>* scratch,
                                 HierarchicalCompactStats* stats) {
  if (block_size == 0) throw std::invalid_argument("compact_hierarchical: block size must be >= 1");
  const std::size_t n = keep.size();
  const std::size_t s = block_size;
  const std::size_t blocks = (n + s - 1) / s;
  std::vector<std::uint32_t> own;
  std::vector<std::uint32_t>& local = scratch ? *scratch : own;
  local.resize(blocks * s);
  std::vector<std::uint32_t> count(blocks);
  // Level 1: every block reduces itself (one launch chunk = a fixed number of blocks).
  const std::size_t blocks_per_chunk = std::max<std::size_t>(1, kStreamChunk / s);
  std::vector<std::uint64_t> chunk_steps(Executor::chunk_count(blocks, blocks_per_chunk));
  ex.parallel_for(launch_name(name, "block_reduce"), blocks, blocks_per_chunk,
                  [&](std::size_t b0, std::size_t b1) {
                    std::vector<std::uint32_t> psum(s);
                    std::uint64_t steps = 0;
                    for (std::size_t b = b0; b < b1; ++b) {
                      const std::size_t first = b * s;
                      const std::size_t len = std::min(s, n - first);  // the tail block is short
                      const std::size_t c = compact_block_gather(
                          keep.subspan(first, len), psum, std::span(local).subspan(first, s), steps);
                      for (std::size_t k = 0; k < c; ++k) local[first + k] += std::uint32_t(first);
                      count[b] = std::uint32_t(c);
                    }
                    chunk_steps[b0 / blocks_per_chunk] = steps;
                  });
  // Level 2: block displacements (exclusive scan of kept counts, in output order).
  std::vector<std::uint32_t> displacement(blocks + 1);
  std::size_t total = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    displacement[b] = std::uint32_t(total);
    total += count[b];
  }
  displacement[blocks] = std::uint32_t(total);
  if (out.size() < total) throw std::invalid_argument("compact_hierarchical: output span too small");
  // Concatenation as a gather: output slot k finds its block by binary search over the
  // displacements and reads that block's local slot.
  ex.parallel_for(launch_name(name, "concatenate"), total, kStreamChunk, [&](std::size_t k0, std::size_t k1) {
    std::size_t b = std::size_t(std::upper_bound(displacement.begin(), displacement.end(), std::uint32_t(k0)) -
                                displacement.begin()) - 1;
    for (std::size_t k = k0; k < k1; ++k) {
      while (displacement[b + 1] <= k) ++b;  // walk forward within the chunk
      out[k] = local[b * s + (k - displacement[b])];
    }
  });
  if (stats) {
    stats->blocks = blocks;
    stats->search_steps = 0;
    for (auto v : chunk_steps) stats->search_steps += v;
  }
  return total;
}

}  // namespace speculum::par
