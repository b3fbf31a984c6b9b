// The cone-tracing technique's recipe (ROGER ch.5, §5.2): one cone per specular pixel from
// the pixel's footprint, the surface's mean curvature and the material's gloss, traced
// through the ray hierarchy with cone leaves; the n nearest triangles per pixel blended front
// to back by their exact coverage; see recipes.h.
#include <algorithm>
#include <cmath>
#include <string>

#include "apps/techniques/frame_passes.h"
#include "apps/techniques/gbuffer_rays.h"
#include "apps/techniques/recipes.h"
#include "raster/pixel_curvature.h"
#include "trace/cone_tracing_passes.h"
#include "trace/ray_hierarchy_passes.h"

namespace speculum::pipeline {

FrameOutputs add_cone_tracing_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  // As ray-hierarchy: the second generation lets refracted rays leave the glass.
  const int bounces = f.bounces > 0 ? f.bounces : 2;
  trace::HierarchyTraverseOptions traverse;
  traverse.pair_capacity = static_cast<std::size_t>(f.param("pair_capacity"));
  traverse.block_size = static_cast<std::size_t>(f.param("block"));
  trace::PixelConeOptions cone;
  cone.footprint = float(f.param("footprint"));
  cone.gloss_angle = float(f.param("gloss_angle"));
  cone.lobe_energy = float(f.param("lobe_energy"));
  cone.far_blur = float(f.param("far_blur"));
  const Bounds bounds = scene->bounds();
  cone.scene_radius = bounds.valid() ? std::max(0.5f * glm::length(bounds.extent()), 1e-6f) : 1.0f;
  const int kept = int(f.param("kept"));

  SurfacePassNotes notes;
  notes.visibility = "Primary visibility by rasterization (ROGER §5.2.2: cones start from the G-buffer).";
  notes.gbuffer = "Positions, normals and materials of the visible samples (ROGER §5.2.2).";
  const SurfaceResources s = add_surface_passes(g, scene, f, notes);

  auto curvature = g.add("pixel_curvature", raster::PixelCurvaturePass{scene, f.camera.eye}, s.visibility);
  auto cones = g.add("pixel_cones", PixelConesPass{f.camera, cone}, s.gbuffer, s.visibility, curvature);
  auto hierarchy = g.add("cone_hierarchy", trace::ConeHierarchyPass{}, cones);
  auto hits = g.add("cone_triangle_coverage", trace::ConeTriangleCoveragePass{scene, kept, traverse}, cones,
                    hierarchy);
  par::Resource<trace::SecondaryRays> rays = g.add("cone_blend", trace::ConeBlendPass{scene}, cones, hits);
  par::Resource<trace::HitStream> layer_hits = g.add("cone_layer_hits", trace::ConeLayerHitsPass{scene}, cones, hits);
  // The first generation on the layer grid: shadowed and shaded by the ray hierarchy's
  // passes, then gathered per pixel; later generations continue from each pixel's nearest
  // layer on the pixel grid, exactly as ray-hierarchy's.
  auto shadows = g.add("shadow_rays", trace::ConeShadowRaysPass{scene, traverse}, rays, layer_hits, hits);
  auto layers = g.add("shade_hits", trace::ShadeHitsPass{scene, 0, 0, 1, bounces == 1}, rays, layer_hits, shadows,
                      par::Resource<ImageRGBA>{});
  par::Resource<ImageRGBA> specular =
      g.add("cone_gather", trace::ConeGatherPass{scene, f.param("fill") != 0.0}, cones, hits, layers);
  if (bounces > 1) {
    rays = g.add("bounce_rays_2", trace::ConeBounceRaysPass{scene}, rays, layer_hits, hits);
    for (int b = 2; b <= bounces; ++b) {
      const std::string suffix = "_" + std::to_string(b);
      auto hierarchy_b = g.add("ray_hierarchy" + suffix, trace::RayHierarchyPass{0, 0, b}, rays);
      auto hits_b = g.add("hierarchy_traverse" + suffix, trace::HierarchyTraversePass{scene, traverse}, rays,
                          hierarchy_b);
      auto shadows_b = g.add("shadow_rays" + suffix, trace::ShadowRaysPass{scene, traverse, 0, 0}, rays, hits_b);
      specular = g.add("shade_hits" + suffix, trace::ShadeHitsPass{scene, 0, 0, b, b == bounces}, rays, hits_b,
                       shadows_b, specular);
      if (b < bounces)
        rays = g.add("bounce_rays_" + std::to_string(b + 1), trace::BounceRaysPass{scene, b + 1}, rays, hits_b);
    }
  }
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
