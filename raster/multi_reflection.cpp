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
                                      DistanceReflectStats* stats) {
  ReflectorMaps next;
  next.map_of_object = current.map_of_object;
  next.centres = current.centres;
  const Bounds all = scene.bounds();
  const float scene_size = all.valid() ? glm::length(all.extent()) : 1.0f;
  for (std::size_t o = 0; o < current.map_of_object.size(); ++o) {
    const int m = current.map_of_object[o];
    if (m < 0) continue;
    // Same cube set-up as render_reflector_maps (reflector_maps.cpp).
    CubeMapOptions opt;
    opt.size = current.cubes[m].size;
    opt.znear = 1e-4f * scene_size;
    opt.zfar = 4.0f * scene_size;
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;
    next.cubes.push_back(render_cube_map(
        executor, scene, current.centres[m], opt, [&](const GBuffer& g, const Camera& cam) {
          return composite(executor, direct_light(executor, scene, g, cam, shadows, env),
                           distance_map_reflect(executor, g, env, current, options, stats));
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
  ReflectorMaps maps = render_reflector_maps(executor, scene, shadows, env, size, camera_view);
  for (int k = 1; k < rounds; ++k)
    maps = rerender_reflector_maps(executor, scene, shadows, env, maps, options, stats);
  return maps;
}

}  // namespace speculum::raster
