// The glTF 2.0 metallic-roughness BRDF (core/brdf.h) and the direct-light shading built on
// it (core/shading.h): reciprocity, a white-furnace energy bound, continuity across the
// curve R·L = 0 where the old Phong highlight of exponent 0 had a step, the spec's
// smooth limit, metal tinting and the single (1 - transmission) factor; and the forms that
// compute a point's viewer terms and a light's constants once (BrdfAtView, LightSampler)
// against the formulas written out per call, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/brdf.h"
#include "core/optics.h"
#include "core/sampling.h"
#include "core/shading.h"

namespace speculum {
namespace {

const glm::vec3 kUp(0.0f, 0.0f, 1.0f);

glm::vec3 view_at(float theta) { return {std::sin(theta), 0.0f, std::cos(theta)}; }

BrdfParams params(float roughness, float metallic, glm::vec3 base = glm::vec3(1.0f)) {
  BrdfParams p;
  p.base_color = base;
  p.metallic = metallic;
  p.alpha = roughness * roughness;
  p.dielectric_f0 = fresnel_f0(1.5f);
  return p;
}

TEST(GltfBrdf, Reciprocal) {
  for (std::uint32_t i = 0; i < 2000; ++i) {
    const glm::vec3 l = sample_cosine_hemisphere(random_float2(i, 0, 0, 7));
    const glm::vec3 v = sample_cosine_hemisphere(random_float2(i, 0, 1, 7));
    const glm::vec2 m = random_float2(i, 0, 2, 7);
    const glm::vec2 c = random_float2(i, 0, 3, 7);
    BrdfParams p = params(0.03f + 0.97f * m.x, m.y, glm::vec3(c.x, c.y, 0.5f));
    p.transmission = random_float(i, 0, 4, 7);
    p.dielectric_f0 = fresnel_f0(1.0f + random_float(i, 0, 5, 7));
    const glm::vec3 a = gltf_brdf(p, kUp, l, v).total();
    const glm::vec3 b = gltf_brdf(p, kUp, v, l).total();
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k], b[k], 1e-5f * std::max(1.0f, a[k])) << i;
  }
}

// ∫ f(l, v) cos θ_l dω_l for a constant unit environment, by deterministic midpoint
// quadrature. The diffuse lobe is integrated under cosine-weighted coordinates (its
// integrand is then (1 − F) c, smooth); the specular lobe in half-vector coordinates
// θ_h = atan(α √(u/(1−u))), whose density p(h) = α² cos θ_h / (π ((α²−1) cos² θ_h + 1)²)
// (written here independently of core/brdf.cpp) makes f cos θ_l / (p(h) / (4 V·H)) smooth
// even for narrow lobes; half-vectors whose mirror l falls under the horizon count 0.
struct Albedo {
  double diffuse = 0.0, specular = 0.0;
  double total() const { return diffuse + specular; }
};
Albedo directional_albedo(const BrdfParams& p, const glm::vec3& v, int n_theta, int n_phi) {
  Albedo out;
  const double a2 = double(p.alpha) * double(p.alpha);
  for (int i = 0; i < n_theta; ++i) {
    for (int j = 0; j < n_phi; ++j) {
      const float u1 = (i + 0.5f) / n_theta, u2 = (j + 0.5f) / n_phi;
      const double w = 1.0 / (double(n_theta) * n_phi);
      // Diffuse: cosine-weighted l, pdf cos/π.
      const glm::vec3 l = sample_cosine_hemisphere({u1, u2});
      out.diffuse += w * double(gltf_brdf(p, kUp, l, v).diffuse.x) * kPi;
      // Specular: half-vector coordinates.
      const double t = std::atan(double(p.alpha) * std::sqrt(u1 / (1.0 - u1)));
      const glm::vec3 h = spherical_local(static_cast<float>(std::cos(t)), u2);
      const float vh = glm::dot(v, h);
      if (vh <= 0.0f) continue;
      const glm::vec3 lh = 2.0f * vh * h - v;
      if (lh.z <= 0.0f) continue;
      const double ch = std::cos(t);
      const double den = (a2 - 1.0) * ch * ch + 1.0;
      const double pdf_h = a2 * ch / (kPi * den * den);
      const double pdf_l = pdf_h / (4.0 * vh);
      out.specular += w * double(gltf_brdf(p, kUp, glm::normalize(lh), v).specular.x) * lh.z / pdf_l;
    }
  }
  return out;
}

// White furnace. The microfacet layer (specular_brdf × Schlick F ≤ 1, single scattering)
// and a white metal must never reflect more than they receive, at any view angle, and the
// coupled diffuse (core/brdf.h) makes a white dielectric reflect exactly what it receives:
// its Lambert lobe returns 1 − E(N·V) and its specular layer E(N·V).
TEST(GltfBrdf, WhiteFurnaceNeverGainsEnergyAndWhiteDielectricConserves) {
  for (float roughness : {0.05f, 0.1f, 0.25f, 0.5f, 0.75f, 1.0f}) {
    for (float metallic : {0.0f, 0.5f, 1.0f}) {
      for (float theta_v : {0.0f, 0.5f, 1.0f, 1.3f, 1.5f}) {
        const Albedo a = directional_albedo(params(roughness, metallic), view_at(theta_v), 400, 64);
        SCOPED_TRACE(::testing::Message() << "r " << roughness << " m " << metallic << " θv " << theta_v
                                          << " diffuse " << a.diffuse << " specular " << a.specular);
        EXPECT_LE(a.specular, 1.0 + 2e-3);
        EXPECT_LE(a.diffuse, 1.0);
        EXPECT_LE(a.total(), 1.0 + 4e-3);
        if (metallic == 1.0f) {
          EXPECT_EQ(a.diffuse, 0.0);
        }
        if (metallic == 0.0f) {
          EXPECT_NEAR(a.total(), 1.0, 6e-3);
        }
        // Not vacuous: single-scattering GGX loses energy only to masking, which is small
        // for a smooth lobe away from grazing.
        if (metallic == 1.0f && roughness <= 0.1f && theta_v <= 1.0f) {
          EXPECT_GT(a.total(), 0.95);
        }
      }
    }
  }
}

// The split-sum albedo table (built by sampling visible normals) against the independent
// half-vector quadrature above, for F0 = 0 (bias alone) and F0 = 1 (scale + bias), across
// view angles and roughness, including points between the table's nodes.
TEST(SpecularAlbedo, MatchesQuadratureOfTheBrdf) {
  for (float roughness : {0.05f, 0.13f, 0.3f, 0.55f, 0.8f, 1.0f}) {
    for (float theta_v : {0.0f, 0.4f, 0.9f, 1.2f, 1.45f}) {
      const float mu = std::cos(theta_v);
      const SpecularAlbedo e = specular_albedo(mu, roughness * roughness);
      for (float f0 : {0.0f, 0.04f, 1.0f}) {
        BrdfParams p = params(roughness, 1.0f, glm::vec3(f0));
        const Albedo a = directional_albedo(p, view_at(theta_v), 400, 64);
        EXPECT_NEAR(e(f0), a.specular, 4e-3 + 0.01 * a.specular)
            << "r " << roughness << " θv " << theta_v << " f0 " << f0;
      }
    }
  }
  // The smooth limit is Schlick at N·V: exact at the table's nodes, linear in μ between them.
  EXPECT_NEAR(specular_albedo(10.0f / 31.0f, 0.0f)(0.04f), fresnel_schlick(10.0f / 31.0f, 0.04f), 1e-6f);
  EXPECT_NEAR(specular_albedo(0.3f, 0.0f)(0.04f), fresnel_schlick(0.3f, 0.04f), 1e-3f);
}

// Visible normals face the viewer and the surface; their estimator F G2/G1 never exceeds 1.
TEST(SpecularAlbedo, VisibleNormalSamplesAreValid) {
  for (float roughness : {0.05f, 0.3f, 1.0f}) {
    const float alpha = roughness * roughness;
    for (float theta_v : {0.0f, 0.7f, 1.5f}) {
      const glm::vec3 v = view_at(theta_v);
      for (std::uint32_t k = 0; k < 256; ++k) {
        const glm::vec3 h = sample_ggx_visible_normal(v, alpha, hamersley(k, 256));
        EXPECT_NEAR(glm::length(h), 1.0f, 1e-4f);
        EXPECT_GE(h.z, 0.0f);
        EXPECT_GE(glm::dot(v, h), -1e-5f);
        const glm::vec3 l = 2.0f * glm::dot(v, h) * h - v;
        const float w = ggx_sample_weight(l.z, v.z, alpha);
        EXPECT_GE(w, 0.0f);
        EXPECT_LE(w, 1.0f + 1e-5f);
      }
    }
  }
}

// The lobe sampler that keeps what one surface point and viewer share gives, for every u,
// the bits of the whole computation written out per sample (the oracle below: the frame,
// the stretched view, the disc sample, reflection and F G2/G1 all evaluated afresh).
LobeSample lobe_sample_written_out(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v, glm::vec2 u) {
  const float alpha = std::max(s.roughness * s.roughness, kMinAlpha);
  const Onb frame(n);
  const glm::vec3 vl(glm::dot(v, frame.t), glm::dot(v, frame.b), glm::dot(v, n));
  if (!(vl.z > 0.0f)) return {};
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * vl.x, alpha * vl.y, vl.z));
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = len2 > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x), phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  const float sw = 0.5f * (1.0f + vh.z);
  const float p2 = (1.0f - sw) * std::sqrt(std::max(1.0f - p1 * p1, 0.0f)) + sw * r * std::sin(phi);
  const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  const glm::vec3 h = frame.to_world(glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(nh.z, 0.0f))));
  const float cos_vh = glm::dot(v, h);
  const glm::vec3 wi = glm::normalize(2.0f * cos_vh * h - v);
  const float cos_nl = glm::dot(wi, n);
  if (cos_nl <= 0.0f) return {};
  const float g2 = 4.0f * cos_nl * vl.z * smith_visibility_height_correlated(cos_nl, vl.z, alpha);
  const float g1 = smith_g1(vl.z, alpha);
  const float w = g1 > 0.0f ? g2 / g1 : 0.0f;
  if (!(w > 0.0f)) return {};
  return {wi, fresnel_schlick(std::clamp(cos_vh, 0.0f, 1.0f), specular_f0(s)) * w};
}

TEST(SpecularLobe, SamplerGivesTheBitsOfTheWrittenOutSample) {
  std::uint32_t state = 12345u;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24);
  };
  std::size_t below = 0, compared = 0;
  for (int trial = 0; trial < 300; ++trial) {
    SurfaceParams s;
    s.roughness = trial % 7 == 0 ? 0.0f : next();
    s.metallic = next();
    s.base_color = {next(), next(), next()};
    const glm::vec3 n = glm::normalize(glm::vec3(next() - 0.5f, next() - 0.5f, next() - 0.5f));
    const glm::vec3 v = glm::normalize(glm::vec3(next() - 0.5f, next() - 0.5f, next() - 0.5f));
    const SpecularLobeSampler sampler(s, n, v);
    for (int k = 0; k < 16; ++k) {
      const glm::vec2 u(next(), next());
      const LobeSample a = sampler(u), b = lobe_sample_written_out(s, n, v, u), c = sample_specular_lobe(s, n, v, u);
      below += b.weight == glm::vec3(0.0f);
      ++compared;
      ASSERT_EQ(0, std::memcmp(&a, &b, sizeof(LobeSample))) << "trial " << trial << " sample " << k;
      ASSERT_EQ(0, std::memcmp(&c, &b, sizeof(LobeSample))) << "trial " << trial << " sample " << k;
    }
  }
  EXPECT_GT(below, compared / 4);  // viewers below the surface and samples below it occur
  EXPECT_LT(below, compared * 3 / 4);
}

// The spec's limit α → 0: the specular lobe gathers in a small cone about the mirror
// direction R, and its integral there is the Schlick Fresnel at N·V (H → N), tinted by
// base_color for a metal, while a metal has no diffuse lobe at all.
TEST(GltfBrdf, SmoothLimitIsSchlickAtTheMirrorDirection) {
  const glm::vec3 v = view_at(1.0f);
  const glm::vec3 r = reflect(-v, kUp);
  const Onb frame(r);
  const float cone = 0.1f;  // radians; a roughness-0.05 lobe is ~0.005 wide
  const glm::vec3 gold(1.0f, 0.75f, 0.3f);
  for (float metallic : {0.0f, 1.0f}) {
    const BrdfParams p = params(0.05f, metallic, gold);
    glm::dvec3 integral(0.0);
    const int n_theta = 4000, n_phi = 128;
    for (int i = 0; i < n_theta; ++i) {
      const double t = cone * (i + 0.5) / n_theta;
      for (int j = 0; j < n_phi; ++j) {
        const glm::vec3 l = frame.to_world(spherical_local(static_cast<float>(std::cos(t)), (j + 0.5f) / n_phi));
        const BrdfValue f = gltf_brdf(p, kUp, l, v);
        if (metallic == 1.0f) {
          ASSERT_EQ(f.diffuse, glm::vec3(0.0f));
        }
        const double dw = std::sin(t) * (cone / n_theta) * (2.0 * kPi / n_phi);
        integral += glm::dvec3(f.specular) * double(l.z) * dw;
      }
    }
    const glm::vec3 f0 = metallic == 1.0f ? gold : glm::vec3(fresnel_f0(1.5f));
    const glm::vec3 expected = fresnel_schlick(glm::dot(kUp, v), f0);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(integral[k], expected[k], 0.02 * expected[k]) << metallic << " " << k;
  }
}

// shade_light on a rough white surface as the light sweeps through R·L = 0 (at θ_l = 30°
// for a viewer at 60°): adjacent samples 0.1° apart differ by far less than the old
// model's jump there, F(N·V) E / (2π) (Phong exponent 0: the lobe switched on at R·L = 0).
TEST(ShadeLight, ContinuousAcrossTheOldHighlightEdge) {
  SurfaceParams s;
  s.roughness = 1.0f;
  s.metallic = 0.0f;
  const float theta_v = glm::radians(60.0f);
  const glm::vec3 v = view_at(theta_v);
  LightSample ls;
  ls.irradiance = glm::vec3(1.0f);
  const float old_jump = fresnel_schlick(std::cos(theta_v), 0.04f) / (2.0f * kPi);
  float max_step = 0.0f;
  glm::vec3 previous(0.0f);
  for (int i = 0; i <= 600; ++i) {
    const float theta_l = glm::radians(0.1f * i);  // light in the view plane, opposite side
    ls.direction = glm::vec3(-std::sin(theta_l), 0.0f, std::cos(theta_l));
    const glm::vec3 c = shade_light(s, kUp, v, ls);
    if (i > 0) max_step = std::max(max_step, std::abs(c.x - previous.x));
    previous = c;
  }
  EXPECT_GT(old_jump, 0.01f);
  EXPECT_LT(max_step, old_jump / 10.0f);
}

// KHR_materials_transmission replaces only the diffuse lobe: the lamp-lit diffuse of a
// partly transmissive surface is (1 − t) times the opaque one — once — and the specular
// highlight is the same for any t (a fully transmissive rough dielectric still has it).
TEST(ShadeLight, TransmissionScalesTheDiffuseOnce) {
  SurfaceParams s;
  s.roughness = 0.5f;
  s.metallic = 0.0f;
  s.base_color = glm::vec3(0.8f, 0.6f, 0.4f);
  LightSample ls;
  ls.direction = glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f));
  ls.irradiance = glm::vec3(2.0f);
  const glm::vec3 v = glm::normalize(glm::vec3(-0.5f, 0.2f, 1.0f));
  auto shade = [&](float t) {
    SurfaceParams q = s;
    q.transmission = t;
    return shade_light(q, kUp, v, ls);
  };
  const glm::vec3 specular_only = shade(1.0f), opaque = shade(0.0f), partial = shade(0.75f);
  const glm::vec3 expected_specular = gltf_brdf(brdf_params_for_punctual_light(s), kUp, ls.direction, v).specular *
                                      (ls.direction.z * 2.0f);
  for (int k = 0; k < 3; ++k) {
    EXPECT_GT(specular_only[k], 0.0f);
    EXPECT_NEAR(specular_only[k], expected_specular[k], 1e-6f);
    EXPECT_NEAR(partial[k] - specular_only[k], 0.25f * (opaque[k] - specular_only[k]), 1e-5f);
  }
  // The environment-diffuse weight follows the same rule.
  SurfaceParams partial_s = s;
  partial_s.transmission = 0.75f;
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(diffuse_albedo_over_pi(partial_s, 0.7f)[k], 0.25f * diffuse_albedo_over_pi(s, 0.7f)[k], 1e-6f);
}

// Mirror-class surfaces keep the diffuse but add no highlight (see core/shading.h); just
// above the class, the highlight peak is finite thanks to kMinPunctualRoughness.
TEST(ShadeLight, MirrorClassHasNoPunctualHighlightAndGlossyPeakIsFinite) {
  SurfaceParams s;
  s.metallic = 1.0f;
  s.base_color = glm::vec3(0.9f);
  const glm::vec3 v = view_at(0.4f);
  LightSample ls;
  ls.direction = reflect(-v, kUp);
  ls.irradiance = glm::vec3(1.0f);
  s.roughness = kMirrorRoughness;
  EXPECT_EQ(shade_light(s, kUp, v, ls), glm::vec3(0.0f));
  s.roughness = kMirrorRoughness + 1e-3f;
  const glm::vec3 peak = shade_light(s, kUp, v, ls);
  EXPECT_TRUE(std::isfinite(peak.x));
  // At the mirror direction f cos = F D V cos with D = 1/(π α²), V = 1/(4 N·L N·V) (masking
  // ≈ 1 for so narrow a lobe): F / (4 π α² N·V) with α = kMinPunctualRoughness².
  const float a = kMinPunctualRoughness * kMinPunctualRoughness;
  const float expected = fresnel_schlick(std::cos(0.4f), 0.9f) / (4.0f * kPi * a * a * std::cos(0.4f));
  EXPECT_NEAR(peak.x, expected, 0.01f * expected);
}

// gltf_brdf written out per call (every term recomputed for each light), the formula
// BrdfAtView factors: its bits are what the factored form must give.
BrdfValue per_call_gltf_brdf(const BrdfParams& p, const glm::vec3& n, const glm::vec3& l, const glm::vec3& v) {
  BrdfValue out;
  const float cos_nl = glm::dot(n, l);
  if (cos_nl <= 0.0f) return out;
  const float cos_nv = std::max(glm::dot(n, v), 0.0f);
  const glm::vec3 sum = l + v;
  const float sum2 = glm::dot(sum, sum);
  const glm::vec3 h = sum2 > 1e-12f ? sum / std::sqrt(sum2) : n;
  const float cos_vh = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
  const float metallic = std::clamp(p.metallic, 0.0f, 1.0f);
  const float alpha = std::max(p.alpha, 1e-4f);
  const float e_v = specular_albedo(cos_nv, alpha)(p.dielectric_f0);
  const float e_l = specular_albedo(cos_nl, alpha)(p.dielectric_f0);
  const float e_avg = average_specular_albedo(alpha)(p.dielectric_f0);
  const float coupled = (1.0f - e_v) * (1.0f - e_l) / std::max(1.0f - e_avg, 1e-6f);
  out.diffuse = p.base_color * ((1.0f - metallic) * (1.0f - std::clamp(p.transmission, 0.0f, 1.0f)) * coupled / kPi);
  const float cos_nh = glm::dot(n, h);
  if (cos_nh <= 0.0f) return out;
  const glm::vec3 nxh = glm::cross(n, h);
  const float a2 = alpha * alpha;
  const float dd = cos_nh * cos_nh * a2 + glm::dot(nxh, nxh);
  const float d = a2 / (kPi * dd * dd);
  const float vis = smith_visibility_height_correlated(cos_nl, cos_nv, alpha);
  const glm::vec3 f0 = glm::vec3(p.dielectric_f0) * (1.0f - metallic) + p.base_color * metallic;
  out.specular = fresnel_schlick(cos_vh, f0) * (d * vis);
  return out;
}

// A unit direction from two uniform numbers (uniform on the sphere).
glm::vec3 random_direction(glm::vec2 u) { return spherical_local(1.0f - 2.0f * u.x, u.y); }

TEST(GltfBrdf, ViewTermsGiveTheBitsOfThePerCallFormula) {
  std::size_t lit = 0, highlights = 0;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    SurfaceParams s;
    const glm::vec2 a = random_float2(i, 0, 0, 11), b = random_float2(i, 0, 2, 11);
    s.roughness = i % 7 == 0 ? 0.0f : a.x;  // mirror-class surfaces too
    s.metallic = a.y;
    s.transmission = i % 5 == 0 ? b.x : 0.0f;
    s.ior = 1.0f + b.y;
    s.base_color = glm::vec3(a.x, b.x, 1.0f - a.y);
    const BrdfParams p = brdf_params_for_punctual_light(s);
    const glm::vec3 n = random_direction(random_float2(i, 0, 4, 11));
    const glm::vec3 l = random_direction(random_float2(i, 0, 6, 11));
    // Viewers on both sides of the surface (N·V < 0 is clamped alike).
    const glm::vec3 v = random_direction(random_float2(i, 0, 8, 11));
    const BrdfAtView view = brdf_at_view(p, n, v);
    const BrdfValue expected = per_call_gltf_brdf(p, n, l, v);
    const BrdfValue factored = gltf_brdf(view, n, l, v), unfactored = gltf_brdf(p, n, l, v);
    ASSERT_EQ(factored.diffuse, expected.diffuse) << i;
    ASSERT_EQ(factored.specular, expected.specular) << i;
    ASSERT_EQ(unfactored.diffuse, expected.diffuse) << i;
    ASSERT_EQ(unfactored.specular, expected.specular) << i;
    lit += expected.diffuse != glm::vec3(0.0f);
    highlights += expected.specular != glm::vec3(0.0f);

    LightSample ls;
    ls.direction = l;
    ls.irradiance = glm::vec3(1.0f, 2.0f, 0.5f);
    ASSERT_EQ(shade_light(s, view, n, v, ls), shade_light(s, n, v, ls)) << i;
    ASSERT_EQ(diffuse_albedo_over_pi(s, view), diffuse_albedo_over_pi(s, glm::dot(n, v))) << i;
  }
  EXPECT_GT(lit, 8000u);
  EXPECT_GT(highlights, 5000u);
}

// The albedo table in core/albedo_table.inc is the quadrature's, bit for bit: the file is
// what albedo_table_source prints. On a mismatch the right file is written beside the test
// binary's working directory, to be copied over core/albedo_table.inc.
TEST(AlbedoTable, StoredTableIsTheQuadratures) {
  const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
  const AlbedoTable computed = albedo_table_by_quadrature();
  const AlbedoTable& stored = albedo_table();
  const auto expect_same = [&](const auto& want, const auto& got, const char* what) {
    for (std::size_t k = 0; k < want.size(); ++k) {
      EXPECT_EQ(bits(want[k].scale), bits(got[k].scale)) << what << " " << k;
      EXPECT_EQ(bits(want[k].bias), bits(got[k].bias)) << what << " " << k;
    }
  };
  expect_same(computed.e, stored.e, "entry");
  expect_same(computed.average, stored.average, "average");
  if (HasFailure()) std::ofstream("albedo_table.inc.new") << albedo_table_source(computed);
}

// sample_light written out per call (the light's direction and cone cosines recomputed at
// every point), the formula LightSampler factors.
LightSample per_call_sample_light(const Light& light, const glm::vec3& position) {
  LightSample out;
  if (light.type == LightType::Directional) {
    out.direction = -glm::normalize(light.direction);
    out.distance = std::numeric_limits<float>::infinity();
    out.irradiance = light.color * light.intensity;
    return out;
  }
  const glm::vec3 to_light = light.position - position;
  const float d2 = glm::dot(to_light, to_light);
  if (!(d2 > 0.0f)) return out;
  const float d = std::sqrt(d2);
  out.direction = to_light / d;
  out.distance = d;
  float window = 1.0f;
  if (light.range > 0.0f) {
    const float r = d / light.range, r2 = r * r;
    window = std::clamp(1.0f - r2 * r2, 0.0f, 1.0f);
  }
  float cone = 1.0f;
  if (light.type == LightType::Spot) {
    const float cos_outer = std::cos(light.outer_cone), cos_inner = std::cos(light.inner_cone);
    const float scale = 1.0f / std::max(0.001f, cos_inner - cos_outer);
    const float a = std::clamp((glm::dot(glm::normalize(light.direction), -out.direction) - cos_outer) * scale, 0.0f, 1.0f);
    cone = a * a;
  }
  out.irradiance = light.color * (light.intensity * window * cone / d2);
  return out;
}

TEST(ShadeLight, LightSamplerGivesTheBitsOfThePerCallFormula) {
  std::vector<Light> lights(4);
  lights[0].type = LightType::Point;
  lights[0].position = {0.5f, 2.0f, -1.0f};
  lights[1] = lights[0];
  lights[1].range = 3.0f;
  lights[2].type = LightType::Spot;
  lights[2].position = {1.0f, 2.5f, 0.5f};
  lights[2].direction = {-0.4f, -1.0f, -0.3f};  // not unit: the sampler normalizes it
  lights[2].inner_cone = 0.2f;
  lights[2].outer_cone = 0.6f;
  lights[2].range = 6.0f;
  lights[3].type = LightType::Directional;
  lights[3].direction = {0.3f, -1.0f, 0.2f};
  std::size_t in_cone = 0;
  for (const Light& light : lights) {
    const LightSampler sampler(light);
    for (std::uint32_t i = 0; i < 5000; ++i) {
      const glm::vec3 p = light.position + 4.0f * random_direction(random_float2(i, 0, 0, 13)) *
                                               random_float(i, 0, 2, 13);
      const LightSample expected = per_call_sample_light(light, p), got = sampler(p);
      ASSERT_EQ(got.direction, expected.direction) << i;
      ASSERT_EQ(got.irradiance, expected.irradiance) << i;
      ASSERT_EQ(got.distance, expected.distance) << i;
      const LightSample via_function = sample_light(light, p);
      ASSERT_EQ(via_function.irradiance, expected.irradiance) << i;
      in_cone += light.type == LightType::Spot && expected.irradiance != glm::vec3(0.0f);
    }
  }
  EXPECT_GT(in_cone, 200u);
}

}  // namespace
}  // namespace speculum
