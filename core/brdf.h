// glTF 2.0's metallic-roughness BRDF (glTF 2.0 specification, Appendix B), evaluated for
// one pair of directions. All vectors are unit; n is the shading normal, l points towards
// the light, v towards the viewer, h = normalize(l + v).
//
//   D(h)    = α² χ(N·H) / (π ((N·H)² (α² − 1) + 1)²)               Trowbridge-Reitz / GGX (B.3.2)
//   V(l, v) = χ(H·L) χ(H·V) / (2 (|N·L| √((N·V)²(1−α²)+α²) + |N·V| √((N·L)²(1−α²)+α²)))
//                                                     height-correlated Smith, G/(4|N·L||N·V|)
//   specular_brdf = V D
//   F_x(f0) = f0 + (1 − f0)(1 − |V·H|)^5                                 Schlick (B.3.4)
//   dielectric = fresnel_mix: (1 − F_x(f0_ior)) diffuse_base + F_x(f0_ior) specular_brdf
//   metal      = conductor_fresnel: F_x(base_color) specular_brdf
//   f          = mix(dielectric, metal, metallic)
// with α = roughness², f0_ior = ((ior − 1)/(ior + 1))² (KHR_materials_ior) and
// diffuse_base = (1 − transmission) base_color / π: KHR_materials_transmission mixes the
// dielectric's Lambert lobe towards the specular BTDF, which is not a reflection and is
// traced separately; the specular reflection layer is not scaled by transmission.
// Because Schlick is linear in f0, the two specular terms merge exactly into
// F_x(mix(f0_ior, base_color, metallic)) V D; the diffuse keeps the dielectric's own
// Fresnel weight (1 − metallic)(1 − F_x(f0_ior)), the spec's exact mix (Appendix B.3.5
// before its simplification to a single F). Every factor is symmetric in l and v, so f is
// reciprocal.
#pragma once

#include <glm/vec3.hpp>

namespace speculum {

// Punctual lights are deltas: against a near-delta lobe their highlight has an unbounded
// peak that no pixel filter resolves. Direct-light evaluation therefore never uses a lobe
// narrower than this roughness (α = 0.03² ≈ 9e-4; the GGX peak stays below ~4e5/sr).
constexpr float kMinPunctualRoughness = 0.03f;

// The material inputs of the BRDF (textures already applied).
struct BrdfParams {
  glm::vec3 base_color{1.0f};
  float metallic = 0.0f;
  float alpha = 1.0f;           // roughness², clamped inside to ≥ 1e-4 (avoids 0/0)
  float dielectric_f0 = 0.04f;  // ((ior − 1)/(ior + 1))²
  float transmission = 0.0f;    // scales the dielectric's diffuse lobe only
};

// The spec's D, V and Schlick terms (exposed for tests and for anything that needs the
// parts). cos_nh ≤ 0 gives D = 0.
float ggx_distribution(float cos_nh, float alpha);
float smith_visibility_height_correlated(float cos_nl, float cos_nv, float alpha);

// The two lobes of f(l, v) separately (1/sr); f = diffuse + specular. Both are 0 unless
// N·L > 0; N·V is clamped to ≥ 0 (a viewer at the horizon still sees a finite value).
struct BrdfValue {
  glm::vec3 diffuse{0.0f};
  glm::vec3 specular{0.0f};
  glm::vec3 total() const { return diffuse + specular; }
};
BrdfValue gltf_brdf(const BrdfParams& p, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v);

}  // namespace speculum
