// The envmap technique's recipe: see pipeline_envmap.h.
#include "apps/pipeline_envmap.h"

#include <vector>

#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/envmap_reflect.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;

void add_envmap_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  g.add("environment", [scene, f](par::NodeContext& c) {
     c.set_output("environment", build_environment(c.executor(), scene->environment,
                                                   f.environment_size));
   }).writes<EnvironmentMap>("environment").param("size", f.environment_size);

  g.add("shadow_map", [scene, f](par::NodeContext& c) {
     c.set_output("shadow_maps", render_shadow_maps(c.executor(), *scene, f.shadow_map_size));
   }).writes<ShadowMaps>("shadow_maps").param("size", f.shadow_map_size);

  g.add("visibility", [scene, f, sw, sh](par::NodeContext& c) {
     c.set_output("visibility", render_visibility(c.executor(), *scene, f.camera, sw, sh));
   }).writes<VisibilityBuffer>("visibility").param("width", sw).param("height", sh);

  g.add("gbuffer", [scene, f](par::NodeContext& c) {
     c.set_output("gbuffer", resolve_gbuffer(c.executor(), *scene,
                                             c.input<VisibilityBuffer>("visibility"), f.camera.eye));
   }).reads<VisibilityBuffer>("visibility").writes<GBuffer>("gbuffer");

  g.add("reflector_cube_maps", [scene, f](par::NodeContext& c) {
     auto& maps = c.output<ReflectorMaps>("reflector_maps");
     maps = render_reflector_maps(c.executor(), *scene, c.input<ShadowMaps>("shadow_maps"),
                                  c.input<EnvironmentMap>("environment"), f.cube_map_size,
                                  &c.input<GBuffer>("gbuffer"));
     c.count("cube_maps", maps.cubes.size());
   }).reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment").reads<GBuffer>("gbuffer")
     .writes<ReflectorMaps>("reflector_maps").param("size", f.cube_map_size);

  g.add("direct_light", [scene, f](par::NodeContext& c) {
     c.set_output("direct", direct_light(c.executor(), *scene, c.input<GBuffer>("gbuffer"),
                                         f.camera, c.input<ShadowMaps>("shadow_maps"),
                                         c.input<EnvironmentMap>("environment")));
   }).reads<GBuffer>("gbuffer").reads<ShadowMaps>("shadow_maps")
     .reads<EnvironmentMap>("environment").writes<ImageRGBA>("direct");

  g.add("envmap_reflect", [](par::NodeContext& c) {
     c.set_output("specular", envmap_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                             c.input<EnvironmentMap>("environment"),
                                             &c.input<ReflectorMaps>("reflector_maps")));
   }).reads<GBuffer>("gbuffer").reads<EnvironmentMap>("environment")
     .reads<ReflectorMaps>("reflector_maps").writes<ImageRGBA>("specular");

  g.add("composite", [](par::NodeContext& c) {
     c.set_output("samples", composite(c.executor(), c.input<ImageRGBA>("direct"),
                                       c.input<ImageRGBA>("specular")));
   }).reads<ImageRGBA>("direct").reads<ImageRGBA>("specular").writes<ImageRGBA>("samples");

  g.add("resolve", [f](par::NodeContext& c) {
     c.set_output(kRadiance, resolve_supersamples(c.executor(), c.input<ImageRGBA>("samples"),
                                                  f.supersample));
   }).reads<ImageRGBA>("samples").writes<ImageRGBA>(kRadiance).param("k", f.supersample);

  g.add("tonemap", [f](par::NodeContext& c) {
     c.set_output(kDisplay, tonemap(c.executor(), c.input<ImageRGBA>(kRadiance), f.exposure));
   }).reads<ImageRGBA>(kRadiance).writes<ImageRGBA>(kDisplay).param("exposure", f.exposure);
}

}  // namespace speculum::pipeline
