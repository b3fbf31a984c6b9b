// The material parameters of every sample of an image (a G-buffer's surface plane), stored as
// one slot per sample: most samples lie on materials whose parameters are the same everywhere
// (no texture), and those share one entry per material instead of writing 44 bytes per sample.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/image.h"
#include "core/shading.h"

namespace speculum {

struct SurfacePlane {
  // slot value of a sample whose parameters are its own entry of `own`.
  static constexpr std::uint32_t kOwn = 0xffffffffu;

  IdBuffer slot;                      // per sample: an index into `shared`, or kOwn
  std::vector<SurfaceParams> shared;  // parameters many samples share
  Buffer2D<SurfaceParams> own;        // per sample, read only where slot is kOwn (empty when none is)

  int width() const { return slot.width; }
  int height() const { return slot.height; }
  std::size_t size() const { return slot.size(); }
  const SurfaceParams& operator[](std::size_t i) const {
    const std::uint32_t s = slot.pixels[i];
    return s == kOwn ? own.pixels[i] : shared[s];
  }

  // Every sample with its own parameters: a plane written sample by sample.
  static SurfacePlane per_sample(Buffer2D<SurfaceParams> params) {
    SurfacePlane p;
    p.slot = IdBuffer(params.width, params.height, kOwn);
    p.own = std::move(params);
    return p;
  }
  // Every sample with the same parameters.
  static SurfacePlane uniform(int width, int height, const SurfaceParams& params) {
    SurfacePlane p;
    p.slot = IdBuffer(width, height, 0);
    p.shared = {params};
    return p;
  }
};

}  // namespace speculum
