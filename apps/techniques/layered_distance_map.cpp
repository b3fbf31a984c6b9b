// The layered-distance-map technique's recipe (SURVEY §4.5): the envmap frame with one
// layered distance cube map of the whole scene and the recursive layered tracer as the
// specular layer.
#include <algorithm>
#include <vector>

#include "apps/techniques/distance_map.h"
#include "raster/layered_distance_map.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;

namespace {

LayeredMapOptions layered_map_options(const FrameSettings& f) {
  LayeredMapOptions o;
  o.layers = std::clamp(static_cast<int>(f.param("layers", 3)), 1, 8);
  o.size = std::clamp(static_cast<int>(f.param("layer_size", 128)), 8, 1024);
  return o;
}

LayeredTraceOptions layered_trace_options(const FrameSettings& f) {
  LayeredTraceOptions o;
  o.linear_steps = std::max(2, static_cast<int>(f.param("linear_steps", 16)));
  o.secant_steps = std::max(0, static_cast<int>(f.param("secant_steps", 4)));
  o.bounces = std::clamp(static_cast<int>(f.param("bounces", std::max(2, f.bounces))), 1, 16);
  return o;
}

// The reference point: halfway between the camera and the centre of the scene's bounds,
// so the layers see the scene from near the viewer's side (documented choice).
glm::vec3 layered_centre(const Scene& scene, const FrameSettings& f) {
  const Bounds b = scene.bounds();
  return 0.5f * (f.camera.eye + (b.valid() ? b.center() : f.camera.target));
}

}  // namespace

std::string describe_layered(const FrameSettings& f) {
  const LayeredMapOptions m = layered_map_options(f);
  const LayeredTraceOptions t = layered_trace_options(f);
  return "layers=" + std::to_string(m.layers) + " linear=" + std::to_string(t.linear_steps) +
         " secant=" + std::to_string(t.secant_steps) + " bounces=" + std::to_string(t.bounces);
}

void add_layered_distance_map_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_frame_passes(g, scene, f);
  const LayeredMapOptions mo = layered_map_options(f);
  const LayeredTraceOptions to = layered_trace_options(f);
  g.add("layered_distance_map", [scene, f, mo](par::NodeContext& c) {
     c.set_output("layered_map", render_layered_distance_map(
                                     c.executor(), *scene, layered_centre(*scene, f),
                                     c.input<ShadowMaps>("shadow_maps"),
                                     c.input<EnvironmentMap>("environment"), mo));
   }).reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment")
     .writes<LayeredDistanceMap>("layered_map").param("layers", mo.layers).param("size", mo.size)
     .describe("the whole scene depth-peeled into L cube layers (material, distance, normal, "
               "direct-lit colour) around one reference point (SURVEY §4.5)");

  g.add("layered_reflect", [to](par::NodeContext& c) {
     LayeredTraceStats st;
     c.set_output("specular", layered_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                              c.input<LayeredDistanceMap>("layered_map"),
                                              c.input<EnvironmentMap>("environment"), to, &st));
     c.count("searches", st.rays);
     c.count("distance_lookups", st.lookups);
     c.count("misses", st.misses);
   }).reads<GBuffer>("gbuffer").reads<LayeredDistanceMap>("layered_map")
     .reads<EnvironmentMap>("environment").writes<ImageRGBA>("specular")
     .param("linear_steps", to.linear_steps).param("secant_steps", to.secant_steps)
     .param("bounces", to.bounces)
     .describe("recursive tracer: linear + secant search in every layer, nearest hit, "
               "continued at specular hits up to the bounce limit (SURVEY §4.5)");
}

}  // namespace speculum::pipeline
