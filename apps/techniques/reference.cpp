// The reference technique's recipe: the path-sampled reference tracer as one pass, then the
// same tonemap as every other technique (so images compare like for like).
#include <algorithm>

#include "apps/techniques/recipes.h"
#include "raster/composite.h"
#include "trace/reference_tracer.h"

namespace speculum::pipeline {

FrameOutputs add_reference_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  trace::ReferenceOptions o;
  o.width = f.width;
  o.height = f.height;
  o.spp = f.spp;
  if (f.bounces > 0) o.max_depth = f.bounces;  // 0: the tracer's own default depth
  o.seed = f.seed;
  o.pixel_jitter = f.spp > 1;
  // Photons per pixel of the frame, per light and caustic generator, so the caustics' noise
  // does not depend on the image size.
  o.caustic_photons = static_cast<std::uint64_t>(f.param("caustic_photons")) * static_cast<std::uint64_t>(f.width) *
                      static_cast<std::uint64_t>(f.height);
  o.caustic_photons = std::min<std::uint64_t>(o.caustic_photons, std::uint64_t{1} << 32);
  FrameOutputs out;
  out.radiance = g.add("reference_trace", trace::ReferencePass{scene, f.camera, o});
  out.display = g.add("tonemap", raster::TonemapPass{f.exposure, f.auto_exposure}, out.radiance);
  return out;
}

}  // namespace speculum::pipeline
