// Exclusive and inclusive scan over the Executor: chunk sums, a serial scan of the chunk
// sums in chunk order, then each chunk scanned from its offset (deterministic for any
// thread count; for floats the association is fixed by the chunk size).
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "parallel/stream.h"

namespace speculum::par {

namespace detail {
template <bool Inclusive, class T, class Op>
T scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init, Op op,
       std::size_t chunk) {
  const std::size_t n = in.size();
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  std::vector<T> offset(chunks);
  ex.parallel_for(launch_name(name, "chunk_sums"), n, chunk, [&](std::size_t b, std::size_t e) {
    T acc = in[b];
    for (std::size_t i = b + 1; i < e; ++i) acc = op(acc, in[i]);
    offset[b / chunk] = acc;
  });
  T running = init;
  for (auto& o : offset) {
    const T sum = o;
    o = running;
    running = op(running, sum);
  }
  // In-place safe: each element is read before its slot is written.
  ex.parallel_for(launch_name(name, "chunk_scan"), n, chunk, [&](std::size_t b, std::size_t e) {
    T acc = offset[b / chunk];
    for (std::size_t i = b; i < e; ++i) {
      const T x = in[i];
      if constexpr (Inclusive) {
        acc = op(acc, x);
        out[i] = acc;
      } else {
        out[i] = acc;
        acc = op(acc, x);
      }
    }
  });
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
