// The distance-map technique's recipe and the frame passes it shares with envmap (the same
// nodes as apps/pipeline_envmap.cpp): see pipeline_distance_map.h.
#include "apps/pipeline_distance_map.h"

#include <vector>

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
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  g.add("environment", [scene, f](par::NodeContext& c) {
     c.set_output("environment", build_environment(c.executor(), scene->environment,
                                                   f.environment_size));
   }).writes<EnvironmentMap>("environment").param("size", f.environment_size)
     .describe("the scene's environment as a prefiltered cube (SURVEY §3.1)");

  g.add("shadow_map", [scene, f](par::NodeContext& c) {
     c.set_output("shadow_maps", render_shadow_maps(c.executor(), *scene, f.shadow_map_size));
   }).writes<ShadowMaps>("shadow_maps").param("size", f.shadow_map_size)
     .describe("one shadow map per light, for direct light in the frame and in the cube maps (SURVEY §4.2)");

  g.add("visibility", [scene, f, sw, sh](par::NodeContext& c) {
     c.set_output("visibility", render_visibility(c.executor(), *scene, f.camera, sw, sh));
   }).writes<VisibilityBuffer>("visibility").param("width", sw).param("height", sh)
     .describe("primary visibility by rasterization: non-specular objects rendered normally (SURVEY §4.2)");

  g.add("gbuffer", [scene, f](par::NodeContext& c) {
     c.set_output("gbuffer", resolve_gbuffer(c.executor(), *scene,
                                             c.input<VisibilityBuffer>("visibility"), f.camera.eye));
   }).reads<VisibilityBuffer>("visibility").writes<GBuffer>("gbuffer")
     .describe("surface attributes of the visible samples: position, normal, material (SURVEY §4.2)");

  g.add("direct_light", [scene, f](par::NodeContext& c) {
     c.set_output("direct", direct_light(c.executor(), *scene, c.input<GBuffer>("gbuffer"),
                                         f.camera, c.input<ShadowMaps>("shadow_maps"),
                                         c.input<EnvironmentMap>("environment")));
   }).reads<GBuffer>("gbuffer").reads<ShadowMaps>("shadow_maps")
     .reads<EnvironmentMap>("environment").writes<ImageRGBA>("direct")
     .describe("direct light + ambient of the visible samples (SURVEY §4.2)");

  g.add("composite", [](par::NodeContext& c) {
     c.set_output("samples", composite(c.executor(), c.input<ImageRGBA>("direct"),
                                       c.input<ImageRGBA>("specular")));
   }).reads<ImageRGBA>("direct").reads<ImageRGBA>("specular").writes<ImageRGBA>("samples")
     .describe("direct + Fresnel-weighted specular layer (SURVEY §4.2, eq.2)");

  g.add("resolve", [f](par::NodeContext& c) {
     c.set_output(kRadiance, resolve_supersamples(c.executor(), c.input<ImageRGBA>("samples"),
                                                  f.supersample));
   }).reads<ImageRGBA>("samples").writes<ImageRGBA>(kRadiance).param("k", f.supersample)
     .describe("k×k supersample box filter (SURVEY §4.2 frame)");

  g.add("tonemap", [f](par::NodeContext& c) {
     c.set_output(kDisplay, tonemap(c.executor(), c.input<ImageRGBA>(kRadiance), f.exposure));
   }).reads<ImageRGBA>(kRadiance).writes<ImageRGBA>(kDisplay).param("exposure", f.exposure)
     .describe("exposure + ACES fit, as for every technique (SURVEY §4.2 frame)");
}

void add_distance_map_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_frame_passes(g, scene, f);
  g.add("reflector_cube_maps", [scene, f](par::NodeContext& c) {
     auto& maps = c.output<ReflectorMaps>("reflector_maps");
     maps = render_reflector_maps(c.executor(), *scene, c.input<ShadowMaps>("shadow_maps"),
                                  c.input<EnvironmentMap>("environment"), f.cube_map_size,
                                  &c.input<GBuffer>("gbuffer"));
     c.count("cube_maps", maps.cubes.size());
   }).reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment").reads<GBuffer>("gbuffer")
     .writes<ReflectorMaps>("reflector_maps").param("size", f.cube_map_size)
     .describe("per reflector a colour + distance cube map at its reference point (SURVEY §4.2)");

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
