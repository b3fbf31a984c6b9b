// Dynamic environment maps per reflector: see reflector_maps.h.
#include "raster/reflector_maps.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/envmap_reflect.h"
#include "raster/planar_mirror.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {

namespace {

// Mean position and normal of object `object`'s samples, summed serially in sample order
// (a fixed-order reduction). False when the object covers no sample.
bool visible_centroid(const GBuffer& g, std::uint32_t object, glm::vec3& centre, glm::vec3& normal) {
  glm::dvec3 p(0.0), n(0.0);
  std::size_t count = 0;
  for (std::size_t i = 0; i < g.object.size(); ++i)
    if (g.object.pixels[i] == object) {
      p += glm::dvec3(g.position.pixels[i]);
      n += glm::dvec3(g.normal.pixels[i]);
      ++count;
    }
  if (count == 0) return false;
  centre = glm::vec3(p / double(count));
  const double nl = glm::length(n);
  normal = nl > 0.0 ? glm::vec3(n / nl) : glm::vec3(0.0f, 1.0f, 0.0f);
  return true;
}

// The smallest Phong exponent a reflection node reads an object's map with for this
// material: refractors read sharply (specular_radiance.h); a roughness texture can only
// scale roughness down (glTF), but be safe and keep every level then (exponent 0).
float map_lookup_exponent(const Material& material, const SurfaceParams& s) {
  if (s.is_refractor()) return kSharpLookupExponent;
  if (material.metallic_roughness_texture.valid()) return 0.0f;
  return s.phong_exponent;
}

}  // namespace

const char* to_string(ReflectorSelection which) {
  switch (which) {
    case ReflectorSelection::not_planar_mirrors: return "all but planar mirrors";
    case ReflectorSelection::refractors: return "refractors";
    default: return "all";
  }
}

ReflectorMaps render_reflector_maps(par::Executor& executor, const Scene& scene,
                                    const std::vector<ShadowMap>& shadows,
                                    const EnvironmentMap& env, int size,
                                    const GBuffer* camera_view, ReflectorSelection which,
                                    const FaceLight& add_light, const std::vector<std::uint8_t>* skip) {
  ReflectorMaps out;
  out.map_of_object.assign(scene.objects.size(), -1);
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  const TriangleMesh& m = scene.mesh;
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    if (skip && o < skip->size() && (*skip)[o]) continue;
    bool specular = false, refracts = false;
    float widest_lobe = 1e6f;  // smallest Phong exponent the map is read with
    Bounds b;
    for (std::uint32_t t = object.first_triangle; t < object.first_triangle + object.triangle_count;
         ++t) {
      const Material& material = scene.materials[m.triangle_material[t]];
      const SurfaceParams s = surface_params(material);
      if (is_specular(s)) {
        specular = true;
        refracts = refracts || s.is_refractor();
        widest_lobe = std::min(widest_lobe, map_lookup_exponent(material, s));
      }
      for (int k = 0; k < 3; ++k) b.grow(m.positions[m.indices[3 * t + k]]);
    }
    if (!specular || !b.valid()) continue;
    if (which == ReflectorSelection::not_planar_mirrors && planar_mirror_plane(scene, static_cast<std::uint32_t>(o)))
      continue;
    if (which == ReflectorSelection::refractors && !refracts) continue;
    glm::vec3 centre = b.center();
    const glm::vec3 e = b.extent();
    const float smallest = std::min({e.x, e.y, e.z}), largest = std::max({e.x, e.y, e.z});
    glm::vec3 seen, normal;
    if (camera_view && smallest < 0.05f * largest &&
        visible_centroid(*camera_view, static_cast<std::uint32_t>(o), seen, normal))
      centre = seen + normal * (0.01f * glm::length(e));
    CubeMapOptions opt;
    opt.size = size;
    opt.set_depth_range(depth_range);
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;  // a reflector does not see itself in its own map
    CubeMap cube = render_cube_map(
        executor, scene, centre, opt, [&](const GBuffer& g, const Camera& cam) {
          // Other reflectors seen in this map show the environment along their own R (and
          // T): the first-order fallback, so a mirror seen in a mirror is never black.
          ImageRGBA direct = direct_light(executor, scene, g, cam, shadows, env);
          if (add_light) direct = add_light(g, direct);
          return composite(executor, direct, envmap_reflect(executor, g, env));
        });
    out.map_of_object[o] = static_cast<int>(out.cubes.size());
    out.maps.push_back(environment_from_faces(executor, cube.colour, false,
                                              levels_for_lobes(size, widest_lobe)));
    out.cubes.push_back(std::move(cube));
    out.centres.push_back(centre);
  }
  return out;
}

ReflectorMaps ReflectorCubeMapsPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                const EnvironmentMap& environment,
                                                const GBuffer& gbuffer) const {
  ReflectorMaps maps = render_reflector_maps(c.executor(), *scene, shadows, environment, size, &gbuffer,
                                             which);
  c.count("cube_maps", maps.cubes.size());
  return maps;
}

}  // namespace speculum::raster
