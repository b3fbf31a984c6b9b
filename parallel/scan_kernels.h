// Per-chunk kernels of the chained scan (scan.h): chunk sum, and chunk scan from an offset
// that also sums the thread's next chunk, generic over T and Op, written over Lanes<W> for
// 32-bit integer sums (exact in any order, so every W gives the same bits), with optional
// streaming (cache-bypassing) stores for outputs too big to stay cached.
#pragma once

#include <algorithm>
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

// Bytes a scan reading its next chunk prefetches ahead of its loads. The reads of the next
// chunk are demand loads spread over this chunk's scan; without prefetching, only the few
// dozen lines the out-of-order window holds are in flight and one thread reads at 2/3 of a
// copy's rate. 16M u32 exclusive, about 400 interleaved samples per distance, mean of the
// sample medians: 4, 8, 16 and 32 KiB gave 1T 3.10, 2.77, 2.80 and 3.12 ms, and 2T (in the
// host's high-bandwidth state) 1.74, 1.59, 1.65 and 1.78 ms. The hint is T0: T1 measured the
// same, NTA slower at 2T (1.65 against 1.52 ms).
inline constexpr std::size_t kNextPrefetchBytes = 8192;

// One step of the 32-bit sum scan: out[k, k + 2W) from in[k, k + 2W) and the running carry
// (prefix sums within the lanes, then the carry).
template <int W, bool Inclusive, bool Streaming>
[[gnu::always_inline]] inline void scan_step32(const std::uint32_t* in, std::uint32_t* out, std::size_t k,
                                               LaneU32<W>& carry) {
  using L = Lanes<W>;
  using V = LaneU32<W>;
  const V x0 = L::load(in + k);
  const V x1 = L::load(in + k + W);
  const V p0 = prefix_sum<W>(x0);
  // Everything but the carry update is independent of the carry, so the loop-carried chain
  // is one add per 2W elements (a cross-lane broadcast in it would cost its latency).
  const V p1 = prefix_sum<W>(x1) + last_lane<W>(p0);
  V s0 = p0 + carry;
  V s1 = p1 + carry;
  carry += last_lane<W>(p1);
  if constexpr (!Inclusive) {
    s0 -= x0;
    s1 -= x1;
  }
  if constexpr (Streaming) {
    stream_store<W>(s0, out + k);
    stream_store<W>(s1, out + k + W);
  } else {
    L::store(s0, out + k);
    L::store(s1, out + k + W);
  }
}

// The 32-bit sum scan over Lanes<W>, 2W elements per step: prefix sums within the lanes,
// then the running carry. While it scans, it sums the next chunk (the chained pass's
// `next`, null for none) at the same indices: the loads of the next chunk and the stores of
// this one are then one read stream and one write stream, as in a copy, where reducing the
// next chunk separately, its lines prefetched during this scan, left the memory idle while
// it ran (16M u32 exclusive, 1T, alternating runs: 2.62-2.71 ms before, 2.37-2.63 after).
// Streaming: the output is written from its first 64-byte line boundary with stream_store
// (aligned for every W). Returns the next chunk's sum.
// Flattened: in a translation unit with many kernels GCC stopped inlining the W = 16 lane
// split (stdx::split, eight calls per step). 16M u32 exclusive, 1T, W = 16 in the benchmark
// binary: 11.5 ms without, 2.50 with (W = 8: 2.37).
template <int W, bool Inclusive, bool Streaming>
[[gnu::flatten]] std::uint32_t scan_sum32(const std::uint32_t* in, std::uint32_t* out, std::size_t m,
                                          std::uint32_t acc, const std::uint32_t* next, std::size_t next_m) {
  using L = Lanes<W>;
  using V = LaneU32<W>;
  constexpr std::size_t kStep = 2 * W;
  const std::size_t head = Streaming ? to_line(out, m) : 0;
  std::plus<std::uint32_t> plus;
  acc = scan_scalar<Inclusive>(in, out, head, acc, plus);
  if (next == nullptr) next_m = 0;
  // A group is a 64-byte line of the next chunk's elements (one prefetch), or one step when
  // a step is longer.
  constexpr std::size_t kGroup = kStep > 16 ? kStep : 16;
  constexpr std::size_t kAhead = kNextPrefetchBytes / 4;  // elements
#if defined(__SSE__)
  for (std::size_t k = 0; k < std::min(next_m, kAhead); k += 16) _mm_prefetch(next + k, _MM_HINT_T0);
#endif
  V carry(acc);
  V next_lanes(0u);
  std::size_t i = head;
  const std::size_t both = std::min(m, next_m);  // only the last chunk is shorter
  for (; i + kGroup <= both; i += kGroup) {
#if defined(__SSE__)
    for (std::size_t k = 0; k < kGroup; k += 16)
      if (i + k + kAhead < next_m) _mm_prefetch(next + i + k + kAhead, _MM_HINT_T0);
#endif
    for (std::size_t k = i; k < i + kGroup; k += kStep) {
      next_lanes += L::load(next + k) + L::load(next + k + W);
      scan_step32<W, Inclusive, Streaming>(in, out, k, carry);
    }
  }
  const std::size_t summed_end = i;  // next[head, summed_end) is in next_lanes
  for (; i + kStep <= m; i += kStep) scan_step32<W, Inclusive, Streaming>(in, out, i, carry);
  scan_scalar<Inclusive>(in + i, out + i, m - i, std::uint32_t(carry[0]), plus);
  std::uint32_t next_sum = L::hadd(next_lanes);
  for (std::size_t k = 0; k < std::min(head, next_m); ++k) next_sum += next[k];
  for (std::size_t k = std::max(head, summed_end); k < next_m; ++k) next_sum += next[k];
  return next_sum;
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

// Scans in[0, m) from `offset` into out[0, m) (out may equal in) with lane width W, and
// returns the sum of the `next_m` elements at `next` (the chunk the thread does next; T{}
// when null or empty), the same bits as chunk_sum<W>(next, next_m). Streaming: full output
// lines bypass the caches (followed by a store fence, so the join publishes them).
template <int W, bool Inclusive, class T, class Op>
T chunk_scan(const T* in, T* out, std::size_t m, T offset, Op& op, bool streaming, const T* next = nullptr,
             std::size_t next_m = 0) {
  if constexpr (kLaneSum32<T, Op>) {
    const auto* i32 = reinterpret_cast<const std::uint32_t*>(in);
    auto* o32 = reinterpret_cast<std::uint32_t*>(out);
    const auto* n32 = reinterpret_cast<const std::uint32_t*>(next);
    if (streaming) {
      const std::uint32_t next_sum = detail::scan_sum32<W, Inclusive, true>(i32, o32, m, std::uint32_t(offset), n32, next_m);
      stream_fence();
      return T(next_sum);
    }
    return T(detail::scan_sum32<W, Inclusive, false>(i32, o32, m, std::uint32_t(offset), n32, next_m));
  } else {
    bool streamed = false;
    if constexpr (std::is_trivially_copyable_v<T> && 64 % sizeof(T) == 0 && sizeof(T) % 4 == 0) {
      if (streaming) {
        detail::scan_streaming<W, Inclusive>(in, out, m, offset, op);
        stream_fence();
        streamed = true;
      }
    }
    if (!streamed) detail::scan_scalar<Inclusive>(in, out, m, offset, op);
    return next != nullptr && next_m > 0 ? chunk_sum<W>(next, next_m, op) : T{};
  }
}

}  // namespace speculum::par::scan_kernels
