// The `direct_light` node: see direct_light.h.
#include "raster/direct_light.h"

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/optics.h"

namespace speculum::raster {

namespace {

// shade_surface with light k sampled at p by sample(k, p) (sample_light's bits).
template <class SampleLight>
glm::vec3 shade_point(const Scene& scene, const SampleLight& sample, const SurfaceParams& s, const glm::vec3& p,
                      glm::vec3 n, const glm::vec3& v, const std::vector<ShadowMap>& shadows,
                      const EnvironmentMap& env) {
  if (glm::dot(n, v) < 0.0f) n = -n;  // refractors seen from inside: light the near side
  glm::vec3 radiance = s.emissive;
  const BrdfAtView view = brdf_at_view(brdf_params_for_punctual_light(s), n, v);
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    const LightSample ls = sample(k, p);
    if (ls.irradiance == glm::vec3(0.0f) || glm::dot(n, ls.direction) <= 0.0f) continue;
    const float lit = k < shadows.size() ? shadows[k].visibility(p, n, ls.direction) : 1.0f;
    if (lit > 0.0f) radiance += lit * shade_light(s, view, n, v, ls);
  }
  radiance += diffuse_albedo_over_pi(s, view) * env.irradiance(n);
  // The specular lobe of a surface too rough for a reflection pass (core/shading.h).
  if (s.has_rough_specular_lobe())
    radiance += specular_reflectance(s, glm::dot(n, v)) * env.radiance(reflect(-v, n), s.phong_exponent);
  return radiance;
}

}  // namespace

glm::vec3 shade_surface(const Scene& scene, const SurfaceParams& s, const glm::vec3& p, glm::vec3 n,
                        const glm::vec3& v, const std::vector<ShadowMap>& shadows, const EnvironmentMap& env) {
  const auto sample = [&](std::size_t k, const glm::vec3& at) { return sample_light(scene.lights[k], at); };
  return shade_point(scene, sample, s, p, n, v, shadows, env);
}

SurfaceShader::SurfaceShader(const Scene& scene, const std::vector<ShadowMap>& shadows, const EnvironmentMap& env)
    : scene_(&scene), shadows_(&shadows), env_(&env) {
  lights_.reserve(scene.lights.size());
  for (const Light& light : scene.lights) lights_.emplace_back(light);
}

glm::vec3 SurfaceShader::operator()(const SurfaceParams& s, const glm::vec3& p, glm::vec3 n,
                                    const glm::vec3& v) const {
  const auto sample = [&](std::size_t k, const glm::vec3& at) { return lights_[k](at); };
  return shade_point(*scene_, sample, s, p, n, v, *shadows_, *env_);
}

ImageRGBA direct_light(par::Executor& executor, const Scene& scene, const GBuffer& g,
                       const Camera& camera, const std::vector<ShadowMap>& shadows,
                       const EnvironmentMap& env, const std::vector<std::uint8_t>* read) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const SurfaceShader shade(scene, shadows, env);
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
      out.pixels[i] = glm::vec4(shade(g.surface.pixels[i], g.position.pixels[i], g.normal.pixels[i], g.view_direction(i)),
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
