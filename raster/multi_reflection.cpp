// Inter-object multiple reflections by rounds of cube-map re-rendering: see multi_reflection.h.
#include "raster/multi_reflection.h"

#include <glm/geometric.hpp>

#include "raster/composite.h"
#include "raster/direct_light.h"

namespace speculum::raster {

ReflectorMaps rerender_reflector_maps(par::Executor& executor, const Scene& scene,
                                      const std::vector<ShadowMap>& shadows,
                                      const EnvironmentMap& env, const ReflectorMaps& current,
                                      const DistanceSearchOptions& options,
                                      DistanceReflectStats* stats,
                                      const std::vector<MapFaceLayers>* layers) {
  ReflectorMaps next;
  next.map_of_object = current.map_of_object;
  next.centres = current.centres;
  next.faces = current.faces;
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  // Reflectors seen in a cube face are a few texels wide: one search along each lobe's axis.
  DistanceSearchOptions face_search = options;
  face_search.lobe_directions = 1;
  for (std::size_t o = 0; o < current.map_of_object.size(); ++o) {
    const int m = current.map_of_object[o];
    if (m < 0) continue;
    if (layers && static_cast<std::size_t>(m) < layers->size()) {
      const MapFaceLayers& kept = (*layers)[m];
      const CubeMap& was = current.cubes[m];
      CubeMap cube;
      cube.size = was.size;
      cube.centre = was.centre;
      cube.distance = was.distance;
      for (int f = 0; f < kCubeFaces; ++f) {
        ImageRGBA specular(was.size, was.size, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        if (kept.direct[f].size() == 0) {  // a face render_cube_map left out: black
          cube.colour[f] = std::move(specular);
          continue;
        }
        const ImageRGBA seen = distance_map_reflect(executor, kept.specular[f], env, current, face_search, stats);
        for (std::size_t k = 0; k < kept.specular_texel[f].size(); ++k)
          specular.pixels[kept.specular_texel[f][k]] = seen.pixels[k];
        cube.colour[f] = composite(executor, kept.direct[f], specular);
      }
      next.cubes.push_back(std::move(cube));
      continue;
    }
    // Same cube set-up as render_reflector_maps (reflector_maps.cpp).
    CubeMapOptions opt;
    opt.size = current.cubes[m].size;
    opt.set_depth_range(depth_range);
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;
    next.cubes.push_back(render_cube_map(
        executor, scene, current.centres[m], opt, [&](const GBuffer& g, const Camera& cam, int, const std::vector<std::uint8_t>*) {
          return composite(executor, direct_light(executor, scene, g, cam, shadows, env),
                           distance_map_reflect(executor, g, env, current, face_search, stats));
        }));
  }
  // map_of_object numbers maps in object order, as render_reflector_maps does.
  // Each map keeps the levels its reflector's materials read (render_reflector_maps).
  for (std::size_t k = 0; k < next.cubes.size(); ++k)
    next.maps.push_back(environment_from_faces(
        executor, next.cubes[k].colour, false, static_cast<int>(current.maps[k].levels.size())));
  return next;
}

ReflectorMaps render_multi_reflection_maps(par::Executor& executor, const Scene& scene,
                                           const std::vector<ShadowMap>& shadows,
                                           const EnvironmentMap& env, int size,
                                           const GBuffer* camera_view, int rounds,
                                           const DistanceSearchOptions& options,
                                           DistanceReflectStats* stats) {
  std::vector<MapFaceLayers> layers;
  ReflectorMaps maps = render_reflector_maps(executor, scene, shadows, env, size, camera_view, ReflectorSelection::all,
                                             {}, nullptr, {}, rounds > 1 ? &layers : nullptr);
  for (int k = 1; k < rounds; ++k)
    maps = rerender_reflector_maps(executor, scene, shadows, env, maps, options, stats, &layers);
  return maps;
}

ReflectorMaps MultiReflectionMapsPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                  const EnvironmentMap& environment,
                                                  const GBuffer& gbuffer,
                                                  const ReflectorMaps* previous) const {
  DistanceReflectStats st;
  ReflectorMaps maps =
      lagged && previous
          ? rerender_reflector_maps(c.executor(), *scene, shadows, environment, *previous, search, &st)
          : render_multi_reflection_maps(c.executor(), *scene, shadows, environment, size, &gbuffer,
                                         lagged ? 1 : rounds, search, &st);
  c.count("cube_maps", maps.cubes.size());
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("fallback_search_missed", st.missed);
  return maps;
}

}  // namespace speculum::raster
