// The multi-reflection technique's recipe (SURVEY §4.3): the distance-map frame with the
// reflector maps rebuilt in rounds; `--param lagged=1` instead does one round per frame from
// the previous frame's maps (a cross-frame edge: par::own_previous).
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/distance_map_reflect.h"
#include "raster/multi_reflection.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_multi_reflection_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  const DistanceSearchOptions search = distance_search_options(f);
  const bool lagged = f.param("lagged") != 0;
  const int rounds = static_cast<int>(f.param("rounds"));
  if (lagged) {
    // One round per frame from the previous frame's maps: every map re-rendered whole.
    auto maps = g.add("multi_reflection_maps", MultiReflectionMapsPass{scene, f.cube_map_size, rounds, lagged, search},
                      s.shadow_maps, s.environment, s.gbuffer, par::OwnPrevious{lagged});
    auto specular = g.add("distance_map_reflect", DistanceMapReflectPass{search}, s.gbuffer, s.environment, maps);
    return add_output_passes(g, f, s.direct, specular);
  }
  // The maps' distances first; the camera's searches in them; the rounds, each shaded only
  // where the next round's searches (or the camera's) read it; the camera's reads.
  // Reflectors the camera does not see are seen in other maps: every one gets a map.
  auto distances = g.add("reflector_distance_maps",
                         ReflectorDistanceMapsPass{scene, f.cube_map_size, ReflectorSelection::all, searched_distance_maps(false, false)},
                         s.gbuffer);
  auto searches = g.add("distance_map_search", DistanceMapSearchPass{search}, s.gbuffer, distances);
  auto maps = g.add("multi_reflection_maps", MultiReflectionWhereReadPass{scene, rounds, search}, s.shadow_maps,
                    s.environment, distances, searches);
  auto specular = g.add("distance_map_reflect", DistanceMapLookupPass{search}, s.gbuffer, s.environment, maps, searches);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
