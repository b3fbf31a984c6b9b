// The one shading model shared by the rasterizer's direct_light node and the reference
// tracer, so techniques and the ground truth agree (glTF metallic-roughness materials;
// KHR_lights_punctual units). The model, in full:
// - Direct light (punctual lights): glTF 2.0's metallic-roughness BRDF (glTF 2.0 spec,
//   Appendix B; formulas in core/brdf.h): GGX D with α = roughness², height-correlated
//   Smith V, Schlick F on V·H with F0 = mix(fresnel_f0(ior) [0.04 at ior 1.5], base_color,
//   metallic), and a Lambert diffuse (1 - metallic)(1 - transmission) base_color/π scaled by
//   what the dielectric's specular layer leaves, coupled symmetrically in l and v so the
//   whole BRDF never reflects more than it receives (core/brdf.h says why not the spec's
//   fresnel_mix). Reflected radiance L = f(l, v) (N·L) E. α is clamped to
//   kMinPunctualRoughness² so the highlight of a delta light stays finite. The BRDF is
//   smooth in l, so there is no edge anywhere on a lit surface.
// - Mirror-class surfaces (r <= kMirrorRoughness) get the diffuse term but no direct
//   highlight: in the spec's limit α → 0 the lobe is a delta, and a delta lobe's image of a
//   point light is a point of zero solid angle — the same invisible point the camera sees
//   when it looks at the light itself (lights are not geometry). Their reflections are
//   traced/looked up along R = reflect(-V, N) instead, weighted by Schlick F(N·V).
// - Indirect glossy reflection (kMirrorRoughness < r < kGlossyRoughness) is the same GGX
//   specular lobe integrated against incoming radiance, L_s = ∫ f_spec L cos dω:
//   · traced with samples: each sample weighted f_spec cos / p by its own pdf (the reference
//     samples GGX's visible normals; YU's rays sample a Phong lobe, trace/glossy_rays.h);
//   · read from prefiltered maps (environment, distance and reflector maps): the map is
//     prefiltered with the normalized Phong lobe of exponent Material::phong_exponent()
//     about R — the one roughness → lobe-width mapping (core/scene.h), matched to GGX's
//     peak — and the lookup is scaled by the lobe's directional albedo
//     specular_reflectance(s, N·V) = E(F0) (core/brdf.h specular_albedo), the split-sum
//     approximation ∫ f L cos ≈ E · (prefiltered L).
//   In the mirror limit both reduce to F(N·V) L(R). Rougher surfaces (r >= kGlossyRoughness)
//   reflect only the environment with their specular lobe: the techniques read the
//   prefiltered environment along R scaled by E(F0) (like their ambient diffuse, unshadowed),
//   the reference samples the lobe with occlusion. So a white dielectric of any roughness
//   under a uniform environment returns exactly the environment's radiance.
// - Environment/ambient diffuse: diffuse_albedo_over_pi = what the coupled Lambert lobe
//   above reflects under uniform light, base (1 − E_dielectric(N·V)) / π, times the
//   irradiance.
// - Refractors (transmission > 0.5): smooth dielectric, exact Fresnel (fresnel_dielectric),
//   transmitted light tinted by base_color. KHR_materials_transmission replaces the diffuse
//   lobe by the transmission: the direct light's diffuse is scaled by (1 - transmission)
//   once; its specular highlight is not scaled.
// - Emission adds `emissive` towards every direction.
// - Lights (KHR_lights_punctual): point/spot intensity in candela, E = I/d² times the range
//   window clamp(1 - (d/range)^4, 0, 1) (range 0: infinite); spot cone smoothstep-free
//   falloff of the glTF spec; directional intensity in lux, E = I.
// - Environment: constant, or the equirect image (core/scene.h) looked up bilinearly with
//   u = 0.5 + atan2(d.x, -d.z)/(2π) (so -Z is the image centre, +X at u = 0.75) and
//   v = acos(d.y)/π (+Y at the top row), times intensity.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/brdf.h"
#include "core/sampling.h"
#include "core/scene.h"

namespace speculum {

template <int W>
struct Vec3Lanes;

// Material parameters at one surface point, textures already applied.
struct SurfaceParams {
  glm::vec3 base_color{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  float transmission = 0.0f;
  float ior = 1.5f;
  glm::vec3 emissive{0.0f};
  float phong_exponent = 0.0f;  // Material::phong_exponent(): indirect glossy lobes only

  bool is_refractor() const { return transmission > 0.5f; }
  bool is_mirror_lobe() const { return roughness <= kMirrorRoughness; }
  bool is_glossy_lobe() const { return roughness > kMirrorRoughness && roughness < kGlossyRoughness; }
  // Too rough for a traced/looked-up reflection: its specular lobe still reflects the
  // environment (unshadowed in the techniques, occluded in the reference).
  bool has_rough_specular_lobe() const { return !is_refractor() && roughness >= kGlossyRoughness; }
};

// The constant factors of a material (no texture lookups).
SurfaceParams surface_params(const Material& material);
// The material `material_index` of `scene` at texture coordinates uv (TEXCOORD_0) /
// uv1 (TEXCOORD_1): base colour, metallic-roughness, emissive and transmission textures
// sampled bilinearly with repeat wrapping after KHR_texture_transform. An out-of-range
// texture index is ignored (Scene::validate rejects it earlier).
SurfaceParams surface_params(const Scene& scene, std::uint32_t material_index, glm::vec2 uv,
                             glm::vec2 uv1 = glm::vec2(0.0f));

// Light arriving at a point from one punctual light.
struct LightSample {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // unit, from the surface point towards the light
  float distance = 0.0f;                  // to the light; +inf for directional lights
  glm::vec3 irradiance{0.0f};             // at normal incidence: colour × E (0: out of reach)
};
LightSample sample_light(const Light& light, const glm::vec3& position);
// sample_light's per-light constants (the unit direction, the spot cone's cosines) computed
// once, for a pass that samples one light at many points: sampler(p) gives the bits of
// sample_light(light, p).
class LightSampler {
 public:
  explicit LightSampler(const Light& light);
  LightSample operator()(const glm::vec3& position) const;
  // The same at W points (core/shading_lanes.h): each lane's direction and irradiance have
  // the bits of operator()'s.
  template <int W>
  void sample(const Vec3Lanes<W>& position, Vec3Lanes<W>& direction, Vec3Lanes<W>& irradiance) const;

 private:
  const Light* light_;
  glm::vec3 direction_{0.0f};  // unit (spot and directional lights)
  float cos_outer_ = 0.0f, cone_scale_ = 1.0f;  // spot lights
};

// Inline: a shading loop calls it per point and light, and the call's returned struct
// cost more than its arithmetic.
inline LightSample LightSampler::operator()(const glm::vec3& position) const {
  const Light& light = *light_;
  LightSample out;
  if (light.type == LightType::Directional) {
    out.direction = -direction_;
    out.distance = std::numeric_limits<float>::infinity();
    out.irradiance = light.color * light.intensity;
    return out;
  }
  const glm::vec3 to_light = light.position - position;
  const float d2 = glm::dot(to_light, to_light);
  if (!(d2 > 0.0f)) return out;  // at the light itself: no defined direction
  const float d = std::sqrt(d2);
  out.direction = to_light / d;
  out.distance = d;
  float window = 1.0f;
  if (light.range > 0.0f) {
    const float r = d / light.range;
    const float r2 = r * r;
    window = std::clamp(1.0f - r2 * r2, 0.0f, 1.0f);
  }
  float cone = 1.0f;
  if (light.type == LightType::Spot) {
    const float cd = glm::dot(direction_, -out.direction);
    const float a = std::clamp((cd - cos_outer_) * cone_scale_, 0.0f, 1.0f);
    cone = a * a;
  }
  out.irradiance = light.color * (light.intensity * window * cone / d2);
  return out;
}

// F0 of the specular lobe, and the weight of a reflection looked up or traced along R for a
// viewer at cos_nv = N·V: the lobe's directional albedo E(F0) (glossy; the split-sum scale
// of a prefiltered lookup) or Schlick's F(N·V) (mirror, the delta limit of E).
glm::vec3 specular_f0(const SurfaceParams& s);
glm::vec3 specular_reflectance(const SurfaceParams& s, float cos_nv);

// Radiance reflected towards V (unit, surface → viewer) from one light sample, N unit:
// f(l, v) (N·L) E with the glTF BRDF above (no highlight on mirror-class surfaces). The
// caller decides visibility (shadow ray or shadow map).
glm::vec3 shade_light(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                      const LightSample& light);
// The same for a point shaded under several lights, its viewer's terms computed once
// (view = brdf_at_view(brdf_params_for_punctual_light(s), n, v)): the same bits.
glm::vec3 shade_light(const SurfaceParams& s, const BrdfAtView& view, const glm::vec3& n, const glm::vec3& v,
                      const LightSample& light);
// The BRDF inputs shade_light uses (roughness clamped to kMinPunctualRoughness).
BrdfParams brdf_params_for_punctual_light(const SurfaceParams& s);
// A direction from the GGX specular lobe of s about the unit normal n for a viewer at v
// (visible normals, α = roughness², from two uniform numbers u) and its weight
// f_spec cos / p = F(V·H) G2/G1 (core/brdf.h); weight 0 when v or the sample lies below the
// surface. The estimator of the reference tracer and of the exact specular reference.
struct LobeSample {
  glm::vec3 direction{0.0f};
  glm::vec3 weight{0.0f};
};
LobeSample sample_specular_lobe(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v, glm::vec2 u);
// The same for many u at one surface point and viewer: the frame, the visible-normal
// sampler, G1(v) and F0 are computed once (the same bits as the one-call form, which uses it).
class SpecularLobeSampler {
 public:
  SpecularLobeSampler(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v);
  LobeSample operator()(glm::vec2 u) const;

 private:
  Onb frame_;
  glm::vec3 v_;
  float alpha_, cos_nv_, g1_;
  bool above_;  // v above the surface (else every sample weighs 0)
  GgxVisibleNormalSampler normals_;
  glm::vec3 f0_;
};

// The diffuse part alone, for irradiance from many directions (environment, ambient): the
// weight of incident irradiance, (1 - metallic)(1 - transmission)(1 - E_dielectric(N·V))
// base_color / π (1/sr), exact for uniform incident light.
glm::vec3 diffuse_albedo_over_pi(const SurfaceParams& s, float cos_nv);
// The same at the viewer of view = brdf_at_view(brdf_params_for_punctual_light(s), n, v), its
// albedo lookup reused: the bits of diffuse_albedo_over_pi(s, N·V).
glm::vec3 diffuse_albedo_over_pi(const SurfaceParams& s, const BrdfAtView& view);

// Equirect mapping (see the header comment) and the environment radiance towards -d
// (d: unit direction of the ray leaving the scene).
glm::vec2 equirect_uv(const glm::vec3& d);
// Its inverse: the direction the equirect point (u, v) looks along, φ = 2π(u − ½), θ = πv,
// d = (sinθ sinφ, cosθ, −sinθ cosφ).
glm::vec3 equirect_direction(float u, float v);
// The solid angle of one pixel of row y of a width × height equirect image:
// Δφ (cos θ0 − cos θ1).
double equirect_pixel_solid_angle(int y, int width, int height);
glm::vec3 environment_radiance(const Environment& env, const glm::vec3& d);
// The environment's radiance averaged over the sphere (each equirect row weighted by its
// solid angle); π times it is the irradiance of a constant environment, and the ambient
// term of shading that has no spherical-harmonic projection at hand.
glm::vec3 environment_mean_radiance(const Environment& env);

// Bilinear lookup with repeat wrapping in u and v (texel centres at (i+0.5)/w).
// repeat_index is its wrap: texel index i of any integer on a side of n texels, in [0, n).
int repeat_index(long long i, int n);
glm::vec4 sample_bilinear_repeat(const ImageRGBA& image, glm::vec2 uv);

// sample_bilinear_repeat in two steps: where it reads (bilinear_repeat_taps) and the blend
// (value), so that a caller can find many lookups' texels, and fetch them, before it waits on
// any. value(bilinear_repeat_taps(image, uv)) is sample_bilinear_repeat(image, uv) bit for bit.
struct BilinearTaps {
  const glm::vec4* texel[4];  // (x0, y0), (x1, y0), (x0, y1), (x1, y1); only [0] when `single`
  float ax = 0.0f, ay = 0.0f;  // the weights of x1 and y1
  bool single = false;         // the lookup is texel[0] itself (no image, or a non-finite uv)
  glm::vec4 value() const;
  // Asks for the cache lines of the texels.
  void prefetch() const;
};
BilinearTaps bilinear_repeat_taps(const ImageRGBA& image, glm::vec2 uv);
// The taps of texture `ref` of `scene` at uv (TEXCOORD_0) / uv1 (TEXCOORD_1) after its
// KHR_texture_transform: surface_params' lookups (an invalid reference reads 1).
BilinearTaps texture_taps(const Scene& scene, const TextureRef& ref, glm::vec2 uv, glm::vec2 uv1);

// Per scene object: 1 when any of its triangles has a refracting material.
std::vector<std::uint8_t> refractor_objects(const Scene& scene);

}  // namespace speculum
