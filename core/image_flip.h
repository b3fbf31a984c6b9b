// LDR-FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images",
// §4): per-pixel perceptual error in [0, 1] of two display images — CSF-filtered colour
// difference in YCxCz → Hunt-adjusted L*a*b* (HyAB), raised by edge and point feature
// differences of the luminance. `compare --metric flip` reports the mean.
#pragma once

#include "core/image.h"

namespace speculum {

struct FlipOptions {
  double pixels_per_degree = 67.0;  // the paper's default: 0.7 m from a 0.7 m wide 4K display
};

struct FlipResult {
  double mean = 0;  // the FLIP value of the pair
  double max = 0;
  ImageF error;     // per pixel, [0, 1]
};

// Display images (linear values; what a PNG stores after clamping to [0, 1]). Throws
// InputError naming `what` when the sizes differ.
FlipResult flip_error(const ImageRGBA& reference, const ImageRGBA& test,
                      const FlipOptions& options = {}, const std::string& what = "images");

}  // namespace speculum
