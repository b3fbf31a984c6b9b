// The reference technique's recipe: the path-sampled reference tracer as one node, then the
// same tonemap as every other technique (so images compare like for like).
#include "apps/techniques/envmap.h"
#include "raster/composite.h"
#include "trace/reference_tracer.h"

namespace speculum::pipeline {

void add_reference_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  g.add("reference_trace", [scene, f](par::NodeContext& c) {
     trace::ReferenceOptions o;
     o.width = f.width;
     o.height = f.height;
     o.spp = f.spp;
     o.seed = f.seed;
     o.pixel_jitter = f.spp > 1;
     trace::ReferenceStats stats;
     c.set_output(kRadiance, trace::render_reference(*scene, f.camera, o, c.executor(), &stats));
     c.count("camera_rays", stats.camera_rays);
     c.count("shadow_rays", stats.shadow_rays);
     c.count("specular_rays", stats.specular_rays);
   }).writes<ImageRGBA>(kRadiance).param("spp", f.spp).param("seed", f.seed)
     .describe("Ground truth: ray tracing in the original geometry on the BVH, with camera, shadow and specular/glossy rays and spp jittered samples per pixel (SURVEY §2).");

  g.add("tonemap", [f](par::NodeContext& c) {
     c.set_output(kDisplay, raster::tonemap(c.executor(), c.input<ImageRGBA>(kRadiance), f.exposure));
   }).reads<ImageRGBA>(kRadiance).writes<ImageRGBA>(kDisplay).param("exposure", f.exposure)
     .describe("Exposure, then the ACES filmic curve: the display image a PNG stores (DESIGN.md, Data and formats; the same for every technique).");
}

}  // namespace speculum::pipeline
