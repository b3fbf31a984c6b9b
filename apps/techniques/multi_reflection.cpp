// The multi-reflection technique's recipe (SURVEY §4.3): the distance-map frame with the
// reflector maps rebuilt in rounds; `--param lagged=1` instead does one round per frame from
// the previous frame's maps (a cross-frame edge: par::own_previous).
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/distance_map_reflect.h"
#include "raster/multi_reflection.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_multi_reflection_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  const DistanceSearchOptions search = distance_search_options(f);
  const bool lagged = f.param("lagged") != 0;
  const int rounds = static_cast<int>(f.param("rounds"));
  auto maps = g.add("multi_reflection_maps",
                    MultiReflectionMapsPass{scene, f.cube_map_size, rounds, lagged, search},
                    s.shadow_maps, s.environment, s.gbuffer, par::OwnPrevious{lagged});
  auto specular = g.add("distance_map_reflect", DistanceMapReflectPass{search}, s.gbuffer,
                        s.environment, maps);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
