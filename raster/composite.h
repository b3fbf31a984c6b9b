// The last passes of a feed-forward frame: `composite` (direct light + specular layer),
// the k×k supersample resolve and `tonemap` (SOFF §3.1's final blend and supersampling).
#pragma once

#include "core/image.h"
#include "parallel/executor.h"

namespace speculum::raster {

// SOFF §3.1 blends rgb = lerp(rgb_d, rgb_n, s). In the shared shading model the diffuse
// term already carries the (1 − F) weight and the specular layer the F weight, so the lerp
// is the sum of the two layers: composite = direct + specular.
ImageRGBA composite(par::Executor& executor, const ImageRGBA& direct, const ImageRGBA& specular);

// Box-filters k×k samples into one pixel (k = 1: a copy). Sizes must be multiples of k.
ImageRGBA resolve_supersamples(par::Executor& executor, const ImageRGBA& samples, int k);

// Exposure then the Narkowicz ACES fit per channel; alpha set to 1. Output is linear in
// [0, 1] (1 once exposure × value ≳ 7.24) — the PNG writer applies the sRGB curve.
ImageRGBA tonemap(par::Executor& executor, const ImageRGBA& hdr, float exposure = 1.0f);

}  // namespace speculum::raster
