// Image error metrics: see image_metrics.h.
#include "core/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "core/error.h"

namespace speculum {

int display_to_8bit(float v) {
  if (!(v > 0.0f)) return 0;  // also NaN → 0, as the PNG writer clamps
  if (v >= 1.0f) return 255;
  return static_cast<int>(std::lround(linear_to_srgb(v) * 255.0f));
}

ImageError image_error(const ImageRGBA& a, const ImageRGBA& b, const std::string& what) {
  if (a.width != b.width || a.height != b.height)
    throw InputError(what, "sizes differ: " + std::to_string(a.width) + "x" +
                               std::to_string(a.height) + " vs " + std::to_string(b.width) +
                               "x" + std::to_string(b.height));
  ImageError e;
  if (a.empty()) return e;
  // Integer sums: the result does not depend on summation order.
  std::uint64_t abs_sum = 0, sq_sum = 0;
  int max8 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    bool differs = false;
    for (int c = 0; c < 3; ++c) {
      const int d = std::abs(display_to_8bit(a.pixels[i][c]) - display_to_8bit(b.pixels[i][c]));
      abs_sum += static_cast<std::uint64_t>(d);
      sq_sum += static_cast<std::uint64_t>(d * d);
      max8 = std::max(max8, d);
      differs = differs || d != 0;
    }
    e.differing_pixels += differs ? 1 : 0;
  }
  const double n = 3.0 * static_cast<double>(a.size());
  e.mae8 = static_cast<double>(abs_sum) / n;
  e.rmse = std::sqrt(static_cast<double>(sq_sum) / n) / 255.0;
  e.psnr = e.rmse > 0 ? std::min(kPsnrIdentical, 20.0 * std::log10(1.0 / e.rmse)) : kPsnrIdentical;
  e.max8 = max8;
  return e;
}

}  // namespace speculum
