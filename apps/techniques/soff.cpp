// The soff technique's recipe (SOFF §3.1): surface passes → soff_clusters (§3.2) →
// soff_cameras (§3.3) → soff_depth_images (step 3b) → soff_intersect (§3.4, §3.5) → output
// passes; see recipes.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/soff.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_soff_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  SurfacePassNotes notes;
  notes.gbuffer = "SOFF §3.1 step 1: per sample the diffuse inputs, specular level, glossiness, "
                  "normal, depth and reflector id that clustering and the blend read.";
  const SurfaceResources s = add_surface_passes(g, scene, f, notes);
  SoffBinSettings bins;
  bins.theta_bins = static_cast<int>(f.param("theta_bins"));
  bins.phi_bins = static_cast<int>(f.param("phi_bins"));
  bins.share_gain = static_cast<float>(f.param("share_gain"));
  auto clusters = g.add("soff_clusters", SoffClustersPass{bins}, s.gbuffer);
  SoffCameraSettings cam;
  cam.image_scale = static_cast<float>(f.param("image_scale"));
  cam.max_image_side = static_cast<int>(f.param("max_image_side"));
  cam.glossy_far = static_cast<float>(f.param("glossy_far"));
  auto cameras = g.add("soff_cameras", SoffCamerasPass{scene, cam}, s.gbuffer, clusters);
  auto images = g.add("soff_depth_images", SoffDepthImagesPass{scene}, clusters, cameras, s.shadow_maps,
                      s.environment);
  SoffIntersectSettings isect;
  isect.glossy_rays = static_cast<int>(f.param("glossy_rays"));
  isect.seed = f.seed;
  isect.glossy_fade = cam.glossy_far < 1.0f;
  isect.fill_disocclusions = f.param("fill") != 0.0;
  isect.reshade = f.param("reshade") != 0.0;
  isect.concave_self = f.param("concave") != 0.0;
  isect.camera = f.camera;
  auto specular = g.add("soff_intersect", SoffIntersectPass{scene, isect}, s.gbuffer, clusters, cameras, images,
                        s.shadow_maps, s.environment);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
