// Exclusive and inclusive scan over the Executor in one pass over memory (single-pass
// chained scan with decoupled look-back, see chained_pass.h): each fixed chunk
// is reduced (during its thread's previous chunk's scan), gets its offset from the prefixes
// its predecessors publish, and is scanned again from cache; big outputs other than the
// input go out with streaming stores. The association (chunk sums folded in chunk order
// from init) is fixed, so results are the same for any thread count, lane width and timing,
// floats included.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <type_traits>

#include "parallel/chained_pass.h"
#include "parallel/scan_kernels.h"
#include "parallel/stream.h"

namespace speculum::par {

// Elements per scan chunk: 2^15 (128 KiB of u32, rescanned from L2). Same-run medians, 16M
// u32, exclusive: 1T 2.52 ms and 2T 1.40-1.44 ms at 2^15 against 2.59-2.60 and 1.53-1.88 at
// 2^14 (fewer chunks: fewer claims, look-backs and prefetcher restarts); 2^16 was no better.
// Fixed, never derived from the thread count: it fixes a float scan's association.
inline constexpr std::size_t kScanChunk = std::size_t(1) << 15;

namespace detail {

// Scans at least this large do not fit the caches: an output that is not the input bypasses
// them (streaming stores). It cannot stay cached for the next kernel anyway, and a cached
// store would first read every output line from memory (read-for-ownership), a third memory
// stream beside the input read and the write. In place the output lines are the ones the
// chunk has just read, already cached: plain stores cost no extra read there, and streaming
// stores, which must first evict those lines, measured slower (16M u32 in-place inclusive,
// interleaved runs: 1T 3.2-4.0 ms and 2T 3.1-3.4 ms streaming against 2.55-2.72 and
// 2.16-2.43 plain).
inline constexpr std::size_t kScanUncachedBytes = std::size_t(8) << 20;

template <int W, bool Inclusive, class T, class Op>
T scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init, Op op,
       std::size_t chunk) {
  const std::size_t n = in.size();
  if (out.size() < n) throw std::invalid_argument("scan: output shorter than input");
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  if (chunks == 0) return init;
  const T* const src = in.data();
  T* const dst = out.data();
  const auto length = [&](std::size_t c) { return std::min(n, (c + 1) * chunk) - c * chunk; };
  auto sum_of = [&](std::size_t c) { return scan_kernels::chunk_sum<W>(src + c * chunk, length(c), op); };
  const auto addr = [](const T* p) { return reinterpret_cast<std::uintptr_t>(p); };
  const bool in_place = addr(src) < addr(dst + n) && addr(dst) < addr(src + n);
  const bool streaming = n * sizeof(T) >= kScanUncachedBytes && !in_place;
  return chained_pass(ex, name, "chained_scan", n, chunks, init, op, sum_of, !in_place,
                      [&](std::size_t c, T offset, T, std::size_t next) {
                        const bool has_next = next != kNoChunk;
                        return scan_kernels::chunk_scan<W, Inclusive>(
                            src + c * chunk, dst + c * chunk, length(c), offset, op, streaming,
                            has_next ? src + next * chunk : nullptr, has_next ? length(next) : 0);
                      });
}

// W = 0: the executor's width, ex.lanes() (`--lanes W`).
template <int W, bool Inclusive, class T, class Op>
T scan_at_width(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init,
                Op op, std::size_t chunk) {
  if constexpr (W == 0) {
    return dispatch_lanes(ex.lanes(), [&](auto w) {
      return scan<decltype(w)::value, Inclusive>(ex, name, in, out, init, op, chunk);
    });
  } else {
    return scan<W, Inclusive>(ex, name, in, out, init, op, chunk);
  }
}
}  // namespace detail

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i-1]; returns the total init ⊕ in[0..n). out may alias in.
// W: lane width of the kernels (1, 4, 8, 16; 0 = ex.lanes()); the bits do not depend on it.
template <int W = 0, class T, class Op = std::plus<T>>
T exclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kScanChunk) {
  return detail::scan_at_width<W, false>(ex, name, in, out, init, op, chunk);
}

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i]; returns the total. out may alias in.
template <int W = 0, class T, class Op = std::plus<T>>
T inclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kScanChunk) {
  return detail::scan_at_width<W, true>(ex, name, in, out, init, op, chunk);
}

}  // namespace speculum::par
