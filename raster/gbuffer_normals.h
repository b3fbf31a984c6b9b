// The shading-normal step of the `gbuffer` node 8 samples at a time (AVX2): normalize the
// interpolated normal and turn opaque surfaces towards the eye.
// The same IEEE operations in the same order as the scalar glm code (length = sqrt of
// (x·x + y·y) + z·z, division per component, no FMA), so the bytes are identical; the
// per-sample sqrt and three divisions were the resolve's bottleneck on the divider unit.
#pragma once

#include <cstddef>
#include <cstdint>

#include <immintrin.h>

#include <glm/vec3.hpp>

namespace speculum::raster::detail {

// Structure-of-arrays lanes of one staging block (N a multiple of 8).
template <std::size_t N>
struct alignas(32) NormalLanes {
  static_assert(N % 8 == 0);
  float nx[N], ny[N], nz[N];  // interpolated normal in, unit shading normal out
  float px[N], py[N], pz[N];  // interpolated position
  std::uint32_t keep_side[N]; // all ones: refractor (keeps its geometric orientation)
  std::uint32_t valid[N];     // out: all ones where the normal had a usable length
};

// For lanes [0, count) (count rounded up to 8; unused lanes hold any finite or zero value):
// n ← n / |n| where |n| > 1e-12 (valid), then n ← −n where the surface is opaque and
// n·(eye − p) < 0. Invalid lanes are left for the caller's face-normal fallback.
template <std::size_t N>
inline void normalize_and_face_eye(NormalLanes<N>& l, std::size_t count, const glm::vec3& eye) {
  const __m256 ex = _mm256_set1_ps(eye.x), ey = _mm256_set1_ps(eye.y), ez = _mm256_set1_ps(eye.z);
  const __m256 tiny = _mm256_set1_ps(1e-12f), zero = _mm256_setzero_ps();
  const __m256 sign = _mm256_castsi256_ps(_mm256_set1_epi32(static_cast<int>(0x80000000u)));
  for (std::size_t j = 0; j < count; j += 8) {
    __m256 x = _mm256_load_ps(l.nx + j), y = _mm256_load_ps(l.ny + j), z = _mm256_load_ps(l.nz + j);
    const __m256 len = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)), _mm256_mul_ps(z, z)));
    const __m256 valid = _mm256_cmp_ps(len, tiny, _CMP_GT_OQ);
    x = _mm256_div_ps(x, len);
    y = _mm256_div_ps(y, len);
    z = _mm256_div_ps(z, len);
    const __m256 dx = _mm256_sub_ps(ex, _mm256_load_ps(l.px + j));
    const __m256 dy = _mm256_sub_ps(ey, _mm256_load_ps(l.py + j));
    const __m256 dz = _mm256_sub_ps(ez, _mm256_load_ps(l.pz + j));
    const __m256 facing = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, dx), _mm256_mul_ps(y, dy)),
                                        _mm256_mul_ps(z, dz));
    const __m256 keep = _mm256_load_ps(reinterpret_cast<const float*>(l.keep_side + j));
    const __m256 flip = _mm256_and_ps(_mm256_andnot_ps(keep, _mm256_cmp_ps(facing, zero, _CMP_LT_OQ)),
                                      sign);
    _mm256_store_ps(l.nx + j, _mm256_xor_ps(x, flip));
    _mm256_store_ps(l.ny + j, _mm256_xor_ps(y, flip));
    _mm256_store_ps(l.nz + j, _mm256_xor_ps(z, flip));
    _mm256_store_ps(reinterpret_cast<float*>(l.valid + j), valid);
  }
}

}  // namespace speculum::raster::detail
