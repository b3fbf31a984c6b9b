// The passes shared by every feed-forward technique's frame: see frame_passes.h.
#include "apps/techniques/frame_passes.h"

#include "raster/composite.h"
#include "raster/direct_light.h"

namespace speculum::pipeline {

using namespace speculum::raster;

namespace {
// Replaces a pass's own description when the technique has a note for it.
template <class T>
void note(par::PassBuilder<T>& pass, const std::string& text) {
  if (!text.empty()) pass.describe(text);
}
}  // namespace

SurfaceResources add_surface_passes(par::Graph& g, const Scene* scene, const FrameSettings& f,
                                    const SurfacePassNotes& notes) {
  SurfaceResources s;
  s.environment = g.add("environment", EnvironmentPass{scene, f.environment_size});
  auto shadow_maps = g.add("shadow_map", ShadowMapPass{scene, f.shadow_map_size});
  note(shadow_maps, notes.shadow_map);
  auto visibility = g.add("visibility", VisibilityPass{scene, f.camera, f.width * f.supersample,
                                                       f.height * f.supersample});
  note(visibility, notes.visibility);
  auto gbuffer = g.add("gbuffer", GBufferPass{scene, f.camera.eye}, visibility);
  note(gbuffer, notes.gbuffer);
  s.shadow_maps = shadow_maps;
  s.visibility = visibility;
  s.gbuffer = gbuffer;
  s.direct = g.add("direct_light", DirectLightPass{scene, f.camera}, s.gbuffer, s.shadow_maps,
                   s.environment);
  return s;
}

FrameOutputs add_output_passes(par::Graph& g, const FrameSettings& f,
                               const par::Resource<ImageRGBA>& direct,
                               const par::Resource<ImageRGBA>& specular) {
  auto samples = g.add("composite", CompositePass{}, direct, specular);
  FrameOutputs out;
  out.radiance = g.add("resolve", ResolvePass{f.supersample}, samples);
  out.display = g.add("tonemap", TonemapPass{f.exposure, f.auto_exposure}, out.radiance);
  return out;
}

}  // namespace speculum::pipeline
