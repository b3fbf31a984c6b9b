// The yu-lod technique's recipe (YU §3.5): raster passes for primary visibility and direct
// light, trace/ passes for the glossy layer; see recipes.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/gbuffer_rays.h"
#include "apps/techniques/recipes.h"
#include "raster/composite.h"
#include "raster/envmap_reflect.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

FrameOutputs add_yu_lod_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  return add_yu_lod_passes_cached(g, scene, f, nullptr);
}

FrameOutputs add_yu_lod_passes_cached(par::Graph& g, const Scene* scene, const FrameSettings& f,
                                      std::shared_ptr<trace::LodStaticData> cache) {
  // One sample per pixel: N is the number of glossy rays, not supersamples.
  FrameSettings one = f;
  one.supersample = 1;
  SurfacePassNotes notes;
  notes.shadow_map = "Shadow maps of the punctual lights (direct light of primary hits).";
  notes.visibility = "Primary visibility by rasterization (YU §3.5 step 1).";
  notes.gbuffer = "Positions, normals and materials of the visible samples (YU §3.5).";
  const SurfaceResources s = add_surface_passes(g, scene, one, notes);

  trace::RadianceBakeOptions bake;
  bake.environment_samples = static_cast<int>(f.param("env_samples"));
  bake.seed = f.seed;
  auto bvh = g.add("bvh_build", trace::BvhBuildPass{scene, cache});
  auto lighting = g.add("radiance_bake", trace::RadianceBakePass{scene, bake, cache}, bvh);
  auto lod = g.add("lod_build", trace::LodBuildPass{cache}, bvh, lighting);

  trace::GlossyRayOptions rays_options;
  rays_options.rays_per_pixel = f.spp;
  rays_options.seed = f.seed;
  auto rays = g.add("glossy_rays", GlossyRaysPass{rays_options}, s.gbuffer);
  trace::LodOptions lod_options;
  lod_options.enabled = f.alpha > 0.0f;
  lod_options.alpha = f.alpha;
  auto hits = g.add("lod_trace", trace::LodTracePass{lod_options}, bvh, lod, rays);
  auto specular = g.add("hit_radiance", trace::HitRadiancePass{scene}, lod, lighting, rays, hits);
  // YU traces reflections only; refractors fall back to cube maps of their own, which see the
  // room around them (SURVEY §3.1), so glass is never black.
  auto refractor_maps = g.add("refractor_cube_maps",
                              raster::ReflectorCubeMapsPass{scene, f.cube_map_size, raster::ReflectorSelection::refractors, raster::MapSizing{}},
                              s.shadow_maps, s.environment, s.gbuffer);
  auto refractors = g.add("refractor_environment", raster::RefractorEnvironmentPass{}, s.gbuffer, s.environment,
                          refractor_maps);
  auto direct = g.add("direct_and_refractors", raster::CompositePass{}, s.direct, refractors);
  return add_output_passes(g, one, direct, specular);
}

}  // namespace speculum::pipeline
