// Per-chunk kernels of the chained scan (scan.h): chunk sum and chunk scan from an offset,
// generic over T and Op, with AVX2 versions for 32-bit integer sums (exact in any order)
// and optional streaming (cache-bypassing) stores for outputs too big to stay cached.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <type_traits>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace speculum::par::scan_kernels {

inline void cpu_relax() {
#if defined(__AVX2__)
  _mm_pause();
#endif
}

// 32-bit integer sums take the SIMD path: wrap-around addition is associative, so any
// grouping gives the serial fold's bits.
template <class T, class Op>
inline constexpr bool kSimdSum32 =
    std::is_integral_v<T> && sizeof(T) == 4 &&
    (std::is_same_v<Op, std::plus<T>> || std::is_same_v<Op, std::plus<>>);

// in[0] ⊕ in[1] ⊕ ... ⊕ in[m-1], folded left from in[0] (the documented float association).
// m >= 1.
template <class T, class Op>
T chunk_sum(const T* in, std::size_t m, Op& op) {
#if defined(__AVX2__)
  if constexpr (kSimdSum32<T, Op>) {
    __m256i a0 = _mm256_setzero_si256(), a1 = a0, a2 = a0, a3 = a0;
    std::size_t i = 0;
    for (; i + 32 <= m; i += 32) {
      a0 = _mm256_add_epi32(a0, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i)));
      a1 = _mm256_add_epi32(a1, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i + 8)));
      a2 = _mm256_add_epi32(a2, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i + 16)));
      a3 = _mm256_add_epi32(a3, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i + 24)));
    }
    const __m256i a = _mm256_add_epi32(_mm256_add_epi32(a0, a1), _mm256_add_epi32(a2, a3));
    __m128i h = _mm_add_epi32(_mm256_castsi256_si128(a), _mm256_extracti128_si256(a, 1));
    h = _mm_add_epi32(h, _mm_shuffle_epi32(h, 0x4e));
    h = _mm_add_epi32(h, _mm_shuffle_epi32(h, 0xb1));
    std::uint32_t s = std::uint32_t(_mm_cvtsi128_si32(h));
    for (; i < m; ++i) s += std::uint32_t(in[i]);
    return T(s);
  }
#endif
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

// Elements before `p + k` is 64-byte aligned (m if that is never reached within m).
template <class T>
std::size_t to_line(const T* p, std::size_t m) {
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
  if (a % sizeof(T) != 0) return m;
  const std::size_t k = ((64 - a % 64) % 64) / sizeof(T);
  return k < m ? k : m;
}

#if defined(__AVX2__)
// Streams one 64-byte line (64-byte aligned dst) out of two registers.
inline void stream_line(void* dst, __m256i lo, __m256i hi) {
  _mm256_stream_si256(static_cast<__m256i*>(dst), lo);
  _mm256_stream_si256(static_cast<__m256i*>(dst) + 1, hi);
}

// Inclusive prefix sum of the 8 lanes of x.
inline __m256i prefix8(__m256i x) {
  x = _mm256_add_epi32(x, _mm256_slli_si256(x, 4));
  x = _mm256_add_epi32(x, _mm256_slli_si256(x, 8));
  // Carry the low half's total (lane 3) into every lane of the high half.
  const __m256i low_total = _mm256_shuffle_epi32(x, 0xff);
  return _mm256_add_epi32(x, _mm256_permute2x128_si256(low_total, low_total, 0x08));
}

// Prefetch::next / end: the lines of the chunk this thread most likely scans next, fetched
// into L2 one line per 16 elements of this chunk's scan, so its reduction reads cache while
// this scan, bound by arithmetic and writes, would otherwise leave the memory reads idle.
struct Prefetch {
  const char* next = nullptr;
  const char* end = nullptr;
  void step() {
    if (next < end) {
      _mm_prefetch(next, _MM_HINT_T1);
      next += 64;
    }
  }
  void rest() {
    for (; next < end; next += 64) _mm_prefetch(next, _MM_HINT_T1);
  }
};

template <bool Inclusive, bool Streaming>
std::uint32_t scan_sum32(const std::uint32_t* in, std::uint32_t* out, std::size_t m,
                         std::uint32_t acc, Prefetch& prefetch) {
  std::size_t i = Streaming ? to_line(out, m) : 0;
  std::plus<std::uint32_t> plus;
  acc = scan_scalar<Inclusive>(in, out, i, acc, plus);
  __m256i carry = _mm256_set1_epi32(int(acc));
  const __m256i last = _mm256_set1_epi32(7);
  for (; i + 16 <= m; i += 16) {
    prefetch.step();
    const __m256i x0 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i));
    const __m256i x1 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i + 8));
    const __m256i p0 = prefix8(x0);
    // Everything but the carry update is independent of the carry, so the loop-carried
    // chain is one add per 16 elements (a cross-lane broadcast in it would cost its latency).
    const __m256i p1 = _mm256_add_epi32(prefix8(x1), _mm256_permutevar8x32_epi32(p0, last));
    __m256i s0 = _mm256_add_epi32(p0, carry);
    __m256i s1 = _mm256_add_epi32(p1, carry);
    carry = _mm256_add_epi32(carry, _mm256_permutevar8x32_epi32(p1, last));
    if constexpr (!Inclusive) {
      s0 = _mm256_sub_epi32(s0, x0);
      s1 = _mm256_sub_epi32(s1, x1);
    }
    if constexpr (Streaming) {
      stream_line(out + i, s0, s1);
    } else {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), s0);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i + 8), s1);
    }
  }
  acc = std::uint32_t(_mm256_cvtsi256_si32(carry));
  return scan_scalar<Inclusive>(in + i, out + i, m - i, acc, plus);
}

// Generic streaming: scan a block into an aligned buffer in cache, then stream it out.
template <bool Inclusive, class T, class Op>
T scan_streaming(const T* in, T* out, std::size_t m, T acc, Op& op) {
  constexpr std::size_t kBlock = 2048 / sizeof(T);  // a multiple of a line when 64 % sizeof(T) == 0
  std::size_t i = to_line(out, m);
  acc = scan_scalar<Inclusive>(in, out, i, acc, op);
  alignas(64) T buf[kBlock];
  for (; i + kBlock <= m; i += kBlock) {
    acc = scan_scalar<Inclusive>(in + i, buf, kBlock, acc, op);
    for (std::size_t k = 0; k < kBlock * sizeof(T); k += 64)
      stream_line(reinterpret_cast<char*>(out + i) + k,
                  _mm256_load_si256(reinterpret_cast<const __m256i*>(reinterpret_cast<const char*>(buf) + k)),
                  _mm256_load_si256(reinterpret_cast<const __m256i*>(reinterpret_cast<const char*>(buf) + k + 32)));
  }
  return scan_scalar<Inclusive>(in + i, out + i, m - i, acc, op);
}
#endif

}  // namespace detail

// Scans in[0, m) from `offset` into out[0, m) (out may equal in). Streaming: full output
// lines bypass the caches (followed by a store fence, so the join publishes them), and the
// `next_count` elements at `next` (the thread's likely next chunk, none when null) are prefetched
// into L2 during the scan.
template <bool Inclusive, class T, class Op>
void chunk_scan(const T* in, T* out, std::size_t m, T offset, Op& op, bool streaming,
                const T* next = nullptr, std::size_t next_count = 0) {
#if defined(__AVX2__)
  if constexpr (kSimdSum32<T, Op>) {
    const auto* i32 = reinterpret_cast<const std::uint32_t*>(in);
    auto* o32 = reinterpret_cast<std::uint32_t*>(out);
    detail::Prefetch prefetch;
    if (streaming && next != nullptr) {
      prefetch.next = reinterpret_cast<const char*>(next);
      prefetch.end = reinterpret_cast<const char*>(next + next_count);
    }
    if (streaming) {
      detail::scan_sum32<Inclusive, true>(i32, o32, m, std::uint32_t(offset), prefetch);
      _mm_sfence();
    } else {
      detail::scan_sum32<Inclusive, false>(i32, o32, m, std::uint32_t(offset), prefetch);
    }
    prefetch.rest();
    return;
  }
  if constexpr (std::is_trivially_copyable_v<T> && 64 % sizeof(T) == 0) {
    if (streaming) {
      detail::scan_streaming<Inclusive>(in, out, m, offset, op);
      _mm_sfence();
      return;
    }
  }
#endif
  (void)streaming, (void)next, (void)next_count;
  detail::scan_scalar<Inclusive>(in, out, m, offset, op);
}

}  // namespace speculum::par::scan_kernels
