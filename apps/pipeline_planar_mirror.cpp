// The planar-mirror technique's recipe: see pipeline_planar_mirror.h.
#include "apps/pipeline_planar_mirror.h"

#include <algorithm>
#include <vector>

#include "core/error.h"
#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/planar_mirror.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;
using PlanarMirrors = std::vector<PlanarMirror>;

void add_planar_mirror_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  const double depth_param = f.param("depth", 3.0);
  if (!(depth_param >= 0.0 && depth_param <= 16.0))
    throw InputError("--param depth", "planar-mirror depth must be in [0, 16]");
  const int depth = static_cast<int>(depth_param);

  g.add("environment", [scene, f](par::NodeContext& c) {
     c.set_output("environment", build_environment(c.executor(), scene->environment,
                                                   f.environment_size));
   }).writes<EnvironmentMap>("environment").param("size", f.environment_size)
     .describe("Mip-mapped, prefiltered environment cube (SURVEY §3.1).");

  g.add("shadow_map", [scene, f](par::NodeContext& c) {
     c.set_output("shadow_maps", render_shadow_maps(c.executor(), *scene, f.shadow_map_size));
   }).writes<ShadowMaps>("shadow_maps").param("size", f.shadow_map_size)
     .describe("Shadow maps of the punctual lights, shared by every mirrored view (SURVEY §5).");

  g.add("visibility", [scene, f, sw, sh](par::NodeContext& c) {
     c.set_output("visibility", render_visibility(c.executor(), *scene, f.camera, sw, sh));
   }).writes<VisibilityBuffer>("visibility").param("width", sw).param("height", sh)
     .describe("Camera visibility buffer; the mirror samples are the stencil of SURVEY §5.");

  g.add("gbuffer", [scene, f](par::NodeContext& c) {
     c.set_output("gbuffer", resolve_gbuffer(c.executor(), *scene,
                                             c.input<VisibilityBuffer>("visibility"), f.camera.eye));
   }).reads<VisibilityBuffer>("visibility").writes<GBuffer>("gbuffer")
     .describe("Camera G-buffer: positions, normals, materials, object ids.");

  g.add("planar_mirrors", [scene](par::NodeContext& c) {
     auto& mirrors = c.output<PlanarMirrors>("planar_mirrors");
     mirrors = find_planar_mirrors(*scene);
     c.count("mirrors", mirrors.size());
   }).writes<PlanarMirrors>("planar_mirrors")
     .describe("Planar mirror objects (coplanar within 1e-3 of their size) and the scene "
               "clipped to each side of each mirror plane (SURVEY §5).");

  g.add("direct_light", [scene, f](par::NodeContext& c) {
     c.set_output("direct", direct_light(c.executor(), *scene, c.input<GBuffer>("gbuffer"),
                                         f.camera, c.input<ShadowMaps>("shadow_maps"),
                                         c.input<EnvironmentMap>("environment")));
   }).reads<GBuffer>("gbuffer").reads<ShadowMaps>("shadow_maps")
     .reads<EnvironmentMap>("environment").writes<ImageRGBA>("direct")
     .describe("Direct light of the camera view (core/shading.h model, shadow maps).");

  g.add("planar_mirror_reflect", [scene, f, depth](par::NodeContext& c) {
     PlanarMirrorSettings settings;
     settings.depth = depth;
     PlanarMirrorStats stats;
     c.set_output("specular",
                  planar_mirror_reflect(c.executor(), *scene, c.input<PlanarMirrors>("planar_mirrors"),
                                        c.input<GBuffer>("gbuffer"), f.camera,
                                        c.input<ShadowMaps>("shadow_maps"),
                                        c.input<EnvironmentMap>("environment"), settings, &stats));
     c.count("mirrored_views", stats.mirrored_views);
     c.count("mirror_samples", stats.mirror_samples);
   }).reads<PlanarMirrors>("planar_mirrors").reads<GBuffer>("gbuffer")
     .reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment")
     .writes<ImageRGBA>("specular").param("depth", depth)
     .describe("Each planar mirror's samples get F × the view of the camera reflected about "
               "the mirror plane (scene clipped at the plane), recursively to depth k; other "
               "specular samples the environment map (SURVEY §5).");

  g.add("composite", [](par::NodeContext& c) {
     c.set_output("samples", composite(c.executor(), c.input<ImageRGBA>("direct"),
                                       c.input<ImageRGBA>("specular")));
   }).reads<ImageRGBA>("direct").reads<ImageRGBA>("specular").writes<ImageRGBA>("samples")
     .describe("Direct + specular layers.");

  g.add("resolve", [f](par::NodeContext& c) {
     c.set_output(kRadiance, resolve_supersamples(c.executor(), c.input<ImageRGBA>("samples"),
                                                  f.supersample));
   }).reads<ImageRGBA>("samples").writes<ImageRGBA>(kRadiance).param("k", f.supersample)
     .describe("Box-filter k×k supersamples to pixels.");

  g.add("tonemap", [f](par::NodeContext& c) {
     c.set_output(kDisplay, tonemap(c.executor(), c.input<ImageRGBA>(kRadiance), f.exposure));
   }).reads<ImageRGBA>(kRadiance).writes<ImageRGBA>(kDisplay).param("exposure", f.exposure)
     .describe("Exposure and sRGB encoding for display.");
}

}  // namespace speculum::pipeline
