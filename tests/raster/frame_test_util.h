// Helpers shared by the raster tests that render whole frames: one technique's display image,
// and byte equality of two images.
#pragma once

#include <cstring>
#include <string>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"

namespace speculum::raster {

// The display image of `technique` on `scene`, rendered on `threads` threads.
inline ImageRGBA render_display(const Scene& scene, const std::string& technique,
                                const pipeline::FrameSettings& f, int threads = 2) {
  par::Executor ex(threads);
  return pipeline::render_frame(scene, pipeline::find_technique(technique), f, ex).display;
}

inline bool same_bytes(const ImageRGBA& a, const ImageRGBA& b) {
  return a.width == b.width && a.height == b.height &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])) == 0;
}

}  // namespace speculum::raster
