// The layered-distance-map technique's recipe (SURVEY §4.5): the envmap frame with one
// layered distance cube map of the whole scene and the recursive layered tracer as the
// specular layer.
#include <algorithm>

#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/layered_distance_map.h"

namespace speculum::pipeline {

using namespace speculum::raster;

namespace {

LayeredMapOptions layered_map_options(const FrameSettings& f) {
  LayeredMapOptions o;
  o.layers = static_cast<int>(f.param("layers"));
  o.size = static_cast<int>(f.param("layer_size"));
  return o;
}

// `--bounces B` raises the bounce limit to B.
LayeredTraceOptions layered_trace_options(const FrameSettings& f) {
  LayeredTraceOptions o;
  o.linear_steps = static_cast<int>(f.param("linear_steps"));
  o.secant_steps = static_cast<int>(f.param("secant_steps"));
  o.bounces = std::max(static_cast<int>(f.param("bounces")), f.bounces);
  return o;
}

// The reference point: halfway between the camera and the centre of the scene's bounds,
// so the layers see the scene from near the viewer's side.
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

FrameOutputs add_layered_distance_map_passes(par::Graph& g, const Scene* scene,
                                             const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  auto map = g.add("layered_distance_map",
                   LayeredDistanceMapPass{scene, layered_centre(*scene, f), layered_map_options(f)},
                   s.shadow_maps, s.environment);
  auto specular = g.add("layered_reflect", LayeredReflectPass{layered_trace_options(f)}, s.gbuffer,
                        map, s.environment);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
