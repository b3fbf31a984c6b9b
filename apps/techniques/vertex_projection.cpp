// The vertex-projection technique's recipe (ROGER ch.2): see recipes.h and
// raster/vertex_projection.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/envmap_reflect.h"
#include "raster/vertex_projection.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_vertex_projection_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  auto geometry = g.add("tessellate", TessellatePass{scene, f.param("edge")});
  auto param = g.add("reflector_param", ReflectorParamPass{scene, int(f.param("param_size"))});
  // Specular samples the projection does not handle (glossy reflectors, reflectors that are
  // not star-shaped) keep the environment-map layer; only they get cube maps.
  MapSizing sizing = camera_read_maps();
  sizing.refractors_read_at_surface = true;  // only envmap_reflect reads them
  auto maps = g.add("reflector_cube_maps", FallbackCubeMapsPass{scene, f.cube_map_size, sizing}, param, s.shadow_maps,
                    s.environment, s.gbuffer);
  auto fallback = g.add("envmap_reflect", EnvmapReflectPass{}, s.gbuffer, s.environment, maps);
  FermatSettings fermat;
  fermat.max_iterations = int(f.param("max_iterations"));
  fermat.pixel_tolerance = f.param("pixel_tolerance");
  fermat.residual = f.param("residual");
  auto projected = g.add("vertex_project", VertexProjectPass{f.camera, fermat}, geometry, param, s.gbuffer);
  auto layer = g.add("reflected_triangles", ReflectedTrianglesPass{}, geometry, projected, param, s.gbuffer);
  auto specular = g.add("vertex_projection_shade", VertexProjectionShadePass{scene}, layer, geometry, param, s.gbuffer,
                        s.shadow_maps, s.environment, fallback);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
