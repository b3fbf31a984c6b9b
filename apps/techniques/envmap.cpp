// The envmap technique's recipe (SURVEY §3.1): see recipes.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/envmap_reflect.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_envmap_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  MapSizing sizing = camera_read_maps();
  sizing.refractors_read_at_surface = true;  // envmap_reflect reads every map, refractors' too
  auto maps = g.add("reflector_cube_maps", ReflectorCubeMapsPass{scene, f.cube_map_size, ReflectorSelection::all, sizing},
                    s.shadow_maps, s.environment, s.gbuffer)
                  .describe("For every specular object, renders the scene without it into a "
                            "colour + distance cube map around its reference point and "
                            "prefilters it: the dynamic environment maps of SURVEY §3.1.");
  auto specular = g.add("envmap_reflect", EnvmapReflectPass{}, s.gbuffer, s.environment, maps);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
