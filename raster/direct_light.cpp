// The `direct_light` node: see direct_light.h.
#include "raster/direct_light.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/optics.h"
#include "core/shading_lanes.h"

namespace speculum::raster {

namespace {

// The normal shade_surface lights: refractors seen from inside light the near side.
glm::vec3 facing_viewer(const glm::vec3& n, const glm::vec3& v) { return glm::dot(n, v) < 0.0f ? -n : n; }

// shade_surface's terms after the lights: ambient light on the diffuse lobe and, on a surface
// too rough for a reflection pass, the environment along R (core/shading.h).
glm::vec3 add_environment(glm::vec3 radiance, const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                          const BrdfAtView& view, const EnvironmentMap& env) {
  radiance += diffuse_albedo_over_pi(s, view) * env.irradiance(n);
  if (s.has_rough_specular_lobe())
    radiance += specular_reflectance(s, glm::dot(n, v)) * env.radiance(reflect(-v, n), s.phong_exponent);
  return radiance;
}

// shade_surface with light k sampled at p by sample(k, p) (sample_light's bits).
template <class SampleLight>
glm::vec3 shade_point(const Scene& scene, const SampleLight& sample, const SurfaceParams& s, const glm::vec3& p,
                      glm::vec3 n, const glm::vec3& v, const std::vector<ShadowMap>& shadows,
                      const EnvironmentMap& env) {
  n = facing_viewer(n, v);
  glm::vec3 radiance = s.emissive;
  const BrdfAtView view = brdf_at_view(brdf_params_for_punctual_light(s), n, v);
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    const LightSample ls = sample(k, p);
    if (ls.irradiance == glm::vec3(0.0f) || glm::dot(n, ls.direction) <= 0.0f) continue;
    const float lit = k < shadows.size() ? shadows[k].visibility(p, n, ls.direction) : 1.0f;
    if (lit > 0.0f) radiance += lit * shade_light(s, view, n, v, ls);
  }
  return add_environment(radiance, s, n, v, view, env);
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

void SurfaceShader::shade8(const SurfaceParams* const* s, const glm::vec3* p, const glm::vec3* n_in,
                           const glm::vec3* v, int count, glm::vec3* out) const {
  using L = par::Lanes<8>;
  using V = Vec3Lanes<8>;
  glm::vec3 n[8];
  BrdfAtView view[8];
  alignas(32) float mirror_flag[8] = {};
  for (int j = 0; j < count; ++j) {
    n[j] = facing_viewer(n_in[j], v[j]);
    out[j] = s[j]->emissive;
    view[j] = brdf_at_view(brdf_params_for_punctual_light(*s[j]), n[j], v[j]);
    mirror_flag[j] = s[j]->is_mirror_lobe() ? 1.0f : 0.0f;
  }
  // Every light's terms eight points at a time (core/shading_lanes.h: each lane has the bits
  // of shade_light's scalar form); lanes past `count` repeat point 0 and are dropped.
  const V pv = V::load(p, count), nv = V::load(n, count), vv = V::load(v, count);
  const BrdfAtViewLanes<8> views = BrdfAtViewLanes<8>::load(view, count);
  const L::mask mirror = L::load(mirror_flag) > 0.0f;
  const L::f32 zero(0.0f);
  V radiance = V::load(out, count);
  for (std::size_t k = 0; k < lights_.size(); ++k) {
    V l, irradiance;
    lights_[k].sample(pv, l, irradiance);
    const L::mask reached = L::first_n(count) &&
                            !(irradiance.x == zero && irradiance.y == zero && irradiance.z == zero) &&
                            !(dot(nv, l) <= zero);
    if (L::none(reached)) continue;
    // The points this light reaches, in point order, and their shadow tests in one call.
    alignas(32) float lit[8] = {};
    if (k < shadows_->size()) {
      glm::vec3 lit_p[8], lit_n[8], lit_l[8];
      glm::vec3 all_l[8];
      l.store(all_l, 8);
      int lane[8], reached_count = 0;
      for (int j = 0; j < count; ++j)
        if (reached[j]) {
          lane[reached_count] = j;
          lit_p[reached_count] = p[j], lit_n[reached_count] = n[j], lit_l[reached_count] = all_l[j];
          ++reached_count;
        }
      float packed[8];
      (*shadows_)[k].visibility8(lit_p, lit_n, lit_l, reached_count, packed);
      for (int t = 0; t < reached_count; ++t) lit[lane[t]] = packed[t];
    } else {
      for (int j = 0; j < count; ++j) lit[j] = reached[j] ? 1.0f : 0.0f;
    }
    const L::f32 lit_lanes = L::load(lit);
    const L::mask shaded = reached && lit_lanes > zero;
    if (L::none(shaded)) continue;
    const V c = shade_light_lanes<8>(views, mirror, nv, vv, l, irradiance);
    radiance = select(shaded, radiance + lit_lanes * c, radiance);
  }
  radiance.store(out, count);
  for (int j = 0; j < count; ++j) out[j] = add_environment(out[j], *s[j], n[j], v[j], view[j], *env_);
}

ImageRGBA direct_light(par::Executor& executor, const Scene& scene, const GBuffer& g,
                       const Camera& camera, const std::vector<ShadowMap>& shadows,
                       const EnvironmentMap& env, const std::vector<std::uint8_t>* read) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const SurfaceShader shade(scene, shadows, env);
  executor.parallel_for("direct_light.shade", out.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    // Covered samples are shaded eight at a time (their shadow tests share lanes).
    std::size_t batch[8];
    int count = 0;
    const auto shade_batch = [&] {
      const SurfaceParams* s[8];
      glm::vec3 p[8], n[8], v[8], radiance[8];
      for (int j = 0; j < count; ++j) {
        const std::size_t i = batch[j];
        s[j] = &g.surface[i], p[j] = g.position.pixels[i], n[j] = g.normal.pixels[i], v[j] = g.view_direction(i);
      }
      shade.shade8(s, p, n, v, count, radiance);
      for (int j = 0; j < count; ++j) out.pixels[batch[j]] = glm::vec4(radiance[j], 1.0f);
      count = 0;
    };
    for (std::size_t i = begin; i < end; ++i) {
      if (read && !(*read)[i]) continue;
      if (!g.covered(i)) {
        const int x = static_cast<int>(i % g.width), y = static_cast<int>(i / g.width);
        const Ray ray = primary_ray(camera, g.width, g.height, x + 0.5f, y + 0.5f);
        out.pixels[i] = glm::vec4(env.radiance(ray.direction, 1e6f), 1.0f);
        continue;
      }
      batch[count++] = i;
      if (count == 8) shade_batch();
    }
    if (count > 0) shade_batch();
  });
  return out;
}

ImageRGBA DirectLightPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                     const ShadowMaps& shadows,
                                     const EnvironmentMap& environment) const {
  return direct_light(c.executor(), *scene, gbuffer, camera, shadows, environment);
}

}  // namespace speculum::raster
