// The envmap technique's recipe: see envmap.h.
#include "apps/techniques/envmap.h"

#include "apps/techniques/frame_passes.h"
#include "raster/envmap_reflect.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

using namespace speculum::raster;

void add_envmap_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_surface_passes(g, scene, f);
  add_reflector_cube_maps_pass(
      g, scene, f,
      "For every specular object, renders the scene without it into a colour + distance cube "
      "map around its reference point and prefilters it: the dynamic environment maps of "
      "SURVEY §3.1.");
  g.add("envmap_reflect", [](par::NodeContext& c) {
     c.set_output("specular", envmap_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                             c.input<EnvironmentMap>("environment"),
                                             &c.input<ReflectorMaps>("reflector_maps")));
   }).reads<GBuffer>("gbuffer").reads<EnvironmentMap>("environment")
     .reads<ReflectorMaps>("reflector_maps").writes<ImageRGBA>("specular")
     .describe("Looks up the reflected (or refracted) direction in the reflector's own cube map, or the environment, weighted by Schlick Fresnel; no parallax, exact only for a distant environment (SURVEY §3.1, eq.2).");

  add_output_passes(g, f);
}

}  // namespace speculum::pipeline
