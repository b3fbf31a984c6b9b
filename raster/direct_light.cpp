// The `direct_light` node: see direct_light.h.
#include "raster/direct_light.h"

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/optics.h"

namespace speculum::raster {

glm::vec3 shade_surface(const Scene& scene, const SurfaceParams& s, const glm::vec3& p, glm::vec3 n,
                        const glm::vec3& v, const std::vector<ShadowMap>& shadows, const EnvironmentMap& env) {
  if (glm::dot(n, v) < 0.0f) n = -n;  // refractors seen from inside: light the near side
  glm::vec3 radiance = s.emissive;
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    const LightSample ls = sample_light(scene.lights[k], p);
    if (ls.irradiance == glm::vec3(0.0f) || glm::dot(n, ls.direction) <= 0.0f) continue;
    const float lit = k < shadows.size() ? shadows[k].visibility(p, n, ls.direction) : 1.0f;
    if (lit > 0.0f) radiance += lit * shade_light(s, n, v, ls);
  }
  radiance += diffuse_albedo_over_pi(s, glm::dot(n, v)) * env.irradiance(n);
  // The specular lobe of a surface too rough for a reflection pass (core/shading.h).
  if (s.has_rough_specular_lobe())
    radiance += specular_reflectance(s, glm::dot(n, v)) * env.radiance(reflect(-v, n), s.phong_exponent);
  return radiance;
}

ImageRGBA direct_light(par::Executor& executor, const Scene& scene, const GBuffer& g,
                       const Camera& camera, const std::vector<ShadowMap>& shadows,
                       const EnvironmentMap& env, const std::vector<std::uint8_t>* read) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  executor.parallel_for("direct_light.shade", out.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (read && !(*read)[i]) continue;
      if (!g.covered(i)) {
        const int x = static_cast<int>(i % g.width), y = static_cast<int>(i / g.width);
        const Ray ray = primary_ray(camera, g.width, g.height, x + 0.5f, y + 0.5f);
        out.pixels[i] = glm::vec4(env.radiance(ray.direction, 1e6f), 1.0f);
        continue;
      }
      out.pixels[i] = glm::vec4(shade_surface(scene, g.surface.pixels[i], g.position.pixels[i],
                                              g.normal.pixels[i], g.view_direction(i), shadows, env),
                                1.0f);
    }
  });
  return out;
}

ImageRGBA DirectLightPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                     const ShadowMaps& shadows,
                                     const EnvironmentMap& environment) const {
  return direct_light(c.executor(), *scene, gbuffer, camera, shadows, environment);
}

}  // namespace speculum::raster
