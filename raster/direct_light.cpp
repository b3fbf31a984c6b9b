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

// On a surface too rough for a reflection pass, the environment along R (core/shading.h).
glm::vec3 add_rough_lobe(glm::vec3 radiance, const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                         const EnvironmentMap& env) {
  if (s.has_rough_specular_lobe())
    radiance += specular_reflectance(s, glm::dot(n, v)) * env.radiance(reflect(-v, n), s.phong_exponent);
  return radiance;
}

// shade_surface's terms after the lights: ambient light on the diffuse lobe, then the rough
// lobe's environment.
glm::vec3 add_environment(glm::vec3 radiance, const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                          const BrdfAtView& view, const EnvironmentMap& env) {
  radiance += diffuse_albedo_over_pi(s, view) * env.irradiance(n);
  return add_rough_lobe(radiance, s, n, v, env);
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
  // shade_point for eight points at once (core/brdf_lanes.h, core/shading_lanes.h: each lane
  // has the bits of the scalar forms); lanes past `count` repeat point 0 and are dropped.
  using L = par::Lanes<8>;
  using V = Vec3Lanes<8>;
  // The points' material parameters as lanes.
  L::mask mirror;
  const BrdfParamsLanes<8> brdf = punctual_brdf_params_lanes<8>(s, count, mirror);
  glm::vec3 emissive[8];
  for (int j = 0; j < count; ++j) emissive[j] = s[j]->emissive;
  const L::f32 zero(0.0f);

  const V pv = V::load(p, count), vv = V::load(v, count), raw_n = V::load(n_in, count);
  const V nv = select(dot(raw_n, vv) < zero, -raw_n, raw_n);  // facing_viewer
  glm::vec3 n[8];
  nv.store(n, count);
  const BrdfAtViewLanes<8> view = brdf_at_view_lanes(brdf, nv, vv);
  V radiance = V::load(emissive, count);
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
      unsigned lanes = 0;
      for (int j = 0; j < count; ++j) lanes |= reached[j] ? 1u << j : 0u;
      (*shadows_)[k].visibility_lanes(pv, nv, l, lanes, lit);
    } else {
      for (int j = 0; j < count; ++j) lit[j] = reached[j] ? 1.0f : 0.0f;
    }
    const L::f32 lit_lanes = L::load(lit);
    const L::mask shaded = reached && lit_lanes > zero;
    if (L::none(shaded)) continue;
    const V c = shade_light_lanes<8>(view, mirror, nv, vv, l, irradiance);
    radiance = select(shaded, radiance + lit_lanes * c, radiance);
  }
  // add_environment: the diffuse lobe's ambient light, then the rough lobes' lookups.
  radiance = radiance + diffuse_albedo_over_pi_lanes(brdf, view) * env_->irradiance8(nv);
  radiance.store(out, count);
  // add_rough_lobe on the points with a rough lobe, their environment lookups in one call.
  glm::vec3 along[8], environment[8];
  float exponent[8];
  int rough_lane[8], rough = 0;
  for (int j = 0; j < count; ++j)
    if (s[j]->has_rough_specular_lobe()) {
      rough_lane[rough] = j, along[rough] = reflect(-v[j], n[j]), exponent[rough] = s[j]->phong_exponent;
      ++rough;
    }
  if (rough == 0) return;
  env_->radiance8(along, exponent, rough, environment);
  // specular_reflectance(s, N·V) of a rough lobe is the view's albedo split applied to F0: the
  // punctual α is the lobe's own (roughness ≥ kGlossyRoughness > kMinPunctualRoughness), the
  // table clamps N·V to [0, 1] either way, and view.f0 is specular_f0's sum.
  alignas(32) float f0[3][8], scale[8], bias[8];
  L::store_aligned(view.f0.x, f0[0]), L::store_aligned(view.f0.y, f0[1]), L::store_aligned(view.f0.z, f0[2]);
  L::store_aligned(view.scale_at_view, scale), L::store_aligned(view.bias_at_view, bias);
  for (int t = 0; t < rough; ++t) {
    const int j = rough_lane[t];
    const SpecularAlbedo albedo{scale[j], bias[j]};
    out[j] += albedo(glm::vec3(f0[0][j], f0[1][j], f0[2][j])) * environment[t];
  }
}

ImageRGBA direct_light(par::Executor& executor, const Scene& scene, const GBuffer& g,
                       const Camera& camera, const std::vector<ShadowMap>& shadows,
                       const EnvironmentMap& env, const std::vector<std::uint8_t>* read) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const SurfaceShader shade(scene, shadows, env);
  executor.parallel_for("direct_light.shade", out.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    shade.shade_samples(
        g, begin, end, [&](std::size_t i) { return !read || (*read)[i]; },
        [&](std::size_t i, const glm::vec3& radiance) { out.pixels[i] = glm::vec4(radiance, 1.0f); },
        [&](std::size_t i) {
          const int x = static_cast<int>(i % g.width), y = static_cast<int>(i / g.width);
          const Ray ray = primary_ray(camera, g.width, g.height, x + 0.5f, y + 0.5f);
          out.pixels[i] = glm::vec4(env.radiance(ray.direction, 1e6f), 1.0f);
        });
  });
  return out;
}

ImageRGBA DirectLightPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                     const ShadowMaps& shadows,
                                     const EnvironmentMap& environment) const {
  return direct_light(c.executor(), *scene, gbuffer, camera, shadows, environment);
}

}  // namespace speculum::raster
