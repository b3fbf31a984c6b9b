// Stream compaction: scan + scatter, and ROGER ch.4 hierarchical gather-only compaction
// (TECHNIQUES.md §4.3; ROGER Fig.4.7 search, Fig.4.8 block displacements).
#include "parallel/compact.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace speculum::par {

namespace {

// Kept flags of 32 consecutive bytes as a bit mask (bit k: p[k] != 0).
inline std::uint32_t kept_mask32(const std::uint8_t* p) {
#if defined(__AVX2__)
  const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
  return ~std::uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(v, _mm256_setzero_si256())));
#else
  std::uint32_t m = 0;
  for (int k = 0; k < 32; ++k) m |= std::uint32_t(p[k] != 0) << k;
  return m;
#endif
}

std::uint32_t count_kept(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0;
  std::size_t i = 0;
  for (; i + 32 <= n; i += 32) c += std::uint32_t(std::popcount(kept_mask32(p + i)));
  for (; i < n; ++i) c += p[i] != 0;
  return c;
}

#if defined(__AVX2__)
// For each 8-bit kept mask, the positions of its set bits, packed to the front (left-pack).
struct LeftPackTable {
  alignas(64) std::uint64_t lanes[256];
  constexpr LeftPackTable() : lanes() {
    for (unsigned m = 0; m < 256; ++m) {
      std::uint64_t packed = 0;
      unsigned k = 0;
      for (unsigned b = 0; b < 8; ++b)
        if (m >> b & 1) packed |= std::uint64_t(b) << (8 * k++);
      lanes[m] = packed;
    }
  }
};
constexpr LeftPackTable kLeftPack;
#endif

}  // namespace

std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk) {
  const std::size_t n = keep.size();
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  std::vector<std::uint32_t> offset(chunks + 1);
  ex.parallel_for(launch_name(name, "count"), n, chunk, [&](std::size_t b, std::size_t e) {
    offset[b / chunk] = count_kept(keep.data() + b, e - b);
  });
  std::size_t total = 0;
  for (auto& o : offset) {
    const std::size_t c = o;
    o = std::uint32_t(total);
    total += c;
  }
  if (out.size() < total) throw std::invalid_argument("compact_scatter: output span too small");
  ex.parallel_for(launch_name(name, "scatter"), n, chunk, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / chunk;
    std::uint32_t* dst = out.data() + offset[c];
    std::uint32_t* const dst_end = out.data() + offset[c + 1];
    std::size_t i = b;
#if defined(__AVX2__)
    // Left-pack 8 indices per step with one unaligned 8-lane store; lanes past the kept
    // ones are garbage that later stores overwrite. Only while 8 lanes fit inside this
    // chunk's own output range, so no store ever touches another chunk's slots.
    for (; i + 32 <= e && dst_end - dst >= 32; i += 32) {
      std::uint32_t m = kept_mask32(keep.data() + i);
      for (int g = 0; g < 4; ++g, m >>= 8) {
        const __m256i pos = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(std::int64_t(kLeftPack.lanes[m & 0xff])));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst),
                            _mm256_add_epi32(pos, _mm256_set1_epi32(int(i + 8 * g))));
        dst += std::popcount(m & 0xffu);
      }
    }
#endif
    for (; i < e; ++i)
      if (keep[i]) *dst++ = std::uint32_t(i);
  });
  return total;
}

namespace {

// One block of the ROGER §4.3.2 reduction, gather-only: psum[j] = empties in [0, j]; output
// slot i (rank i among the kept) reads the kept j with j - psum[j] = i (Fig.4.7's
// invariant). j - psum[j] is non-decreasing in j and the answer lies in [i, i + E] (E = the
// block's empties), so it is the first d in [0, E] with d >= psum[i + d]: a branch-free
// lower bound with the same probe count for every slot of the block (ceil(log2(E + 1)) + 1),
// so consecutive slots' searches overlap in the pipeline instead of mispredicting.
// Writes base + j; returns the kept count and adds the probes to `steps`.
inline std::size_t block_gather(const std::uint8_t* block, std::size_t s, std::uint32_t* psum,
                                std::uint32_t* out, std::uint32_t base, std::uint64_t& steps) {
  std::uint32_t empties = 0;
  for (std::size_t j = 0; j < s; ++j) {
    empties += block[j] == 0;
    psum[j] = empties;
  }
  const std::size_t count = s - empties;
  std::size_t probes = 1;
  for (std::size_t len = std::size_t(empties) + 1; len > 1; len -= len / 2) ++probes;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t* p = psum + i;  // p[d] = psum[i + d]
    std::size_t d = 0;
    for (std::size_t len = std::size_t(empties) + 1; len > 1;) {
      const std::size_t half = len / 2;
      d = d + half < p[d + half] ? d + half : d;
      len -= half;
    }
    d += d < p[d];
    out[i] = base + std::uint32_t(i + d);
  }
  steps += probes * count;
  return count;
}

}  // namespace

std::size_t compact_block_gather(std::span<const std::uint8_t> block, std::span<std::uint32_t> psum,
                                 std::span<std::uint32_t> out, std::uint64_t& steps) {
  return block_gather(block.data(), block.size(), psum.data(), out.data(), 0, steps);
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
                      count[b] = std::uint32_t(block_gather(keep.data() + first, len, psum.data(),
                                                            local.data() + first, std::uint32_t(first), steps));
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
