// Distance impostors of refractors: see refraction_impostor.h.
#include "raster/refraction_impostor.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/shading.h"

namespace speculum::raster {

RefractorImpostors render_refractor_impostors(par::Executor& executor, const Scene& scene, int size, bool mirrors) {
  RefractorImpostors out;
  const std::vector<std::uint8_t> refractors = refractor_objects(scene);
  out.impostor_of_object.assign(scene.objects.size(), -1);
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    const bool mirror = mirrors && obj.material < scene.materials.size() &&
                        surface_params(scene.materials[obj.material]).is_mirror_lobe();
    if (!refractors[o] && !mirror) continue;
    Bounds box;
    for (std::size_t t = 0; t < scene.mesh.triangle_count(); ++t)
      if (scene.mesh.triangle_object[t] == o)
        for (int k = 0; k < 3; ++k) box.grow(scene.mesh.positions[scene.mesh.indices[3 * t + k]]);
    if (!box.valid()) continue;
    CubeMapOptions opt;
    opt.size = size;
    opt.set_depth_range(cube_depth_range(glm::length(box.extent())));
    opt.raster.excluded_objects.assign(scene.objects.size(), 1);
    opt.raster.excluded_objects[o] = 0;  // the refractor alone
    CubeMap cube = render_cube_map(executor, scene, box.center(), opt,
                                   [&](const GBuffer& g, const Camera&, int, const std::vector<std::uint8_t>*) {
      // The G-buffer normal of a refractor keeps its geometric (outward) orientation.
      ImageRGBA normals(g.width, g.height, glm::vec4(0.0f));
      executor.parallel_for("refraction_impostor.normals", normals.size(), 4096,
                            [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          if (g.covered(i)) normals.pixels[i] = glm::vec4(g.normal.pixels[i], 1.0f);
      });
      return normals;
    });
    out.impostor_of_object[o] = static_cast<int>(out.cubes.size());
    out.cubes.push_back(std::move(cube));
  }
  return out;
}

bool find_impostor_exit(const CubeMap& impostor, const glm::vec3& p1, const glm::vec3& t1,
                        const DistanceSearchOptions& options, glm::vec3& p2, glm::vec3& n2) {
  const DistanceSearchResult r = search_distance_map(impostor, p1, t1, options);
  if (!std::isfinite(r.d) || r.d <= 0.0f) return false;
  p2 = p1 + t1 * r.d;
  const glm::vec3 n(impostor.colour_towards(r.direction));
  const float len = glm::length(n);
  n2 = len > 0.0f ? n / len : glm::normalize(p2 - impostor.centre);
  return true;
}

RefractorImpostors RefractorImpostorsPass::operator()(par::NodeContext& c) const {
  RefractorImpostors impostors = render_refractor_impostors(c.executor(), *scene, size, mirrors);
  c.count("impostors", impostors.cubes.size());
  return impostors;
}

}  // namespace speculum::raster
