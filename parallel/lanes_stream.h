// Lane operations the stream primitives need beyond element-wise math: in-register prefix
// sums, a broadcast of the last lane, non-temporal (streaming) stores, even/odd word
// deinterleaving, byte flags to a lane mask, and left-packing the indices of set lanes. Each is written once for every W with a
// generic definition; where a width maps to one register (W = 8 on AVX2, some ops at W = 4
// and 16) an intrinsic path replaces it. Every path computes the same bits (integer work only), so
// a kernel written over these ops gives the same output for every W (lanes.h).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "parallel/lanes.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace speculum::par {

template <int W>
using LaneU32 = typename Lanes<W>::u32;

namespace lanes_detail {

#if defined(__AVX2__)
// The 8-lane register type (its ABI holds a __m256i, also under AVX-512), converted to and
// from the fixed-size lanes at no cost.
using Native8 = stdx::simd<std::uint32_t, stdx::simd_abi::deduce_t<std::uint32_t, 8>>;
inline __m256i native(const LaneU32<8>& v) { return static_cast<__m256i>(stdx::static_simd_cast<Native8>(v)); }
inline LaneU32<8> from_native(__m256i m) { return stdx::static_simd_cast<LaneU32<8>>(Native8(m)); }
using Native4 = stdx::simd<std::uint32_t, stdx::simd_abi::deduce_t<std::uint32_t, 4>>;
inline __m128i native(const LaneU32<4>& v) { return static_cast<__m128i>(stdx::static_simd_cast<Native4>(v)); }
inline LaneU32<4> from_native(__m128i m) { return stdx::static_simd_cast<LaneU32<4>>(Native4(m)); }
// W = 16 (two registers under AVX2) as its two 8-lane halves.
[[gnu::always_inline]] inline std::pair<LaneU32<8>, LaneU32<8>> halves(const LaneU32<16>& v) {
  const auto [lo, hi] = stdx::split<8, 8>(v);
  return {stdx::static_simd_cast<LaneU32<8>>(lo), stdx::static_simd_cast<LaneU32<8>>(hi)};
}
[[gnu::always_inline]] inline LaneU32<16> join(const LaneU32<8>& lo, const LaneU32<8>& hi) {
  return stdx::static_simd_cast<LaneU32<16>>(stdx::concat(lo, hi));
}
#endif

// For each W-bit mask, the positions of its set bits packed to the front, one byte each.
template <int W>
struct LeftPackTable {
  static_assert(W == 4 || W == 8);
  alignas(64) std::uint64_t lanes[1 << W];
  constexpr LeftPackTable() : lanes() {
    for (unsigned m = 0; m < (1u << W); ++m) {
      std::uint64_t packed = 0;
      unsigned k = 0;
      for (unsigned b = 0; b < unsigned(W); ++b)
        if (m >> b & 1) packed |= std::uint64_t(b) << (8 * k++);
      lanes[m] = packed;
    }
  }
};
template <int W>
inline constexpr LeftPackTable<W> kLeftPack{};

}  // namespace lanes_detail

template <int W>
[[gnu::always_inline]] inline LaneU32<W> last_lane(const LaneU32<W>& v);

// The ops are forced inline: they are one to a few instructions each, and an out-of-line
// call per vector (GCC's choice for the 16-lane forms) costs more than the op.

// Inclusive prefix sum across the lanes: r[i] = v[0] + ... + v[i] (mod 2^32).
template <int W>
[[gnu::always_inline]] inline LaneU32<W> prefix_sum(const LaneU32<W>& v) {
#if defined(__AVX2__)
  if constexpr (W == 8) {
    __m256i x = lanes_detail::native(v);
    x = _mm256_add_epi32(x, _mm256_slli_si256(x, 4));
    x = _mm256_add_epi32(x, _mm256_slli_si256(x, 8));
    // Carry the low half's total (lane 3) into every lane of the high half.
    const __m256i low_total = _mm256_shuffle_epi32(x, 0xff);
    return lanes_detail::from_native(_mm256_add_epi32(x, _mm256_permute2x128_si256(low_total, low_total, 0x08)));
  }
  if constexpr (W == 4) {
    __m128i x = lanes_detail::native(v);
    x = _mm_add_epi32(x, _mm_slli_si128(x, 4));
    return lanes_detail::from_native(_mm_add_epi32(x, _mm_slli_si128(x, 8)));
  }
  if constexpr (W == 16) {
    const auto [lo, hi] = lanes_detail::halves(v);
    const LaneU32<8> plo = prefix_sum<8>(lo);
    return lanes_detail::join(plo, prefix_sum<8>(hi) + last_lane<8>(plo));
  }
#endif
  // Hillis–Steele: log2(W) shifted adds.
  LaneU32<W> r = v;
  for (int shift = 1; shift < W; shift *= 2)
    r += LaneU32<W>([&](auto i) { return int(i) >= shift ? std::uint32_t(r[int(i) - shift]) : 0u; });
  return r;
}

// Every lane = v[W - 1].
template <int W>
[[gnu::always_inline]] inline LaneU32<W> last_lane(const LaneU32<W>& v) {
#if defined(__AVX2__)
  if constexpr (W == 8)
    return lanes_detail::from_native(_mm256_permutevar8x32_epi32(lanes_detail::native(v), _mm256_set1_epi32(7)));
  if constexpr (W == 4) return lanes_detail::from_native(_mm_shuffle_epi32(lanes_detail::native(v), 0xff));
#endif
  return LaneU32<W>(std::uint32_t(v[W - 1]));
}

// Stores v to p[0, W) bypassing the caches; p must be aligned to 4·W bytes (a line-aligned
// output is aligned for every W). Call stream_fence() before other threads read the output.
template <int W>
[[gnu::always_inline]] inline void stream_store(const LaneU32<W>& v, std::uint32_t* p) {
#if defined(__AVX2__)
  if constexpr (W == 8) {
    _mm256_stream_si256(reinterpret_cast<__m256i*>(p), lanes_detail::native(v));
    return;
  }
  if constexpr (W == 16) {
    const auto [lo, hi] = lanes_detail::halves(v);
    stream_store<8>(lo, p);
    stream_store<8>(hi, p + 8);
    return;
  }
  if constexpr (W == 4) {
    _mm_stream_si128(reinterpret_cast<__m128i*>(p), lanes_detail::native(v));
    return;
  }
#endif
#if defined(__SSE2__)
  if constexpr (W == 1) {
    _mm_stream_si32(reinterpret_cast<int*>(p), int(std::uint32_t(v[0])));
    return;
  }
#endif
  v.copy_to(p, stdx::element_aligned);
}

// The even and odd words of p[0, 2W): {p[0], p[2], ...} and {p[1], p[3], ...} — the low and
// high halves of W packed 64-bit words on a little-endian machine.
template <int W>
[[gnu::always_inline]] inline std::pair<LaneU32<W>, LaneU32<W>> deinterleave(const std::uint32_t* p) {
#if defined(__AVX2__)
  if constexpr (W == 8) {
    const __m256 a = _mm256_castsi256_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)));
    const __m256 b = _mm256_castsi256_ps(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 8)));
    // Pick per 128-bit lane, then put the quadwords back in order.
    const auto pick = [](__m256 x) { return _mm256_permute4x64_epi64(_mm256_castps_si256(x), _MM_SHUFFLE(3, 1, 2, 0)); };
    return {lanes_detail::from_native(pick(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)))),
            lanes_detail::from_native(pick(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1))))};
  }
  if constexpr (W == 16) {
    const auto [e0, o0] = deinterleave<8>(p);
    const auto [e1, o1] = deinterleave<8>(p + 16);
    return {lanes_detail::join(e0, e1), lanes_detail::join(o0, o1)};
  }
#endif
  return {LaneU32<W>([&](auto i) { return p[2 * int(i)]; }), LaneU32<W>([&](auto i) { return p[2 * int(i) + 1]; })};
}

// Orders this thread's streaming stores before its later stores (e.g. before a join
// publishes the output).
inline void stream_fence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

// How many elements of p[0, m) come before the first 64-byte line boundary (m if none does,
// or if p is not aligned to its element): the head a streaming kernel writes plainly.
template <class T>
std::size_t to_line(const T* p, std::size_t m) {
  const std::uintptr_t a = reinterpret_cast<std::uintptr_t>(p);
  if (a % sizeof(T) != 0) return m;
  const std::size_t k = ((64 - a % 64) % 64) / sizeof(T);
  return k < m ? k : m;
}

// Copies src[0, words) to dst with stream_store, W words at a time: dst aligned to 4·W
// bytes, words a multiple of W.
template <int W>
[[gnu::always_inline]] inline void stream_words(const std::uint32_t* src, std::size_t words, std::uint32_t* dst) {
  for (std::size_t k = 0; k < words; k += W) stream_store<W>(Lanes<W>::load(src + k), dst + k);
}

// Bit k set iff flags[k] != 0, for k < W.
template <int W>
[[gnu::always_inline]] inline unsigned nonzero_bits(const std::uint8_t* flags) {
#if defined(__SSE2__)
  if constexpr (W == 8 || W == 16) {
    const __m128i v = W == 8 ? _mm_loadl_epi64(reinterpret_cast<const __m128i*>(flags))
                             : _mm_loadu_si128(reinterpret_cast<const __m128i*>(flags));
    const unsigned zero = unsigned(_mm_movemask_epi8(_mm_cmpeq_epi8(v, _mm_setzero_si128())));
    return ~zero & ((1u << W) - 1);
  }
#endif
  unsigned m = 0;
  for (int k = 0; k < W; ++k) m |= unsigned(flags[k] != 0) << k;
  return m;
}

// Lanes [0, popcount(bits)) = first + the positions of the set bits of `bits`, ascending;
// the other lanes are unspecified (a kernel stores all W and lets later stores overwrite).
template <int W>
[[gnu::always_inline]] inline LaneU32<W> left_pack(unsigned bits, std::uint32_t first) {
#if defined(__AVX2__)
  if constexpr (W == 8) {
    const __m256i pos =
        _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(std::int64_t(lanes_detail::kLeftPack<8>.lanes[bits & 0xff])));
    return lanes_detail::from_native(_mm256_add_epi32(pos, _mm256_set1_epi32(int(first))));
  }
  if constexpr (W == 16) {  // two 8-lane packs, the second stored right after the first's kept lanes
    alignas(64) std::uint32_t packed[24];
    left_pack<8>(bits & 0xff, first).copy_to(packed, stdx::element_aligned);
    left_pack<8>(bits >> 8 & 0xff, first + 8).copy_to(packed + std::popcount(bits & 0xffu), stdx::element_aligned);
    return LaneU32<W>(packed, stdx::element_aligned);
  }
#endif
  if constexpr (W == 1) return LaneU32<W>(first);  // lane 0 matters only when bit 0 is set
  if constexpr (W == 4) {
    const std::uint64_t packed = lanes_detail::kLeftPack<4>.lanes[bits & 0xf];
#if defined(__AVX2__)
    const __m128i pos = _mm_cvtepu8_epi32(_mm_cvtsi32_si128(int(packed)));
    return lanes_detail::from_native(_mm_add_epi32(pos, _mm_set1_epi32(int(first))));
#else
    return LaneU32<W>([&](auto i) { return first + std::uint32_t(packed >> (8 * int(i)) & 0xff); });
#endif
  }
  std::uint32_t pos[W] = {};
  int k = 0;
  for (int b = 0; b < W; ++b)
    if (bits >> b & 1) pos[k++] = first + std::uint32_t(b);
  return LaneU32<W>(pos, stdx::element_aligned);
}

}  // namespace speculum::par
