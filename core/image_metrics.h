// Image error metrics used by `compare`, the experiments and the technique-vs-reference
// tests. Every metric is computed on what a PNG stores: each RGB channel clamped to [0, 1],
// sRGB-encoded and rounded to 8 bits, so a metric of two in-memory display images equals
// the metric of the two PNG files written from them. Alpha is ignored.
#pragma once

#include <string>

#include "core/image.h"

namespace speculum {

struct ImageError {
  double mae8 = 0;   // mean absolute difference of the 8-bit values (0–255)
  double rmse = 0;   // root mean square difference of the 8-bit values / 255 (0–1)
  double psnr = 0;   // 20·log10(1 / rmse) in dB; kPsnrIdentical when rmse == 0
  double max8 = 0;   // largest absolute 8-bit difference
  std::size_t differing_pixels = 0;  // pixels where any RGB 8-bit value differs
};

// Identical images have no finite PSNR; report this cap instead so tables and JSON stay
// numeric.
inline constexpr double kPsnrIdentical = 100.0;

// `what` names the pair in the error thrown when the sizes differ (InputError).
ImageError image_error(const ImageRGBA& a, const ImageRGBA& b, const std::string& what = "images");

// The 8-bit value a display-space channel becomes in a PNG.
int display_to_8bit(float linear_display);

}  // namespace speculum
