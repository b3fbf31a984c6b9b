// The last passes of a feed-forward frame: `composite` (direct light + specular layer),
// the k×k supersample resolve and `tonemap` (SOFF §3.1's final blend and supersampling).
#pragma once

#include "core/image.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"

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

// The automatic exposure of a frame: middle grey over the log-average luminance,
// 0.18 / exp(mean ln Y), Y = 0.2126 R + 0.7152 G + 0.0722 B (Reinhard et al. 2002,
// "Photographic Tone Reproduction for Digital Images", §2 eq. 1 with key a = 0.18). Pixels
// whose Y is not finite or not positive (background against a black environment, NaNs) are
// left out: they would drag the mean to −∞. 1 when no pixel counts. The sum runs in double
// over fixed chunks combined in chunk order, so the value does not depend on the threads.
float meter_exposure(par::Executor& executor, const ImageRGBA& radiance);

// Pass "composite": direct + specular radiance per sample.
struct CompositePass {
  static constexpr const char* description =
      "Adds direct and specular radiance per sample (SOFF §3.1: the lerp by specular level, as "
      "a sum in the shared shading model).";
  ImageRGBA operator()(par::NodeContext& c, const ImageRGBA& direct, const ImageRGBA& specular) const {
    return composite(c.executor(), direct, specular);
  }
};

// Pass "resolve": k×k supersamples → one linear radiance value per pixel.
struct ResolvePass {
  static constexpr const char* description =
      "Box-filters the k×k supersamples of each pixel into its linear radiance (SOFF §3.1 supersampling).";
  int k = 1;
  void parameters(par::Params& p) const { p.set("k", k); }
  ImageRGBA operator()(par::NodeContext& c, const ImageRGBA& samples) const {
    return resolve_supersamples(c.executor(), samples, k);
  }
};

// Pass "tonemap": the display image every technique ends with. With `automatic` the
// exposure is meter_exposure of the radiance, recorded as the counter "exposure" (the
// value itself: it is added once).
struct TonemapPass {
  static constexpr const char* description =
      "Exposure, then the ACES filmic curve: the display image a PNG stores (the same for every "
      "technique, so images compare like for like).";
  float exposure = 1.0f;
  bool automatic = false;
  void parameters(par::Params& p) const {
    if (automatic) p.set("exposure", "auto");
    else p.set("exposure", exposure);
  }
  ImageRGBA operator()(par::NodeContext& c, const ImageRGBA& radiance) const {
    const float e = automatic ? meter_exposure(c.executor(), radiance) : exposure;
    if (automatic) c.count("exposure", e);
    return tonemap(c.executor(), radiance, e);
  }
};

}  // namespace speculum::raster
