// The one shading model shared by the rasterizer's direct_light node and the reference
// tracer, so techniques and the ground truth agree (glTF metallic-roughness materials;
// KHR_lights_punctual units). The model, in full:
// - F0 = mix(fresnel_f0(ior) [0.04 at ior 1.5], base_color, metallic); F = Schlick(N·V, F0).
// - Diffuse: f_d = (1 - F) (1 - metallic) (1 - transmission) base_color / π (Lambert).
// - Specular: a normalized Phong lobe of exponent n = Material::phong_exponent() about the
//   mirror direction R = reflect(-V, N). Reflected radiance = F × the lobe-weighted mean of
//   incident radiance, L_s = F ∫ p(ω) L(ω) dω with p = (n+1)/(2π) cos^n(R,ω) (YU eq.4), so a
//   lobe sample's weight is exactly F and the mirror limit (n → ∞) is L_s = F L(R).
//   Directions under the surface horizon (N·ω <= 0) contribute nothing.
//   For a punctual light of irradiance E (at normal incidence): L_s = F p(ω_l) E when N·ω_l > 0.
// - Roughness classes: r <= kMirrorRoughness: the lobe is a delta — direct lights give no
//   highlight, reflections are traced/looked up along R; r < kGlossyRoughness: glossy
//   lobe, indirect by lobe sampling; otherwise only the direct-light highlight.
// - Refractors (transmission > 0.5): smooth dielectric, exact Fresnel (fresnel_dielectric),
//   transmitted light tinted by base_color; the opaque terms are scaled by (1-transmission).
// - Emission adds `emissive` towards every direction.
// - Lights (KHR_lights_punctual): point/spot intensity in candela, E = I/d² times the range
//   window clamp(1 - (d/range)^4, 0, 1) (range 0: infinite); spot cone smoothstep-free
//   falloff of the glTF spec; directional intensity in lux, E = I.
// - Environment: constant, or the equirect image (core/scene.h) looked up bilinearly with
//   u = 0.5 + atan2(d.x, -d.z)/(2π) (so -Z is the image centre, +X at u = 0.75) and
//   v = acos(d.y)/π (+Y at the top row), times intensity.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"

namespace speculum {

// Material parameters at one surface point, textures already applied.
struct SurfaceParams {
  glm::vec3 base_color{1.0f};
  float metallic = 0.0f;
  float roughness = 1.0f;
  float transmission = 0.0f;
  float ior = 1.5f;
  glm::vec3 emissive{0.0f};
  float phong_exponent = 0.0f;

  bool is_refractor() const { return transmission > 0.5f; }
  bool is_mirror_lobe() const { return roughness <= kMirrorRoughness; }
  bool is_glossy_lobe() const { return roughness > kMirrorRoughness && roughness < kGlossyRoughness; }
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

// F0 and the Schlick Fresnel factor for the specular lobe, cos_nv = N·V.
glm::vec3 specular_f0(const SurfaceParams& s);
glm::vec3 specular_fresnel(const SurfaceParams& s, float cos_nv);

// Radiance reflected towards V (unit, surface → viewer) from one light sample, N unit:
// diffuse + specular highlight as above, times (1 - transmission) for refractors. The
// caller decides visibility (shadow ray or shadow map).
glm::vec3 shade_light(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                      const LightSample& light);
// The diffuse part alone: the weight of incident irradiance-cosine, i.e. f_d (1/sr).
glm::vec3 diffuse_albedo_over_pi(const SurfaceParams& s, float cos_nv);

// Equirect mapping (see the header comment) and the environment radiance towards -d
// (d: unit direction of the ray leaving the scene).
glm::vec2 equirect_uv(const glm::vec3& d);
glm::vec3 environment_radiance(const Environment& env, const glm::vec3& d);

// Bilinear lookup with repeat wrapping in u and v (texel centres at (i+0.5)/w).
glm::vec4 sample_bilinear_repeat(const ImageRGBA& image, glm::vec2 uv);

// Per scene object: 1 when any of its triangles has a refracting material.
std::vector<std::uint8_t> refractor_objects(const Scene& scene);

}  // namespace speculum
