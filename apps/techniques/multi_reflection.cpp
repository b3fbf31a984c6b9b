// The multi-reflection technique's recipe (SURVEY §4.3): the distance-map frame with the
// reflector maps rebuilt in rounds; `--param lagged=1` instead does one round per frame
// from the previous frame's maps (an explicit cross-frame edge, graph.h reads_previous).
#include <algorithm>
#include <vector>

#include "apps/techniques/distance_map.h"
#include "raster/distance_map_reflect.h"
#include "raster/multi_reflection.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;

void add_multi_reflection_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_frame_passes(g, scene, f);
  const DistanceSearchOptions o = distance_search_options(f);
  const int rounds = std::max(1, static_cast<int>(f.param("rounds", 3)));
  const bool lagged = f.param("lagged", 0) != 0;
  auto node = g.add("multi_reflection_maps", [scene, f, o, rounds, lagged](par::NodeContext& c) {
    auto& maps = c.output<ReflectorMaps>("reflector_maps");
    DistanceReflectStats st;
    const auto& shadows = c.input<ShadowMaps>("shadow_maps");
    const auto& env = c.input<EnvironmentMap>("environment");
    if (lagged && c.has_input<ReflectorMaps>("reflector_maps@previous")) {
      // One round per frame on last frame's maps: bounce depth grows by one per frame.
      maps = rerender_reflector_maps(c.executor(), *scene, shadows, env,
                                     c.input<ReflectorMaps>("reflector_maps@previous"), o, &st);
    } else {
      maps = render_multi_reflection_maps(c.executor(), *scene, shadows, env, f.cube_map_size,
                                          &c.input<GBuffer>("gbuffer"), lagged ? 1 : rounds, o,
                                          &st);
    }
    c.count("cube_maps", maps.cubes.size());
    c.count("searches", st.searches);
    c.count("distance_lookups", st.lookups);
  });
  node.reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment").reads<GBuffer>("gbuffer")
      .writes<ReflectorMaps>("reflector_maps").param("size", f.cube_map_size)
      .param("rounds", lagged ? 1 : rounds).param("lagged", lagged ? 1 : 0)
      .describe("per specular object a colour + distance cube map, re-rendered in rounds with "
                "the others' current maps, one bounce per round (SURVEY §4.3)");
  if (lagged) node.reads_previous<ReflectorMaps>("reflector_maps");

  g.add("distance_map_reflect", [o](par::NodeContext& c) {
     DistanceReflectStats st;
     c.set_output("specular", distance_map_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                                   c.input<EnvironmentMap>("environment"),
                                                   c.input<ReflectorMaps>("reflector_maps"), o, &st));
     c.count("searches", st.searches);
     c.count("distance_lookups", st.lookups);
   }).reads<GBuffer>("gbuffer").reads<EnvironmentMap>("environment")
     .reads<ReflectorMaps>("reflector_maps").writes<ImageRGBA>("specular")
     .param("search", describe_search(o))
     .describe("distance-map search per specular sample in its reflector's map (SURVEY §4.1)");
}

}  // namespace speculum::pipeline
