// The distance-map technique's recipe and the frame passes it shares with envmap (the same
// nodes as apps/techniques/envmap.cpp): see distance_map.h.
#include "apps/techniques/distance_map.h"

#include <vector>

#include "apps/techniques/frame_passes.h"
#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/distance_map_reflect.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;

DistanceSearchOptions distance_search_options(const FrameSettings& f) {
  DistanceSearchOptions o;
  o.parallax = f.param("parallax", 1) != 0;
  o.linear = f.param("linear", 1) != 0;
  o.secant = f.param("secant", 1) != 0;
  o.parallax_steps = static_cast<int>(f.param("parallax_steps", o.parallax_steps));
  o.linear_steps = static_cast<int>(f.param("linear_steps", o.linear_steps));
  o.secant_steps = static_cast<int>(f.param("secant_steps", o.secant_steps));
  return o;
}

std::string describe_search(const DistanceSearchOptions& o) {
  return "parallax=" + (o.parallax ? std::to_string(o.parallax_steps) : std::string("off")) +
         " linear=" + (o.linear ? std::to_string(o.linear_steps) : std::string("off")) +
         " secant=" + (o.secant ? std::to_string(o.secant_steps) : std::string("off"));
}

void add_frame_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_surface_passes(g, scene, f);
  add_output_passes(g, f);
}

void add_distance_map_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_frame_passes(g, scene, f);
  add_reflector_cube_maps_pass(g, scene, f, "per reflector a colour + distance cube map at its reference point (SURVEY §4.2)");

  const DistanceSearchOptions o = distance_search_options(f);
  g.add("distance_map_reflect", [o](par::NodeContext& c) {
     DistanceReflectStats st;
     c.set_output("specular", distance_map_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                                   c.input<EnvironmentMap>("environment"),
                                                   c.input<ReflectorMaps>("reflector_maps"), o, &st));
     c.count("searches", st.searches);
     c.count("distance_lookups", st.lookups);
     c.count("bracketed", st.bracketed);
   }).reads<GBuffer>("gbuffer").reads<EnvironmentMap>("environment")
     .reads<ReflectorMaps>("reflector_maps").writes<ImageRGBA>("specular")
     .param("search", describe_search(o))
     .describe("parallax (eq.4) / linear (§4.1.2) / secant (eq.5) search per specular sample, "
               "Fresnel-weighted (SURVEY §4.1)");
}

}  // namespace speculum::pipeline
