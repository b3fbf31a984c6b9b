// The refraction technique's recipe (SURVEY §4.4): the envmap frame, with refractor samples
// replaced by the refraction pass; the method's own passes feed it (two-face: back faces and
// per-vertex thickness; distance impostors: one cube per refractor).
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/envmap_reflect.h"
#include "raster/reflector_maps.h"
#include "raster/refraction.h"
#include "trace/refractor_thickness.h"

namespace speculum::pipeline {

using namespace speculum::raster;

namespace {

RefractionOptions refraction_options(const FrameSettings& f) {
  RefractionOptions options;
  options.method = static_cast<RefractionMethod>(static_cast<int>(f.param("method")));
  for (DistanceSearchOptions* o : {&options.environment_search, &options.exit_search}) {
    o->linear_steps = static_cast<int>(f.param("linear_steps"));
    o->linear = o->linear_steps >= 2;
    o->secant_steps = static_cast<int>(f.param("secant_steps"));
  }
  return options;
}

}  // namespace

FrameOutputs add_refraction_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const RefractionOptions options = refraction_options(f);
  SurfacePassNotes notes;
  notes.visibility = "Camera visibility buffer: the refractors' front faces (P1).";
  notes.gbuffer = "Camera G-buffer: front-face positions and normals N1 (SURVEY §4.4).";
  const SurfaceResources s = add_surface_passes(g, scene, f, notes);
  auto maps = g.add("reflector_cube_maps", ReflectorCubeMapsPass{scene, f.cube_map_size, ReflectorSelection::all, camera_read_maps()},
                    s.shadow_maps, s.environment, s.gbuffer)
                  .describe("Colour + distance cube map around each specular object, itself left "
                            "out: the environment distance map the refracted rays search "
                            "(SURVEY §4.1, §4.4).");
  auto reflected = g.add("envmap_reflect", EnvmapReflectPass{}, s.gbuffer, s.environment, maps)
                       .describe("Environment-mapped specular layer for the non-refracting "
                                 "reflectors (SURVEY §3.1).");
  par::Resource<GBuffer> back_faces;
  par::Resource<VertexThickness> thickness;
  par::Resource<RefractorImpostors> impostors;
  if (options.method == RefractionMethod::TwoFace) {
    back_faces = g.add("back_faces", RefractorBackFacesPass{scene, f.camera, f.width * f.supersample,
                                                            f.height * f.supersample});
    thickness = g.add("refractor_thickness", trace::RefractorThicknessPass{scene});
  } else if (options.method == RefractionMethod::DistanceImpostor) {
    impostors = g.add("refractor_impostors",
                      RefractorImpostorsPass{scene, static_cast<int>(f.param("impostor_size"))});
  }
  auto specular = g.add("refraction", RefractionPass{scene, f.camera, options}, s.gbuffer,
                        s.visibility, maps, s.environment, reflected, back_faces, thickness,
                        impostors);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
