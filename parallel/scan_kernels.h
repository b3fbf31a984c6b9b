// Per-chunk kernels of the chained scan (scan.h): chunk sum and chunk scan from an offset,
// generic over T and Op, written over Lanes<W> for 32-bit integer sums (exact in any order,
// so every W gives the same bits), with optional streaming (cache-bypassing) stores for
// outputs too big to stay cached.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <type_traits>

#if defined(__SSE__)
#include <immintrin.h>
#endif

#include "parallel/lanes.h"
#include "parallel/lanes_stream.h"

namespace speculum::par::scan_kernels {

inline void cpu_relax() {
#if defined(__SSE2__)
  _mm_pause();
#endif
}

// 32-bit integer sums take the lane path: wrap-around addition is associative, so any
// grouping gives the serial fold's bits, and every lane width W gives the same result.
// Other types and operators fold element by element in the documented order (a float sum's
// association must not depend on W), so for them W changes nothing.
template <class T, class Op>
inline constexpr bool kLaneSum32 =
    std::is_integral_v<T> && sizeof(T) == 4 &&
    (std::is_same_v<Op, std::plus<T>> || std::is_same_v<Op, std::plus<>>);

// in[0] ⊕ in[1] ⊕ ... ⊕ in[m-1], folded left from in[0] (the documented float association).
// m >= 1.
template <int W, class T, class Op>
T chunk_sum(const T* in, std::size_t m, Op& op) {
  if constexpr (kLaneSum32<T, Op>) {
    using L = Lanes<W>;
    using V = LaneU32<W>;
    const auto* u = reinterpret_cast<const std::uint32_t*>(in);
    // Four independent accumulators keep four loads in flight per step.
    V a0(0u), a1(0u), a2(0u), a3(0u);
    std::size_t i = 0;
    for (; i + 4 * W <= m; i += 4 * W) {
      a0 += L::load(u + i);
      a1 += L::load(u + i + W);
      a2 += L::load(u + i + 2 * W);
      a3 += L::load(u + i + 3 * W);
    }
    std::uint32_t s = L::hadd(V((a0 + a1) + (a2 + a3)));
    for (; i < m; ++i) s += u[i];
    return T(s);
  }
  T acc = in[0];
  for (std::size_t i = 1; i < m; ++i) acc = op(acc, in[i]);
  return acc;
}

namespace detail {

// Scalar scan of in[0, m) from acc into out; returns the running value after the last one.
template <bool Inclusive, class T, class Op>
T scan_scalar(const T* in, T* out, std::size_t m, T acc, Op& op) {
  for (std::size_t i = 0; i < m; ++i) {
    const T x = in[i];  // read before the (possibly aliasing) write
    if constexpr (Inclusive) {
      acc = op(acc, x);
      out[i] = acc;
    } else {
      out[i] = acc;
      acc = op(acc, x);
    }
  }
  return acc;
}

// Prefetch::next / end: the lines of the chunk this thread most likely scans next, fetched
// into L2 one line per 16 elements of this chunk's scan, so its reduction reads cache while
// this scan, bound by arithmetic and writes, would otherwise leave the memory reads idle.
struct Prefetch {
  const char* next = nullptr;
  const char* end = nullptr;
  void step() {
#if defined(__SSE__)
    if (next < end) {
      _mm_prefetch(next, _MM_HINT_T1);
      next += 64;
    }
#endif
  }
  void rest() {
#if defined(__SSE__)
    for (; next < end; next += 64) _mm_prefetch(next, _MM_HINT_T1);
#endif
  }
};

// The 32-bit sum scan over Lanes<W>, 2W elements per step: prefix sums within the lanes,
// then the running carry. Streaming: the output is written from its first 64-byte line
// boundary with stream_store (aligned for every W).
template <int W, bool Inclusive, bool Streaming>
std::uint32_t scan_sum32(const std::uint32_t* in, std::uint32_t* out, std::size_t m,
                         std::uint32_t acc, Prefetch& prefetch) {
  using L = Lanes<W>;
  using V = LaneU32<W>;
  constexpr std::size_t kStep = 2 * W;
  std::size_t i = Streaming ? to_line(out, m) : 0;
  std::plus<std::uint32_t> plus;
  acc = scan_scalar<Inclusive>(in, out, i, acc, plus);
  V carry(acc);
  for (std::size_t step = 0; i + kStep <= m; i += kStep, ++step) {
    if constexpr (kStep >= 16) {
      for (std::size_t k = 0; k < kStep / 16; ++k) prefetch.step();
    } else if (step % (16 / kStep) == 0) {
      prefetch.step();
    }
    const V x0 = L::load(in + i);
    const V x1 = L::load(in + i + W);
    const V p0 = prefix_sum<W>(x0);
    // Everything but the carry update is independent of the carry, so the loop-carried
    // chain is one add per 2W elements (a cross-lane broadcast in it would cost its latency).
    const V p1 = prefix_sum<W>(x1) + last_lane<W>(p0);
    V s0 = p0 + carry;
    V s1 = p1 + carry;
    carry += last_lane<W>(p1);
    if constexpr (!Inclusive) {
      s0 -= x0;
      s1 -= x1;
    }
    if constexpr (Streaming) {
      stream_store<W>(s0, out + i);
      stream_store<W>(s1, out + i + W);
    } else {
      L::store(s0, out + i);
      L::store(s1, out + i + W);
    }
  }
  acc = carry[0];
  return scan_scalar<Inclusive>(in + i, out + i, m - i, acc, plus);
}

// Generic streaming: scan a block into an aligned buffer in cache, then stream it out as
// 32-bit lanes (a copy: any T whose size divides a line).
template <int W, bool Inclusive, class T, class Op>
T scan_streaming(const T* in, T* out, std::size_t m, T acc, Op& op) {
  constexpr std::size_t kBlock = 2048 / sizeof(T);  // a multiple of a line when 64 % sizeof(T) == 0
  std::size_t i = to_line(out, m);
  acc = scan_scalar<Inclusive>(in, out, i, acc, op);
  alignas(64) T buf[kBlock];
  for (; i + kBlock <= m; i += kBlock) {
    acc = scan_scalar<Inclusive>(in + i, buf, kBlock, acc, op);
    stream_words<W>(reinterpret_cast<const std::uint32_t*>(buf), kBlock * sizeof(T) / 4,
                    reinterpret_cast<std::uint32_t*>(out + i));
  }
  return scan_scalar<Inclusive>(in + i, out + i, m - i, acc, op);
}

}  // namespace detail

// Scans in[0, m) from `offset` into out[0, m) (out may equal in) with lane width W.
// Streaming: full output lines bypass the caches (followed by a store fence, so the join
// publishes them). The `next_count` elements at `next` (the thread's likely next chunk,
// none when null) are prefetched into L2 during the scan.
template <int W, bool Inclusive, class T, class Op>
void chunk_scan(const T* in, T* out, std::size_t m, T offset, Op& op, bool streaming,
                const T* next = nullptr, std::size_t next_count = 0) {
  if constexpr (kLaneSum32<T, Op>) {
    const auto* i32 = reinterpret_cast<const std::uint32_t*>(in);
    auto* o32 = reinterpret_cast<std::uint32_t*>(out);
    detail::Prefetch prefetch;
    if (next != nullptr) {
      prefetch.next = reinterpret_cast<const char*>(next);
      prefetch.end = reinterpret_cast<const char*>(next + next_count);
    }
    if (streaming) {
      detail::scan_sum32<W, Inclusive, true>(i32, o32, m, std::uint32_t(offset), prefetch);
      stream_fence();
    } else {
      detail::scan_sum32<W, Inclusive, false>(i32, o32, m, std::uint32_t(offset), prefetch);
    }
    prefetch.rest();
    return;
  }
  if constexpr (std::is_trivially_copyable_v<T> && 64 % sizeof(T) == 0 && sizeof(T) % 4 == 0) {
    if (streaming) {
      detail::scan_streaming<W, Inclusive>(in, out, m, offset, op);
      stream_fence();
      return;
    }
  }
  (void)streaming, (void)next, (void)next_count;
  detail::scan_scalar<Inclusive>(in, out, m, offset, op);
}

}  // namespace speculum::par::scan_kernels
