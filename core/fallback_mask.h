// Per pixel, the fallback a technique took where it could not follow a ray: what `inspect`
// draws as a technique's fallback mask, beside the fallback_* counters that total it.
#pragma once

#include <cstdint>

#include "core/image.h"

namespace speculum {

enum class Fallback : std::uint8_t {
  none = 0,
  search_missed,          // a map search found no stored surface: read along the ray
  depth_exhausted,        // a specular continuation past the depth limit: the environment
  refractor_environment,  // a refractor the technique does not trace: its own map or the environment
};

struct FallbackMask {
  Buffer2D<std::uint8_t> reason;  // a Fallback per pixel

  FallbackMask() = default;
  FallbackMask(int width, int height) : reason(width, height, 0) {}
  bool empty() const { return reason.empty(); }
  // Marks pixel i with `why` (a pixel keeps the first reason it got).
  void mark(std::size_t i, Fallback why) {
    if (!reason.empty() && reason.pixels[i] == 0) reason.pixels[i] = static_cast<std::uint8_t>(why);
  }
  std::size_t count(Fallback why) const {
    std::size_t n = 0;
    for (std::uint8_t r : reason.pixels) n += r == static_cast<std::uint8_t>(why);
    return n;
  }
};

}  // namespace speculum
