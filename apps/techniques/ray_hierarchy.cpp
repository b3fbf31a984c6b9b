// The ray-hierarchy technique's recipe (ROGER §3.3): secondary rays from the G-buffer traced
// through a screen-space cone-sphere hierarchy over stream compaction, one generation per
// bounce; see recipes.h.
#include <algorithm>
#include <string>

#include "apps/techniques/frame_passes.h"
#include "apps/techniques/gbuffer_rays.h"
#include "apps/techniques/recipes.h"
#include "trace/ray_hierarchy_passes.h"

namespace speculum::pipeline {

FrameOutputs add_ray_hierarchy_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const int width = f.width * f.supersample, height = f.height * f.supersample;
  // Two generations by default: one reflects, and a refracted ray needs the second to leave
  // the glass it entered (with one, glass shows only its own back face).
  const int bounces = f.bounces > 0 ? f.bounces : 2;
  trace::HierarchyTraverseOptions traverse;
  traverse.pair_capacity = static_cast<std::size_t>(f.param("pair_capacity"));
  traverse.block_size = static_cast<std::size_t>(f.param("block"));

  SurfacePassNotes notes;
  notes.shadow_map = "Shadow maps of the punctual lights for the primary hits (ROGER §3.3.5 set-up).";
  notes.visibility = "Primary visibility by rasterization (ROGER §3.3.1: rays start from the G-buffer).";
  notes.gbuffer = "Positions, normals and materials of the visible samples (ROGER §3.3.1).";
  const SurfaceResources s = add_surface_passes(g, scene, f, notes);

  par::Resource<trace::SecondaryRays> rays = g.add("secondary_rays", SecondaryRaysPass{f.camera.eye}, s.gbuffer);
  par::Resource<ImageRGBA> specular;
  for (int b = 1; b <= bounces; ++b) {
    const std::string suffix = b == 1 ? "" : "_" + std::to_string(b);
    auto hierarchy = g.add("ray_hierarchy" + suffix, trace::RayHierarchyPass{width, height, b}, rays);
    auto hits = g.add("hierarchy_traverse" + suffix, trace::HierarchyTraversePass{scene, traverse},
                      rays, hierarchy);
    auto shadows = g.add("shadow_rays" + suffix, trace::ShadowRaysPass{scene, traverse, width, height},
                         rays, hits);
    specular = g.add("shade_hits" + suffix, trace::ShadeHitsPass{scene, width, height, b, b == bounces}, rays, hits,
                     shadows, specular);
    if (b < bounces)
      rays = g.add("bounce_rays_" + std::to_string(b + 1), trace::BounceRaysPass{scene, b + 1}, rays, hits);
  }
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
