// The 8×8 transpose of 32-bit lanes in AVX2: eight records of eight dwords to eight lanes of
// each field and back (triangle setup assembles its records with it); eight RGBA texels'
// colour channels as lanes (texel lookups in lanes).
#pragma once

#include <immintrin.h>

namespace speculum::raster::detail {

// out[k] holds element k of in[0], in[1], ..., in[7] (lane j of out[k] = lane k of in[j]).
inline void transpose8(const __m256 (&in)[8], __m256 (&out)[8]) {
  const __m256 t0 = _mm256_unpacklo_ps(in[0], in[1]), t1 = _mm256_unpackhi_ps(in[0], in[1]);
  const __m256 t2 = _mm256_unpacklo_ps(in[2], in[3]), t3 = _mm256_unpackhi_ps(in[2], in[3]);
  const __m256 t4 = _mm256_unpacklo_ps(in[4], in[5]), t5 = _mm256_unpackhi_ps(in[4], in[5]);
  const __m256 t6 = _mm256_unpacklo_ps(in[6], in[7]), t7 = _mm256_unpackhi_ps(in[6], in[7]);
  const __m256 u0 = _mm256_shuffle_ps(t0, t2, 0x44), u1 = _mm256_shuffle_ps(t0, t2, 0xee);
  const __m256 u2 = _mm256_shuffle_ps(t1, t3, 0x44), u3 = _mm256_shuffle_ps(t1, t3, 0xee);
  const __m256 u4 = _mm256_shuffle_ps(t4, t6, 0x44), u5 = _mm256_shuffle_ps(t4, t6, 0xee);
  const __m256 u6 = _mm256_shuffle_ps(t5, t7, 0x44), u7 = _mm256_shuffle_ps(t5, t7, 0xee);
  out[0] = _mm256_permute2f128_ps(u0, u4, 0x20), out[1] = _mm256_permute2f128_ps(u1, u5, 0x20);
  out[2] = _mm256_permute2f128_ps(u2, u6, 0x20), out[3] = _mm256_permute2f128_ps(u3, u7, 0x20);
  out[4] = _mm256_permute2f128_ps(u0, u4, 0x31), out[5] = _mm256_permute2f128_ps(u1, u5, 0x31);
  out[6] = _mm256_permute2f128_ps(u2, u6, 0x31), out[7] = _mm256_permute2f128_ps(u3, u7, 0x31);
}

inline void transpose8(const __m256i (&in)[8], __m256i (&out)[8]) {
  __m256 f[8], g[8];
  for (int k = 0; k < 8; ++k) f[k] = _mm256_castsi256_ps(in[k]);
  transpose8(f, g);
  for (int k = 0; k < 8; ++k) out[k] = _mm256_castps_si256(g[k]);
}

// The red, green and blue of eight RGBA texels (texel[j]: lane j's four floats) into
// rgb[c][j] (32-byte aligned): each texel one 128-bit load, lanes j and j + 4 in the two
// halves of a register, the rows transposed into channels within the halves: the values one
// load per channel would give. Whole registers are stored (a 256-bit load of two 128-bit
// stores would wait for them to reach the cache).
inline void rgb_of_rgba8(const float* const (&texel)[8], float (&rgb)[3][8]) {
  __m256 r[4];
  for (int j = 0; j < 4; ++j)
    r[j] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(texel[j])), _mm_loadu_ps(texel[j + 4]), 1);
  const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
  const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
  _mm256_store_ps(rgb[0], _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0)));
  _mm256_store_ps(rgb[1], _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2)));
  _mm256_store_ps(rgb[2], _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0)));
}

}  // namespace speculum::raster::detail
