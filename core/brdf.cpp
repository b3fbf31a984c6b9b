// glTF 2.0 metallic-roughness BRDF (see core/brdf.h for the formulas and their sources).
#include "core/brdf.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "core/sampling.h"

namespace speculum {

namespace {
constexpr float kMinAlpha = 1e-4f;

// D with the denominator written as (N·H)² α² + sin²θ_h: near the peak 1 − (N·H)² in float
// would cancel to 0 and leave only α² terms, so the caller passes sin²θ_h computed from
// the cross product (exact to float precision at any angle).
float ggx_from_cos_sin(float cos2, float sin2, float alpha) {
  const float a2 = alpha * alpha;
  const float d = cos2 * a2 + sin2;
  return a2 / (kPi * d * d);
}
}  // namespace

float ggx_distribution(float cos_nh, float alpha) {
  if (cos_nh <= 0.0f) return 0.0f;
  const float c = std::min(cos_nh, 1.0f);
  alpha = std::max(alpha, kMinAlpha);
  return ggx_from_cos_sin(c * c, std::max(1.0f - c * c, 0.0f), alpha);
}

float smith_visibility_height_correlated(float cos_nl, float cos_nv, float alpha) {
  const float nl = std::abs(cos_nl), nv = std::abs(cos_nv);
  alpha = std::max(alpha, kMinAlpha);
  const float a2 = alpha * alpha;
  const float gv = nl * std::sqrt(nv * nv * (1.0f - a2) + a2);
  const float gl = nv * std::sqrt(nl * nl * (1.0f - a2) + a2);
  const float denom = gv + gl;
  return denom > 0.0f ? 0.5f / denom : 0.0f;
}

BrdfValue gltf_brdf(const BrdfParams& p, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v) {
  BrdfValue out;
  const float cos_nl = glm::dot(n, l);
  if (cos_nl <= 0.0f) return out;
  const float cos_nv = std::max(glm::dot(n, v), 0.0f);
  const glm::vec3 sum = l + v;
  const float sum2 = glm::dot(sum, sum);
  // l = −v cannot happen with both above the surface except at the horizon; H = N there.
  const glm::vec3 h = sum2 > 1e-12f ? sum / std::sqrt(sum2) : n;
  const float cos_vh = std::clamp(glm::dot(v, h), 0.0f, 1.0f);

  const float metallic = std::clamp(p.metallic, 0.0f, 1.0f);
  const float alpha = std::max(p.alpha, kMinAlpha);
  const float fresnel_dielectric_vh = fresnel_schlick(cos_vh, p.dielectric_f0);
  out.diffuse = p.base_color * ((1.0f - metallic) * (1.0f - std::clamp(p.transmission, 0.0f, 1.0f)) *
                                (1.0f - fresnel_dielectric_vh) / kPi);

  const float cos_nh = glm::dot(n, h);
  if (cos_nh <= 0.0f) return out;
  const glm::vec3 nxh = glm::cross(n, h);
  const float d = ggx_from_cos_sin(cos_nh * cos_nh, glm::dot(nxh, nxh), alpha);
  const float vis = smith_visibility_height_correlated(cos_nl, cos_nv, alpha);
  const glm::vec3 f0 = glm::vec3(p.dielectric_f0) * (1.0f - metallic) + p.base_color * metallic;
  out.specular = fresnel_schlick(cos_vh, f0) * (d * vis);
  return out;
}

}  // namespace speculum
