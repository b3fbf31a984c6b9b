// glTF 2.0 metallic-roughness BRDF (see core/brdf.h for the formulas and their sources).
#include "core/brdf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "core/sampling.h"

namespace speculum {

namespace {
// D with the denominator written as (N·H)² α² + sin²θ_h: near the peak 1 − (N·H)² in float
// would cancel to 0 and leave only α² terms, so the caller passes sin²θ_h computed from
// the cross product (exact to float precision at any angle).
float ggx_from_cos_sin(float cos2, float sin2, float alpha) {
  const float a2 = alpha * alpha;
  const float d = cos2 * a2 + sin2;
  return a2 / (kPi * d * d);
}

// The albedo table's grid (brdf.h): μ clamped to ≥ 1e-3 because at the horizon itself the
// viewer sees nothing; columns in √α resolve the smooth end, where the albedo changes fastest.
constexpr int kQuadraturePoints = 1024;

// E(μ, α) by importance sampling visible normals over a fixed Hammersley set, summed in
// double: the estimator F_x G2/G1 has bounded variance, so 1024 points give ~1e-3.
SpecularAlbedo integrate_albedo(float mu, float alpha) {
  if (alpha <= 0.0f) {
    const float c5 = std::pow(1.0f - mu, 5.0f);
    return {1.0f - c5, c5};
  }
  const glm::vec3 v(std::sqrt(std::max(1.0f - mu * mu, 0.0f)), 0.0f, mu);
  double scale = 0.0, bias = 0.0;
  for (int k = 0; k < kQuadraturePoints; ++k) {
    const glm::vec3 h = sample_ggx_visible_normal(v, alpha, hamersley(k, kQuadraturePoints));
    const float cos_vh = glm::dot(v, h);
    const glm::vec3 l = 2.0f * cos_vh * h - v;
    const double w = ggx_sample_weight(l.z, mu, alpha);
    const double c5 = std::pow(1.0 - std::clamp(double(cos_vh), 0.0, 1.0), 5.0);
    scale += w * (1.0 - c5);
    bias += w * c5;
  }
  return {float(scale / kQuadraturePoints), float(bias / kQuadraturePoints)};
}

}  // namespace

AlbedoTable albedo_table_by_quadrature() {
  AlbedoTable t;
  for (int j = 0; j < kAlbedoTableSize; ++j) {
    const float r = float(j) / float(kAlbedoTableSize - 1);
    double avg_scale = 0.0, avg_bias = 0.0;
    for (int i = 0; i < kAlbedoTableSize; ++i) {
      const float mu = std::max(float(i) / float(kAlbedoTableSize - 1), 1e-3f);
      const SpecularAlbedo e = integrate_albedo(mu, r * r);
      t.e[std::size_t(j * kAlbedoTableSize + i)] = e;
      // 2 ∫ E μ dμ by the trapezoid rule on the table's own μ grid.
      const double w = (i == 0 || i == kAlbedoTableSize - 1 ? 0.5 : 1.0) * 2.0 * (float(i) / float(kAlbedoTableSize - 1)) /
                       double(kAlbedoTableSize - 1);
      avg_scale += w * e.scale;
      avg_bias += w * e.bias;
    }
    t.average[std::size_t(j)] = {float(avg_scale), float(avg_bias)};
  }
  return t;
}

const AlbedoTable& albedo_table() {
  static constexpr AlbedoTable kStored =
#include "core/albedo_table.inc"
      ;
  return kStored;
}

std::string albedo_table_source(const AlbedoTable& table) {
  std::string out =
      "// E(mu, alpha) of core/brdf.h's albedo table and its row averages as {scale, bias}, hex floats\n"
      "// (exact). Printed by albedo_table_source(albedo_table_by_quadrature()); the test\n"
      "// AlbedoTable.StoredTableIsTheQuadratures writes it to albedo_table.inc.new when they differ.\n"
      "AlbedoTable{{{\n";
  // One array's entries, four to a line.
  const auto list = [&](const auto& entries) {
    for (std::size_t k = 0; k < entries.size(); ++k) {
      char buf[64];
      const bool last = k + 1 == entries.size();
      std::snprintf(buf, sizeof buf, "{%a, %a}%s", double(entries[k].scale), double(entries[k].bias), last ? "" : ",");
      out += buf;
      out += (k + 1) % 4 == 0 ? "\n" : " ";
    }
  };
  list(table.e);
  out += "}}, {{\n";
  list(table.average);
  out += "}}}\n";
  return out;
}

namespace {

SpecularAlbedo lerp(const SpecularAlbedo& a, const SpecularAlbedo& b, float t) {
  return {a.scale + (b.scale - a.scale) * t, a.bias + (b.bias - a.bias) * t};
}

// Position of x ∈ [0, 1] on the table grid: cell index and fraction.
std::pair<int, float> grid(float x) {
  const float f = std::clamp(x, 0.0f, 1.0f) * float(kAlbedoTableSize - 1);
  const int i = std::min(static_cast<int>(f), kAlbedoTableSize - 2);
  return {i, f - float(i)};
}

}  // namespace

SpecularAlbedo specular_albedo(float cos_nv, float alpha) {
  const AlbedoTable& t = albedo_table();
  const auto [j, tr] = grid(std::sqrt(std::clamp(alpha, 0.0f, 1.0f)));
  const auto [i, tm] = grid(cos_nv);
  auto at = [&](int jj, int ii) { return t.e[std::size_t(jj * kAlbedoTableSize + ii)]; };
  return lerp(lerp(at(j, i), at(j, i + 1), tm), lerp(at(j + 1, i), at(j + 1, i + 1), tm), tr);
}

SpecularAlbedo average_specular_albedo(float alpha) {
  const AlbedoTable& t = albedo_table();
  const auto [j, tr] = grid(std::sqrt(std::clamp(alpha, 0.0f, 1.0f)));
  return lerp(t.average[std::size_t(j)], t.average[std::size_t(j + 1)], tr);
}

float smith_g1(float cos_n, float alpha) {
  const float c = std::abs(cos_n);
  const float a2 = alpha * alpha;
  const float d = c + std::sqrt(a2 + (1.0f - a2) * c * c);
  return d > 0.0f ? 2.0f * c / d : 0.0f;
}

glm::vec3 sample_ggx_visible_normal(const glm::vec3& v_local, float alpha, glm::vec2 u) {
  return GgxVisibleNormalSampler(v_local, alpha)(u);
}

GgxVisibleNormalSampler::GgxVisibleNormalSampler(const glm::vec3& v_local, float alpha)
    : alpha_(std::max(alpha, kMinAlpha)) {
  // Stretch the view to the hemisphere configuration, sample the projected disc of visible
  // normals (denser on its side facing v), unstretch (Heitz 2018, "Sampling the GGX
  // Distribution of Visible Normals").
  vh_ = glm::normalize(glm::vec3(alpha_ * v_local.x, alpha_ * v_local.y, v_local.z));
  const float len2 = vh_.x * vh_.x + vh_.y * vh_.y;
  t1_ = len2 > 0.0f ? glm::vec3(-vh_.y, vh_.x, 0.0f) / std::sqrt(len2) : glm::vec3(1.0f, 0.0f, 0.0f);
  t2_ = glm::cross(vh_, t1_);
  s_ = 0.5f * (1.0f + vh_.z);
}

glm::vec3 GgxVisibleNormalSampler::operator()(glm::vec2 u) const {
  const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  const float p2 = (1.0f - s_) * std::sqrt(std::max(1.0f - p1 * p1, 0.0f)) + s_ * r * std::sin(phi);
  const glm::vec3 nh = p1 * t1_ + p2 * t2_ + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh_;
  return glm::normalize(glm::vec3(alpha_ * nh.x, alpha_ * nh.y, std::max(nh.z, 0.0f)));
}

float ggx_sample_weight(float cos_nl, float cos_nv, float alpha) {
  if (cos_nl <= 0.0f || cos_nv <= 0.0f) return 0.0f;
  return ggx_sample_weight(cos_nl, cos_nv, alpha, smith_g1(cos_nv, std::max(alpha, kMinAlpha)));
}

float ggx_sample_weight(float cos_nl, float cos_nv, float alpha, float g1) {
  if (cos_nl <= 0.0f || cos_nv <= 0.0f) return 0.0f;
  alpha = std::max(alpha, kMinAlpha);
  const float g2 = 4.0f * cos_nl * cos_nv * smith_visibility_height_correlated(cos_nl, cos_nv, alpha);
  return g1 > 0.0f ? g2 / g1 : 0.0f;
}

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

BrdfAtView brdf_at_view(const BrdfParams& p, const glm::vec3& n, const glm::vec3& v) {
  BrdfAtView a;
  a.base_color = p.base_color;
  a.cos_nv = std::max(glm::dot(n, v), 0.0f);
  const float metallic = std::clamp(p.metallic, 0.0f, 1.0f);
  a.alpha = std::max(p.alpha, kMinAlpha);
  a.diffuse_weight = (1.0f - metallic) * (1.0f - std::clamp(p.transmission, 0.0f, 1.0f));
  a.dielectric_f0 = p.dielectric_f0;
  // The coupled diffuse weight's factors that do not depend on the light (gltf_brdf below).
  const SpecularAlbedo at_view = specular_albedo(a.cos_nv, a.alpha);
  a.scale_at_view = at_view.scale;
  a.bias_at_view = at_view.bias;
  a.one_minus_e_v = 1.0f - at_view(p.dielectric_f0);
  a.one_minus_e_avg = std::max(1.0f - average_specular_albedo(a.alpha)(p.dielectric_f0), 1e-6f);
  // smith_visibility_height_correlated's root at the viewer (its alpha is already ≥ kMinAlpha).
  const float nv = std::abs(a.cos_nv), a2 = a.alpha * a.alpha;
  a.smith_view_root = std::sqrt(nv * nv * (1.0f - a2) + a2);
  a.f0 = glm::vec3(p.dielectric_f0) * (1.0f - metallic) + p.base_color * metallic;
  return a;
}

BrdfValue gltf_brdf(const BrdfAtView& a, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v) {
  BrdfValue out;
  const float cos_nl = glm::dot(n, l);
  if (cos_nl <= 0.0f) return out;
  const glm::vec3 sum = l + v;
  const float sum2 = glm::dot(sum, sum);
  // l = −v cannot happen with both above the surface except at the horizon; H = N there.
  const glm::vec3 h = sum2 > 1e-12f ? sum / std::sqrt(sum2) : n;
  const float cos_vh = std::clamp(glm::dot(v, h), 0.0f, 1.0f);

  // The dielectric's coupled diffuse weight (1 − E(N·V))(1 − E(N·L)) / (1 − E_avg) (brdf.h).
  const float e_l = specular_albedo(cos_nl, a.alpha)(a.dielectric_f0);
  const float coupled = a.one_minus_e_v * (1.0f - e_l) / a.one_minus_e_avg;
  out.diffuse = a.base_color * (a.diffuse_weight * coupled / kPi);

  const float cos_nh = glm::dot(n, h);
  if (cos_nh <= 0.0f) return out;
  const glm::vec3 nxh = glm::cross(n, h);
  const float d = ggx_from_cos_sin(cos_nh * cos_nh, glm::dot(nxh, nxh), a.alpha);
  // smith_visibility_height_correlated with the viewer's root computed once.
  const float nl = std::abs(cos_nl), nv = std::abs(a.cos_nv);
  const float a2 = a.alpha * a.alpha;
  const float gv = nl * a.smith_view_root;
  const float gl = nv * std::sqrt(nl * nl * (1.0f - a2) + a2);
  const float denom = gv + gl;
  const float vis = denom > 0.0f ? 0.5f / denom : 0.0f;
  out.specular = fresnel_schlick(cos_vh, a.f0) * (d * vis);
  return out;
}

BrdfValue gltf_brdf(const BrdfParams& p, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v) {
  if (glm::dot(n, l) <= 0.0f) return {};
  return gltf_brdf(brdf_at_view(p, n, v), n, l, v);
}

}  // namespace speculum
