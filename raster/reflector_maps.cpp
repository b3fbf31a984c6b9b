// Dynamic environment maps per reflector: see reflector_maps.h.
#include "raster/reflector_maps.h"

#include <glm/geometric.hpp>

#include "raster/direct_light.h"

namespace speculum::raster {

ReflectorMaps render_reflector_maps(par::Executor& executor, const Scene& scene,
                                    const std::vector<ShadowMap>& shadows,
                                    const EnvironmentMap& env, int size) {
  ReflectorMaps out;
  out.map_of_object.assign(scene.objects.size(), -1);
  const Bounds all = scene.bounds();
  const float scene_size = all.valid() ? glm::length(all.extent()) : 1.0f;
  const TriangleMesh& m = scene.mesh;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    bool specular = false;
    Bounds b;
    for (std::uint32_t t = object.first_triangle; t < object.first_triangle + object.triangle_count;
         ++t) {
      specular |= is_specular(surface_params(scene.materials[m.triangle_material[t]]));
      for (int k = 0; k < 3; ++k) b.grow(m.positions[m.indices[3 * t + k]]);
    }
    if (!specular || !b.valid()) continue;
    CubeMapOptions opt;
    opt.size = size;
    opt.znear = 1e-4f * scene_size;
    opt.zfar = 4.0f * scene_size;
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;  // a reflector does not see itself in its own map
    CubeMap cube = render_cube_map(
        executor, scene, b.center(), opt, [&](const GBuffer& g, const Camera& cam) {
          return direct_light(executor, scene, g, cam, shadows, env);
        });
    out.map_of_object[o] = static_cast<int>(out.cubes.size());
    out.maps.push_back(environment_from_faces(executor, cube.colour, false));
    out.cubes.push_back(std::move(cube));
  }
  return out;
}

}  // namespace speculum::raster
