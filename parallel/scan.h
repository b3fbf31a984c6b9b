// Exclusive and inclusive scan over the Executor: chunk sums, a serial scan of the chunk
// sums in chunk order, then each chunk scanned from its offset (deterministic for any
// thread count; for floats the association is fixed by the chunk size). Large inputs run
// both passes tile by tile so the second read comes from cache.
#pragma once

#include <algorithm>
#include <functional>
#include <span>
#include <vector>

#include "parallel/stream.h"

namespace speculum::par {

namespace detail {

// Elements per tile: the two passes run tile by tile so the second pass re-reads its input
// from the last-level cache instead of memory (4 MiB of input per tile).
template <class T>
std::size_t scan_tile(std::size_t chunk) {
  const std::size_t target = (std::size_t(4) << 20) / sizeof(T);
  return std::max<std::size_t>(1, target / chunk) * chunk;
}

template <bool Inclusive, class T, class Op>
T scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init, Op op,
       std::size_t chunk) {
  const std::size_t n = in.size();
  if (chunk == 0) chunk = 1;
  const std::size_t tile = scan_tile<T>(chunk);
  const std::string sums_name = launch_name(name, "chunk_sums");
  const std::string scan_name = launch_name(name, "chunk_scan");
  std::vector<T> offset(Executor::chunk_count(std::min(n, tile), chunk));
  T running = init;
  // Tiles are whole chunks and run in order, so the association (chunk sums folded in
  // chunk order from init) is the same as one pass over all chunks.
  for (std::size_t t0 = 0; t0 < n; t0 += tile) {
    const std::size_t tn = std::min(tile, n - t0);
    const T* const tin = in.data() + t0;
    T* const tout = out.data() + t0;
    ex.parallel_for(sums_name, tn, chunk, [&](std::size_t b, std::size_t e) {
      T acc = tin[b];
      for (std::size_t i = b + 1; i < e; ++i) acc = op(acc, tin[i]);
      offset[b / chunk] = acc;
    });
    const std::size_t chunks = Executor::chunk_count(tn, chunk);
    for (std::size_t c = 0; c < chunks; ++c) {
      const T sum = offset[c];
      offset[c] = running;
      running = op(running, sum);
    }
    // In-place safe: each element is read before its slot is written.
    ex.parallel_for(scan_name, tn, chunk, [&](std::size_t b, std::size_t e) {
      T acc = offset[b / chunk];
      for (std::size_t i = b; i < e; ++i) {
        const T x = tin[i];
        if constexpr (Inclusive) {
          acc = op(acc, x);
          tout[i] = acc;
        } else {
          tout[i] = acc;
          acc = op(acc, x);
        }
      }
    });
  }
  return running;
}
}  // namespace detail

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i-1]; returns the total init ⊕ in[0..n). out may alias in.
template <class T, class Op = std::plus<T>>
T exclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kStreamChunk) {
  return detail::scan<false>(ex, name, in, out, init, op, chunk);
}

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i]; returns the total. out may alias in.
template <class T, class Op = std::plus<T>>
T inclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kStreamChunk) {
  return detail::scan<true>(ex, name, in, out, init, op, chunk);
}

}  // namespace speculum::par
