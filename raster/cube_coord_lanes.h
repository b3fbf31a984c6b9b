// cube_coord (raster/cube_map.h) for eight directions at once: per lane the operations of
// cube_coord in its order — the face of the largest component (ties as there), the signed
// components along the face's axes, the projection clamped to [0, size] — so each lane has
// the bits of the scalar call. Shared by the kernels that look up cube maps in lanes (shadow
// taps, prefiltering, distance-map searches).
#pragma once

#include <immintrin.h>
#include <stdexcept>

#include "parallel/lanes.h"
#include "raster/cube_map.h"

namespace speculum::raster {

struct CubeCoordLanes {
  par::Lanes<8>::i32 face;
  par::Lanes<8>::f32 x, y;  // CubeCoord::pixel
};

namespace detail {

// kCubeFaceAxes as cube_coord8 reads it: each face's axis signs in lanes 0..5 of a register,
// and the axes each pair of faces 2k, 2k + 1 shares (both look along axis k, the axis
// cube_coord picks them by).
struct CubeFaceLanes {
  __m256 forward_sign, right_sign, up_sign;
  int forward[3], right[3], up[3];
  CubeFaceLanes() {
    alignas(32) float signs[3][8] = {};
    for (int f = 0; f < kCubeFaces; ++f) {
      const CubeFaceAxes& a = kCubeFaceAxes[f];
      signs[0][f] = a.forward_sign, signs[1][f] = a.right_sign, signs[2][f] = a.up_sign;
      const CubeFaceAxes& pair = kCubeFaceAxes[f & ~1];
      if (a.forward != f / 2 || a.right != pair.right || a.up != pair.up)
        throw std::logic_error("cube faces 2k and 2k+1 must look along axis k and share their right and up axes");
    }
    forward_sign = _mm256_load_ps(signs[0]), right_sign = _mm256_load_ps(signs[1]), up_sign = _mm256_load_ps(signs[2]);
    for (int k = 0; k < 3; ++k)
      forward[k] = kCubeFaceAxes[2 * k].forward, right[k] = kCubeFaceAxes[2 * k].right, up[k] = kCubeFaceAxes[2 * k].up;
  }
};

inline const CubeFaceLanes& cube_face_lanes() {
  static const CubeFaceLanes lanes;
  return lanes;
}

}  // namespace detail

[[gnu::always_inline]] inline CubeCoordLanes cube_coord8(const par::Lanes<8>::f32 (&d)[3], int size) {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using i32 = L::i32;
  const f32 ax = L::abs(d[0]), ay = L::abs(d[1]), az = L::abs(d[2]);
  const auto is_x = (ax >= ay) && (ax >= az);
  const auto is_y = !is_x && (ay >= az);
  const f32 major = L::select(is_x, d[0], L::select(is_y, d[1], d[2]));
  i32 face = L::select(is_x, i32(0), L::select(is_y, i32(2), i32(4)));
  face = L::select(!(major >= 0.0f), face + 1, face);
  // Each lane's face's signed components: the component its pair of faces reads, times the
  // face's sign (cube_coord's product: a.forward_sign * d[a.forward] and so on).
  const detail::CubeFaceLanes& axes = detail::cube_face_lanes();
  const auto along = [&](const int (&axis)[3], __m256 sign) {
    const f32 component = L::select(is_x, d[axis[0]], L::select(is_y, d[axis[1]], d[axis[2]]));
    return f32(_mm256_permutevar8x32_ps(sign, static_cast<__m256i>(face))) * component;
  };
  const f32 depth = along(axes.forward, axes.forward_sign);
  const f32 along_right = along(axes.right, axes.right_sign), along_up = along(axes.up, axes.up_sign);
  const float s = static_cast<float>(size);
  return {face, L::clamp((along_right / depth + 1.0f) * 0.5f * s, f32(0.0f), f32(s)),
          L::clamp((1.0f - along_up / depth) * 0.5f * s, f32(0.0f), f32(s))};
}

}  // namespace speculum::raster
