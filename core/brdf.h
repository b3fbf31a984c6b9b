// glTF 2.0's metallic-roughness BRDF (glTF 2.0 specification, Appendix B), evaluated for
// one pair of directions. All vectors are unit; n is the shading normal, l points towards
// the light, v towards the viewer, h = normalize(l + v).
//
//   D(h)    = α² χ(N·H) / (π ((N·H)² (α² − 1) + 1)²)               Trowbridge-Reitz / GGX (B.3.2)
//   V(l, v) = χ(H·L) χ(H·V) / (2 (|N·L| √((N·V)²(1−α²)+α²) + |N·V| √((N·L)²(1−α²)+α²)))
//                                                     height-correlated Smith, G/(4|N·L||N·V|)
//   specular_brdf = V D
//   F_x(f0) = f0 + (1 − f0)(1 − |V·H|)^5                                 Schlick (B.3.4)
//   dielectric = diffuse_base (1 − E(N·V)) (1 − E(N·L)) / (1 − E_avg) + F_x(f0_ior) specular_brdf
//   metal      = conductor_fresnel: F_x(base_color) specular_brdf
//   f          = mix(dielectric, metal, metallic)
// with α = roughness², f0_ior = ((ior − 1)/(ior + 1))² (KHR_materials_ior) and
// diffuse_base = (1 − transmission) base_color / π: KHR_materials_transmission mixes the
// dielectric's Lambert lobe towards the specular BTDF, which is not a reflection and is
// traced separately; the specular reflection layer is not scaled by transmission.
// Because Schlick is linear in f0, the two specular terms merge exactly into
// F_x(mix(f0_ior, base_color, metallic)) V D.
// The diffuse weight is not the spec's fresnel_mix (1 − F_x(V·H)): Appendix B ("Coupling
// Diffuse and Specular Reflection") notes that weighting breaks energy conservation, and it
// does (a white dielectric reflects 1.6× what it receives at 86° from the normal). Instead
// the Lambert lobe is scaled by what the specular layer leaves, coupled symmetrically:
// E(μ) = ∫ F_x(f0_ior) specular_brdf cos dω is the specular layer's directional albedo
// (specular_albedo below) and E_avg = 2 ∫ E(μ) μ dμ its cosine-weighted mean. Integrated
// over l, the diffuse reflects exactly base (1 − E(N·V)), so the dielectric's total albedo
// is base (1 − E) + E ≤ 1 at every view angle. For a smooth ior-1.5 dielectric at normal
// incidence the weight is 0.96²/(1 − E_avg) ≈ 1.05 × the spec's 0.96. Every factor is symmetric in l and v, so f is reciprocal.
#pragma once

#include <array>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace speculum {

// Punctual lights are deltas: against a near-delta lobe their highlight has an unbounded
// peak that no pixel filter resolves. Direct-light evaluation therefore never uses a lobe
// narrower than this roughness (α = 0.03² ≈ 9e-4; the GGX peak stays below ~4e5/sr).
constexpr float kMinPunctualRoughness = 0.03f;

// The smallest α the BRDF evaluates (a smaller one is raised to it: avoids 0/0).
constexpr float kMinAlpha = 1e-4f;

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

// The terms of gltf_brdf that depend on the surface and the viewer alone, computed once for a
// point lit by several lights: gltf_brdf(brdf_at_view(p, n, v), n, l, v) gives the bits of
// gltf_brdf(p, n, l, v) (the same operations, in the same order).
struct BrdfAtView {
  glm::vec3 base_color{1.0f};
  glm::vec3 f0{0.04f};          // Schlick's F0 of the specular lobe
  float alpha = 1.0f;           // ≥ 1e-4
  float cos_nv = 0.0f;          // N·V clamped to ≥ 0
  float diffuse_weight = 1.0f;  // (1 − metallic)(1 − transmission)
  float dielectric_f0 = 0.04f;
  float one_minus_e_v = 1.0f;   // 1 − the dielectric layer's albedo at N·V
  float one_minus_e_avg = 1.0f; // 1 − its average albedo (at least 1e-6)
  float smith_view_root = 1.0f; // √(N·V² (1 − α²) + α²) of the height-correlated V
  float scale_at_view = 1.0f;   // specular_albedo(N·V, α): shared with the diffuse albedo
  float bias_at_view = 0.0f;
};
BrdfAtView brdf_at_view(const BrdfParams& p, const glm::vec3& n, const glm::vec3& v);
BrdfValue gltf_brdf(const BrdfAtView& view, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v);

// Smith's masking of one direction for GGX, G1(μ) = 2μ / (μ + √(α² + (1 − α²) μ²)).
float smith_g1(float cos_n, float alpha);

// The specular layer's directional albedo ∫ F_x(f0) V D (N·L) dl for a viewer at N·V = μ,
// split into the parts linear in f0 (Schlick is linear in f0): E = f0 scale + bias. Read
// from a 32 × 32 table over (μ, √α) built once by quadrature (fixed points, so every
// process gets the same bytes), bilinear in between; exact Schlick (scale = 1 − (1 − μ)^5,
// bias = (1 − μ)^5) at α = 0. This is the "split-sum" scale real-time engines multiply a
// prefiltered environment lookup by.
struct SpecularAlbedo {
  float scale = 1.0f;
  float bias = 0.0f;
  float operator()(float f0) const { return f0 * scale + bias; }
  glm::vec3 operator()(const glm::vec3& f0) const { return f0 * scale + glm::vec3(bias); }
};
SpecularAlbedo specular_albedo(float cos_nv, float alpha);
// Its cosine-weighted mean over view directions, 2 ∫ E(μ) μ dμ (same split).
SpecularAlbedo average_specular_albedo(float alpha);

// The table specular_albedo and average_specular_albedo interpolate: E(μ_i, α_j) with
// μ_i = i/(n−1) (at least 1e-3) and α_j = (j/(n−1))², each by 1024-point quadrature, and per
// row the cosine-weighted mean 2 ∫ E μ dμ (trapezoid rule on the μ grid). It is stored in
// core/albedo_table.inc, so no process spends the ~80 ms of quadrature at start; the tests
// compare it with albedo_table_by_quadrature() bit for bit, and albedo_table_source() prints
// the file.
constexpr int kAlbedoTableSize = 32;
struct AlbedoTable {
  std::array<SpecularAlbedo, kAlbedoTableSize * kAlbedoTableSize> e{};  // [roughness][μ]
  std::array<SpecularAlbedo, kAlbedoTableSize> average{};               // [roughness]
};
const AlbedoTable& albedo_table();
AlbedoTable albedo_table_by_quadrature();
std::string albedo_table_source(const AlbedoTable& table);

// A GGX visible normal for a viewer v_local (in the frame whose +Z is the surface normal,
// v_local.z > 0), from two uniform numbers in [0, 1): the half-vector h has pdf
// G1(v) max(v·h, 0) D(h) / (N·V), so l = reflect(−v, h) has pdf that over 4 v·h and the
// estimator f_spec (N·L) / pdf is F_x(v·h) G2(l, v) / G1(v) (ggx_sample_weight).
glm::vec3 sample_ggx_visible_normal(const glm::vec3& v_local, float alpha, glm::vec2 u);
// The same for many u at one viewer and roughness: the stretched view and its basis are
// computed once (the same bits as the one-call form, which uses it).
class GgxVisibleNormalSampler {
 public:
  GgxVisibleNormalSampler(const glm::vec3& v_local, float alpha);
  glm::vec3 operator()(glm::vec2 u) const;

 private:
  float alpha_;
  glm::vec3 vh_, t1_, t2_;  // the stretched view and the basis of its projected disc
  float s_;                 // the disc's warp towards v
};
// F_x(v·h) G2 / G1(v) without F: G2 = 4 (N·L)(N·V) V(l, v); 0 when l is below the surface.
float ggx_sample_weight(float cos_nl, float cos_nv, float alpha);
// The same given g1 = smith_g1(cos_nv, max(alpha, kMinAlpha)) (for many l at one viewer).
float ggx_sample_weight(float cos_nl, float cos_nv, float alpha, float g1);

}  // namespace speculum
