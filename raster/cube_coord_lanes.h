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

// The axes of cube_coord's faces (kCubeFaceAxes): faces 2k and 2k + 1 look along axis k; a
// face's right axis is z on the x faces and x on the others, its up axis z on the y faces and
// y on the others. Checked against the table once; each face's signs in lanes 0..5 of a
// register.
constexpr int kRightAxis[3] = {2, 0, 0}, kUpAxis[3] = {1, 2, 1};
struct CubeFaceSigns {
  __m256 forward, right, up;
  CubeFaceSigns() {
    alignas(32) float signs[3][8] = {};
    for (int f = 0; f < kCubeFaces; ++f) {
      const CubeFaceAxes& a = kCubeFaceAxes[f];
      if (a.forward != f / 2 || a.right != kRightAxis[f / 2] || a.up != kUpAxis[f / 2])
        throw std::logic_error("cube_coord8: the cube faces' axes are not the ones it was written for");
      signs[0][f] = a.forward_sign, signs[1][f] = a.right_sign, signs[2][f] = a.up_sign;
    }
    forward = _mm256_load_ps(signs[0]), right = _mm256_load_ps(signs[1]), up = _mm256_load_ps(signs[2]);
  }
};

inline const CubeFaceSigns& cube_face_signs() {
  static const CubeFaceSigns signs;
  return signs;
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
  // Each lane's face's signed components (cube_coord's a.forward_sign * d[a.forward] and so
  // on): the face's sign times the component its axis names.
  const detail::CubeFaceSigns& signs = detail::cube_face_signs();
  const auto sign = [&](__m256 of_face) { return f32(_mm256_permutevar8x32_ps(of_face, static_cast<__m256i>(face))); };
  static_assert(detail::kRightAxis[1] == 0 && detail::kRightAxis[2] == 0 && detail::kUpAxis[0] == detail::kUpAxis[2]);
  const f32 depth = sign(signs.forward) * major;
  const f32 along_right = sign(signs.right) * L::select(is_x, d[detail::kRightAxis[0]], d[0]);
  const f32 along_up = sign(signs.up) * L::select(is_y, d[detail::kUpAxis[1]], d[detail::kUpAxis[0]]);
  const float s = static_cast<float>(size);
  return {face, L::clamp((along_right / depth + 1.0f) * 0.5f * s, f32(0.0f), f32(s)),
          L::clamp((1.0f - along_up / depth) * 0.5f * s, f32(0.0f), f32(s))};
}

}  // namespace speculum::raster
