// A cube map's bilinear colour lookup (CubeMap::colour_at, bilinear_face) at eight cube
// coordinates at once: per lane the scalar clamp, taps and weights in their order, so each
// lane has the bits of the scalar lookup. Shared by the kernels that read a cube's colour in
// lanes (prefiltering, the caustic gather).
#pragma once

#include <array>

#include "parallel/lanes.h"
#include "raster/cube_coord_lanes.h"
#include "raster/cube_map.h"
#include "raster/transpose8.h"

namespace speculum::raster {

// Six square RGBA faces as bilinear_rgb8 reads them: their side and each face's first float
// (every face allocated).
struct RgbaFaces {
  int side;
  const float* pixels[kCubeFaces];
  explicit RgbaFaces(const std::array<ImageRGBA, kCubeFaces>& faces) : side(faces[0].width) {
    for (int f = 0; f < kCubeFaces; ++f) pixels[f] = &faces[f].pixels[0].x;
  }
};

// The bilinear red, green and blue at each lane's coordinate (finite: within [0, side]).
[[gnu::always_inline]] inline void bilinear_rgb8(const RgbaFaces& faces, const CubeCoordLanes& cc,
                                                 par::Lanes<8>::f32 (&out)[3]) {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using i32 = L::i32;
  const int side = faces.side;
  const float last = static_cast<float>(side - 1);
  const f32 fx = L::clamp(cc.x - 0.5f, f32(0.0f), f32(last)), fy = L::clamp(cc.y - 0.5f, f32(0.0f), f32(last));
  const i32 x0 = L::to_int(fx), y0 = L::to_int(fy);
  const i32 x1 = L::min(x0 + 1, i32(side - 1)), y1 = L::min(y0 + 1, i32(side - 1));
  const f32 tx = fx - L::to_float(x0), ty = fy - L::to_float(y0);
  const f32 wx = 1.0f - tx, wy = 1.0f - ty;
  const i32 row0 = y0 * side, row1 = y1 * side;
  const i32 taps[4] = {(row0 + x0) * 4, (row0 + x1) * 4, (row1 + x0) * 4, (row1 + x1) * 4};
  // Each lane's tap texel loaded as one RGBA row and transposed into channels.
  alignas(32) float channel[4][3][8];  // [tap][channel][lane]
  for (int q = 0; q < 4; ++q) {
    const float* texel[8];
    for (int j = 0; j < 8; ++j) texel[j] = faces.pixels[cc.face[j]] + taps[q][j];
    detail::rgb_of_rgba8(texel, channel[q]);
  }
  for (int c = 0; c < 3; ++c) {
    const auto tap = [&](int q) { return L::load_aligned(channel[q][c]); };
    out[c] = (tap(0) * wx + tap(1) * tx) * wy + (tap(2) * wx + tap(3) * tx) * ty;
  }
}

}  // namespace speculum::raster
