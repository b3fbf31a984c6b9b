// cube_coord (raster/cube_map.h) for eight directions at once: per lane the operations of
// cube_coord in its order — the face of the largest component (ties as there), the signed
// components along the face's axes, the projection clamped to [0, size] — so each lane has
// the bits of the scalar call. Shared by the kernels that look up cube maps in lanes (shadow
// taps, prefiltering, distance-map searches).
#pragma once

#include "parallel/lanes.h"
#include "raster/cube_map.h"

namespace speculum::raster {

struct CubeCoordLanes {
  par::Lanes<8>::i32 face;
  par::Lanes<8>::f32 x, y;  // CubeCoord::pixel
};

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
  f32 depth(0.0f), along_right(0.0f), along_up(0.0f);
  for (int f = 0; f < kCubeFaces; ++f) {
    const L::mask here = face == f;
    const CubeFaceAxes& a = kCubeFaceAxes[f];
    depth = L::select(here, a.forward_sign * d[a.forward], depth);
    along_right = L::select(here, a.right_sign * d[a.right], along_right);
    along_up = L::select(here, a.up_sign * d[a.up], along_up);
  }
  const float s = static_cast<float>(size);
  return {face, L::clamp((along_right / depth + 1.0f) * 0.5f * s, f32(0.0f), f32(s)),
          L::clamp((1.0f - along_up / depth) * 0.5f * s, f32(0.0f), f32(s))};
}

}  // namespace speculum::raster
