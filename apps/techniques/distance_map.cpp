// The distance-map technique's recipe (SURVEY §4.1–4.2): see recipes.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/distance_map_reflect.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

using namespace speculum::raster;

DistanceSearchOptions distance_search_options(const FrameSettings& f) {
  DistanceSearchOptions o;
  o.parallax = f.param("parallax") != 0;
  o.linear = f.param("linear") != 0;
  o.secant = f.param("secant") != 0;
  o.parallax_steps = static_cast<int>(f.param("parallax_steps"));
  o.linear_steps = static_cast<int>(f.param("linear_steps"));
  o.secant_steps = static_cast<int>(f.param("secant_steps"));
  o.lobe_directions = static_cast<int>(f.param("lobe_directions"));
  return o;
}

FrameOutputs add_distance_map_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  const DistanceSearchOptions search = distance_search_options(f);
  // The maps' distances first; their colour only where the searches turn out to read it.
  auto distances = g.add("reflector_distance_maps",
                         ReflectorDistanceMapsPass{scene, f.cube_map_size, ReflectorSelection::all, searched_distance_maps(true, true)},
                         s.gbuffer);
  auto searches = g.add("distance_map_search", DistanceMapSearchPass{search}, s.gbuffer, distances);
  auto maps = g.add("reflector_cube_maps", ReflectorColourPass<DistanceSearches>{scene}, s.shadow_maps, s.environment, distances, searches);
  auto specular = g.add("distance_map_reflect", DistanceMapLookupPass{search}, s.gbuffer, s.environment, maps, searches);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
