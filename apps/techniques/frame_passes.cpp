// The passes shared by every feed-forward technique's frame: see frame_passes.h.
#include "apps/techniques/frame_passes.h"

#include <vector>

#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;

namespace {
std::string or_default(const std::string& text, const char* fallback) {
  return text.empty() ? std::string(fallback) : text;
}
}  // namespace

void add_surface_passes(par::Graph& g, const Scene* scene, const FrameSettings& f,
                        const SurfacePassNotes& notes) {
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  g.add("environment", [scene, f](par::NodeContext& c) {
     c.set_output("environment", build_environment(c.executor(), scene->environment,
                                                   f.environment_size));
   }).writes<EnvironmentMap>("environment").param("size", f.environment_size)
     .describe("Resamples the scene environment into a mip-mapped cube map whose coarser levels are Phong-prefiltered for glossy lookups, plus 9 SH coefficients for ambient light (SURVEY §3.1).");

  g.add("shadow_map", [scene, f](par::NodeContext& c) {
     c.set_output("shadow_maps", render_shadow_maps(c.executor(), *scene, f.shadow_map_size));
   }).writes<ShadowMaps>("shadow_maps").param("size", f.shadow_map_size)
     .describe(or_default(notes.shadow_map, "One distance map per light (a cube around point and spot lights, one far face for a directional light), read by the 3×3 PCF shadow test of direct_light (SURVEY §4 distance maps)."));

  g.add("visibility", [scene, f, sw, sh](par::NodeContext& c) {
     c.set_output("visibility", render_visibility(c.executor(), *scene, f.camera, sw, sh));
   }).writes<VisibilityBuffer>("visibility").param("width", sw).param("height", sh)
     .describe(or_default(notes.visibility, "Rasterizes the triangle soup from the camera at k×k samples per pixel into triangle id, object id, view depth and barycentrics per sample (SOFF §3.1 primary visibility; setup → bin → rasterize)."));

  g.add("gbuffer", [scene, f](par::NodeContext& c) {
     c.set_output("gbuffer", resolve_gbuffer(c.executor(), *scene,
                                             c.input<VisibilityBuffer>("visibility"), f.camera.eye));
   }).reads<VisibilityBuffer>("visibility").writes<GBuffer>("gbuffer")
     .describe(or_default(notes.gbuffer, "Resolves the visibility buffer into world position, shading normal, uv and material parameters per sample: the G-buffer every reflection pass reads (SOFF §3.1)."));

  g.add("direct_light", [scene, f](par::NodeContext& c) {
     c.set_output("direct", direct_light(c.executor(), *scene, c.input<GBuffer>("gbuffer"),
                                         f.camera, c.input<ShadowMaps>("shadow_maps"),
                                         c.input<EnvironmentMap>("environment")));
   }).reads<GBuffer>("gbuffer").reads<ShadowMaps>("shadow_maps")
     .reads<EnvironmentMap>("environment").writes<ImageRGBA>("direct")
     .describe("Direct light from every scene light with shadow-map visibility, plus SH ambient from the environment, with the one shading model shared with the reference (SURVEY §3.1 diffuse part).");
}

void add_reflector_cube_maps_pass(par::Graph& g, const Scene* scene, const FrameSettings& f,
                                  const std::string& description) {
  g.add("reflector_cube_maps", [scene, f](par::NodeContext& c) {
     auto& maps = c.output<ReflectorMaps>("reflector_maps");
     maps = render_reflector_maps(c.executor(), *scene, c.input<ShadowMaps>("shadow_maps"),
                                  c.input<EnvironmentMap>("environment"), f.cube_map_size,
                                  &c.input<GBuffer>("gbuffer"));
     c.count("cube_maps", maps.cubes.size());
   }).reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment").reads<GBuffer>("gbuffer")
     .writes<ReflectorMaps>("reflector_maps").param("size", f.cube_map_size)
     .describe(description);
}

void add_output_passes(par::Graph& g, const FrameSettings& f, const std::string& specular) {
  g.add("composite", [specular](par::NodeContext& c) {
     c.set_output("samples", composite(c.executor(), c.input<ImageRGBA>("direct"),
                                       c.input<ImageRGBA>(specular)));
   }).reads<ImageRGBA>("direct").reads<ImageRGBA>(specular).writes<ImageRGBA>("samples")
     .describe("Adds direct and specular radiance per sample (SOFF §3.1: the lerp by specular level, as a sum in the shared shading model).");

  g.add("resolve", [f](par::NodeContext& c) {
     c.set_output(kRadiance, resolve_supersamples(c.executor(), c.input<ImageRGBA>("samples"),
                                                  f.supersample));
   }).reads<ImageRGBA>("samples").writes<ImageRGBA>(kRadiance).param("k", f.supersample)
     .describe("Box-filters the k×k supersamples of each pixel into its linear radiance (SOFF §3.1 supersampling).");

  g.add("tonemap", [f](par::NodeContext& c) {
     c.set_output(kDisplay, tonemap(c.executor(), c.input<ImageRGBA>(kRadiance), f.exposure));
   }).reads<ImageRGBA>(kRadiance).writes<ImageRGBA>(kDisplay).param("exposure", f.exposure)
     .describe("Exposure, then the ACES filmic curve: the display image a PNG stores (DESIGN.md, Data and formats; the same for every technique).");
}

}  // namespace speculum::pipeline
