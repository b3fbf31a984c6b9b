// Lane ops for the compaction kernels (compact.cpp), beside lanes_stream.h: a 32-flag mask
// read as W-lane groups. Like lanes_stream.h, each op has one generic definition for every
// W and a single-instruction path where it pays on AVX2; both give the same bits (integer
// work only), so kernels written over them give the same output for every W.
#pragma once

#include <cstdint>

#include "parallel/lanes_stream.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace speculum::par {

// Bit k set iff flags[k] != 0, for k < 32: the 32/W groups of nonzero_bits<W>, lowest group
// in the low bits. A kernel that consumes 32 flags per step reads them with one mask; at
// W >= 8 that is one 32-byte compare on AVX2 (four 8-byte ones cost a fifth more time in the
// compaction scatter); W = 1 and 4 keep the group-wise definition.
template <int W>
[[gnu::always_inline]] inline std::uint32_t nonzero_mask32(const std::uint8_t* flags) {
  static_assert(32 % W == 0);
#if defined(__AVX2__)
  if constexpr (W >= 8) {
    const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(flags));
    return ~std::uint32_t(_mm256_movemask_epi8(_mm256_cmpeq_epi8(v, _mm256_setzero_si256())));
  }
#endif
  std::uint32_t m = 0;
  for (int g = 0; g < 32; g += W) m |= std::uint32_t(nonzero_bits<W>(flags + g)) << g;
  return m;
}

}  // namespace speculum::par
