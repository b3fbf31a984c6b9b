// Stream compaction: scan + scatter, and ROGER ch.4 hierarchical gather-only compaction
// (ROGER §4.3.2 Fig.4.7 search, §4.3.3 Fig.4.8 block displacements). Every kernel is
// written once over Lanes<W> (lanes.h, lanes_stream.h) and instantiated for W = 1, 4, 8, 16;
// all of them are integer work, so every W gives the same indices.
#include "parallel/compact.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include "parallel/chained_pass.h"
#include "parallel/lanes_pack.h"
#include "parallel/scan.h"

namespace speculum::par {

namespace {

// Flags are consumed 32 per outer step as 32/W lane groups: one step's stores then cover at
// most 32 output slots for every W, and the W = 8 build keeps the unrolled 4-group loop of
// the former fixed-width kernel.
constexpr std::size_t kStep = 32;

// Bit k set iff p[k] != 0, for k < count <= W; a short group never reads past p[count).
template <int W>
[[gnu::always_inline]] inline unsigned flag_bits(const std::uint8_t* p, std::size_t count) {
  if (count >= std::size_t(W)) return nonzero_bits<W>(p);
  unsigned m = 0;
  for (std::size_t k = 0; k < count; ++k) m |= unsigned(p[k] != 0) << k;
  return m;
}

template <int W>
std::uint32_t count_kept(const std::uint8_t* p, std::size_t n) {
  std::uint32_t c = 0;
  std::size_t i = 0;
  for (; i + kStep <= n; i += kStep) c += std::uint32_t(std::popcount(nonzero_mask32<W>(p + i)));
  for (; i < n; i += W) c += std::uint32_t(std::popcount(flag_bits<W>(p + i, std::min<std::size_t>(W, n - i))));
  return c;
}

// Writes the indices of the kept flags of keep[b, e) to dst (ascending). Each W-group stores
// all W lanes of its left-packed indices and advances by the kept count; lanes past the kept
// ones are garbage that the next store overwrites. Full-W stores run only while a whole step
// (<= 32 slots) fits inside this chunk's own output range [dst, dst_end), so no store ever
// touches another chunk's slots; the rest is the per-element loop.
template <int W>
void scatter_kept(const std::uint8_t* keep, std::size_t b, std::size_t e, std::uint32_t* dst,
                  std::uint32_t* const dst_end) {
  std::size_t i = b;
  for (; i + kStep <= e && dst_end - dst >= std::ptrdiff_t(kStep); i += kStep) {
    std::uint32_t m = nonzero_mask32<W>(keep + i);
    for (std::size_t g = 0; g < kStep; g += W, m >>= W % 32) {
      const unsigned bits = unsigned(m) & ((1u << W) - 1);
      Lanes<W>::store(left_pack<W>(bits, std::uint32_t(i + g)), dst);
      dst += std::popcount(bits);
    }
  }
  for (; i < e; ++i)
    if (keep[i]) *dst++ = std::uint32_t(i);
}

}  // namespace

template <int W>
std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk) {
  const std::size_t n = keep.size();
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  auto count_of = [&](std::size_t c) {
    const std::size_t b = c * chunk;
    return count_kept<W>(keep.data() + b, std::min(n, b + chunk) - b);
  };
  if (out.size() >= n) {
    // Room for any count: one chained pass (chained_pass.h) — each chunk counts its kept
    // flags, takes its output offset by look-back, and scatters while its flags are cached.
    std::plus<std::uint32_t> plus;
    return chained_pass(ex, name, "chained_scatter", n, chunks, std::uint32_t(0), plus, count_of, true,
                        [&](std::size_t c, std::uint32_t offset, std::uint32_t count, std::size_t next) {
                          const std::size_t b = c * chunk;
                          scatter_kept<W>(keep.data(), b, std::min(n, b + chunk), out.data() + offset,
                                          out.data() + offset + count);
                          return next == kNoChunk ? 0u : count_of(next);
                        });
  }
  // A short output may be too small: count everything first, so that nothing is written
  // before the size check throws.
  std::vector<std::uint32_t> offset(chunks + 1);
  ex.parallel_for(launch_name(name, "count"), n, chunk, [&](std::size_t b, std::size_t) {
    offset[b / chunk] = count_of(b / chunk);
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
    scatter_kept<W>(keep.data(), b, e, out.data() + offset[c], out.data() + offset[c + 1]);
  });
  return total;
}

namespace {

// One block of the ROGER §4.3.2 reduction, gather-only: psum[j] = empties in [0, j]; output
// slot i (rank i among the kept) reads the kept j with j - psum[j] = i (Fig.4.7's
// invariant). j - psum[j] is non-decreasing in j and the answer lies in [i, i + E] (E = the
// block's empties), so it is the first d in [0, E] with d >= psum[i + d]: a branch-free
// lower bound with the same probe count for every slot of the block (ceil(log2(E + 1)) + 1).
// Consecutive slots' searches overlap in the pipeline instead of mispredicting. pSum is
// computed W flags at a time with in-register prefix sums.
// Writes base + j; returns the kept count and adds the probes (per slot) to `steps`.
template <int W>
std::size_t block_gather(const std::uint8_t* block, std::size_t s, std::uint32_t* psum, std::uint32_t* out,
                         std::uint32_t base, std::uint64_t& steps) {
  using L = Lanes<W>;
  using U = LaneU32<W>;
  const U lane([](auto k) { return std::uint32_t(k); });
  // pSum W flags at a time: empty flags as 0/1 lanes, in-register inclusive prefix sum, plus
  // the running count of the groups before (ROGER §4.3.2's per-block scan).
  U carry(0u);
  for (std::size_t j = 0; j < s; j += W) {
    const std::size_t c = std::min<std::size_t>(W, s - j);
    const U empty = (U(~flag_bits<W>(block + j, c)) >> lane) & 1u;
    const U running = prefix_sum<W>(empty) + carry;
    L::store_partial(running, psum + j, int(c));
    carry = last_lane<W>(running);
  }
  const std::uint32_t empties = s ? psum[s - 1] : 0;
  const std::size_t count = s - empties;
  std::size_t probes = 1;
  for (std::size_t len = std::size_t(empties) + 1; len > 1; len -= len / 2) ++probes;
  // The search runs slot by slot: searching W slots per probe (a Lanes<W> gather, vpgatherdd
  // at W = 8, and a lane compare) measured 1.6-1.8x slower than this form at W = 8 (16M
  // flags, s = 64, one thread, Zen 4): each probe's gather is on the search's dependent
  // chain. Independent slots' scalar searches overlap in the pipeline instead.
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

template <int W>
std::size_t compact_block_gather(std::span<const std::uint8_t> block, std::span<std::uint32_t> psum,
                                 std::span<std::uint32_t> out, std::uint64_t& steps) {
  return block_gather<W>(block.data(), block.size(), psum.data(), out.data(), 0, steps);
}

template <int W>
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
                      count[b] = std::uint32_t(block_gather<W>(keep.data() + first, len, psum.data(),
                                                               local.data() + first, std::uint32_t(first), steps));
                    }
                    chunk_steps[b0 / blocks_per_chunk] = steps;
                  });
  // Level 2: block displacements, the exclusive scan of the kept counts in output order
  // (ROGER §4.3.3 Fig.4.8), by the scan primitive (n / s counts: 1M at 16M flags, s = 16).
  std::vector<std::uint32_t> displacement(blocks + 1);
  const std::size_t total = exclusive_scan<W>(ex, launch_name(name, "block_offsets"),
                                              std::span<const std::uint32_t>(count),
                                              std::span(displacement).first(blocks));
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

// The plain forms run at the executor's width (Executor::lanes(), `--lanes W`).
std::size_t compact_scatter(Executor& ex, std::string_view name, std::span<const std::uint8_t> keep,
                            std::span<std::uint32_t> out, std::size_t chunk) {
  return dispatch_lanes(ex.lanes(), [&](auto w) { return compact_scatter<w.value>(ex, name, keep, out, chunk); });
}

std::size_t compact_hierarchical(Executor& ex, std::string_view name,
                                 std::span<const std::uint8_t> keep, std::span<std::uint32_t> out,
                                 std::size_t block_size, std::vector<std::uint32_t>* scratch,
                                 HierarchicalCompactStats* stats) {
  return dispatch_lanes(ex.lanes(), [&](auto w) {
    return compact_hierarchical<w.value>(ex, name, keep, out, block_size, scratch, stats);
  });
}

#define SPECULUM_COMPACT_INSTANTIATE(W)                                                                   \
  template std::size_t compact_scatter<W>(Executor&, std::string_view, std::span<const std::uint8_t>,   \
                                          std::span<std::uint32_t>, std::size_t);                       \
  template std::size_t compact_hierarchical<W>(Executor&, std::string_view, std::span<const std::uint8_t>, \
                                               std::span<std::uint32_t>, std::size_t,                   \
                                               std::vector<std::uint32_t>*, HierarchicalCompactStats*);  \
  template std::size_t compact_block_gather<W>(std::span<const std::uint8_t>, std::span<std::uint32_t>, \
                                               std::span<std::uint32_t>, std::uint64_t&);
SPECULUM_COMPACT_INSTANTIATE(1)
SPECULUM_COMPACT_INSTANTIATE(4)
SPECULUM_COMPACT_INSTANTIATE(8)
SPECULUM_COMPACT_INSTANTIATE(16)
#undef SPECULUM_COMPACT_INSTANTIATE

}  // namespace speculum::par
