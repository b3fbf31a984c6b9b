// cube_coord (raster/cube_map.h) for eight directions at once: per lane the operations of
// cube_coord in its order — the face of the largest component (ties as there), the signed
// components along the face's axes, the projection clamped to [0, size] — so each lane has
// the bits of the scalar call. Shared by the kernels that look up cube maps in lanes (shadow
// taps, prefiltering, distance-map searches).
#pragma once

#include <immintrin.h>

#include "parallel/lanes.h"
#include "raster/cube_map.h"

namespace speculum::raster {

struct CubeCoordLanes {
  par::Lanes<8>::i32 face;
  par::Lanes<8>::f32 x, y;  // CubeCoord::pixel
};

namespace detail {

// The axes of cube_coord's faces (kCubeFaceAxes, made from the face cameras' frames; the
// CubeCoordLanes test holds these to it): faces 2k and 2k + 1 look along axis k; a face's right
// axis is z on the x faces and x on the others, its up axis z on the y faces and y on the
// others; and each face's signs along them.
constexpr int kRightAxis[3] = {2, 0, 0}, kUpAxis[3] = {1, 2, 1};
constexpr float kForwardSign[kCubeFaces] = {1, -1, 1, -1, 1, -1};
constexpr float kRightSign[kCubeFaces] = {1, -1, -1, -1, -1, 1};
constexpr float kUpSign[kCubeFaces] = {1, 1, -1, 1, 1, 1};

// A face table's six entries in lanes 0..5 of a register (a permute by face reads them).
inline __m256 face_lanes(const float (&v)[kCubeFaces]) { return _mm256_setr_ps(v[0], v[1], v[2], v[3], v[4], v[5], 0, 0); }

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
  const auto sign = [&](const float (&of_face)[kCubeFaces]) {
    return f32(_mm256_permutevar8x32_ps(detail::face_lanes(of_face), static_cast<__m256i>(face)));
  };
  static_assert(detail::kRightAxis[1] == 0 && detail::kRightAxis[2] == 0 && detail::kUpAxis[0] == detail::kUpAxis[2]);
  const f32 depth = sign(detail::kForwardSign) * major;
  const f32 along_right = sign(detail::kRightSign) * L::select(is_x, d[detail::kRightAxis[0]], d[0]);
  const f32 along_up = sign(detail::kUpSign) * L::select(is_y, d[detail::kUpAxis[1]], d[detail::kUpAxis[0]]);
  const float s = static_cast<float>(size);
  return {face, L::clamp((along_right / depth + 1.0f) * 0.5f * s, f32(0.0f), f32(s)),
          L::clamp((1.0f - along_up / depth) * 0.5f * s, f32(0.0f), f32(s))};
}

// The texel holding each lane's coordinate (CubeMap::distance_at's): truncated, at most
// size − 1 (and at least 0, which a finite coordinate in [0, size] already is).
[[gnu::always_inline]] inline void nearest_texel8(const CubeCoordLanes& c, int size, par::Lanes<8>::i32& x,
                                                  par::Lanes<8>::i32& y) {
  using L = par::Lanes<8>;
  const L::i32 last(size - 1), zero(0);
  x = L::clamp(L::to_int(c.x), zero, last), y = L::clamp(L::to_int(c.y), zero, last);
}

}  // namespace speculum::raster
