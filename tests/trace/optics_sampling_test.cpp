// Tests of the shared optics, sampling and shading pieces the trace helper wrote
// (core/optics.h, core/sampling.h, core/shading.h) against closed-form values.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/optics.h"
#include "core/sampling.h"
#include "core/shading.h"

namespace speculum {
namespace {

TEST(Optics, FresnelChecks) {
  EXPECT_NEAR(fresnel_f0(1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnel_schlick(1.0f, 0.04f), 0.04f, 1e-7f);
  EXPECT_NEAR(fresnel_schlick(0.0f, 0.04f), 1.0f, 1e-7f);
  // Exact Fresnel: normal incidence equals F0, grazing is 1, TIR beyond the critical angle.
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnel_dielectric(1e-4f, 1.5f), 1.0f, 1e-3f);
  const float critical = std::asin(1.0f / 1.5f);
  EXPECT_EQ(fresnel_dielectric(std::cos(critical + 0.01f), 1.0f / 1.5f), 1.0f);
  EXPECT_LT(fresnel_dielectric(std::cos(critical - 0.01f), 1.0f / 1.5f), 1.0f);
}

TEST(Optics, RefractObeysSnellAndDetectsTir) {
  const glm::vec3 n(0, 0, 1);
  for (float deg = 0; deg < 89.0f; deg += 7.0f) {
    const float a = glm::radians(deg);
    const glm::vec3 v(std::sin(a), 0.0f, -std::cos(a));
    glm::vec3 t;
    ASSERT_TRUE(refract(v, n, 1.5f, t));
    EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
    EXPECT_NEAR(std::sin(a), 1.5f * t.x, 1e-5f);  // Snell: sinθi = ν sinθt
    glm::vec3 same;
    ASSERT_TRUE(refract(v, n, 1.0f, same));  // ν = 1 is the identity
    EXPECT_NEAR(glm::length(same - v), 0.0f, 1e-6f);
    glm::vec3 out;
    const bool ok = refract(v, n, 1.0f / 1.5f, out);
    EXPECT_EQ(ok, std::sin(a) < 1.0f / 1.5f);
  }
  const glm::vec3 r = reflect(glm::normalize(glm::vec3(1, 0, -1)), n);
  EXPECT_NEAR(glm::length(r - glm::normalize(glm::vec3(1, 0, 1))), 0.0f, 1e-6f);
}

TEST(Sampling, HashRngIsUniformAndKeyed) {
  double sum = 0.0;
  int buckets[10] = {};
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const float u = random_float(static_cast<std::uint32_t>(i), 3, 1, 7);
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    sum += u;
    ++buckets[static_cast<int>(u * 10)];
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);
  for (int b : buckets) EXPECT_NEAR(b, n / 10, 400);
  EXPECT_NE(random_float(1, 2, 3, 4), random_float(1, 2, 3, 5));
  EXPECT_NE(random_float(1, 2, 3, 4), random_float(1, 2, 4, 4));
  EXPECT_EQ(random_float(1, 2, 3, 4), random_float(1, 2, 3, 4));
}

TEST(Sampling, HamersleyIsStratified) {
  // Every 1/n x 1 column and every elementary 1/2^k row band holds exactly n/2^k points.
  const std::uint32_t n = 64;
  int rows[8] = {};
  for (std::uint32_t i = 0; i < n; ++i) {
    const glm::vec2 p = hamersley(i, n);
    EXPECT_FLOAT_EQ(p.x, static_cast<float>(i) / n);
    ++rows[static_cast<int>(p.y * 8)];
  }
  for (int r : rows) EXPECT_EQ(r, 8);
}

TEST(Sampling, PhongLobeMatchesItsPdf) {
  // Monte-Carlo check: E[cosθ] under the sampled lobe equals (n+1)/(n+2) analytically.
  for (float e : {1.0f, 10.0f, 200.0f}) {
    double mean = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      const glm::vec3 d = sample_phong_lobe(random_float2(i, 0, 0, 1), e);
      ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
      mean += d.z;
    }
    EXPECT_NEAR(mean / n, (e + 1.0) / (e + 2.0), 0.01) << e;
    // pdf integrates to 1 over the hemisphere: ∫ (n+1)/(2π) cos^n 2π sinθ dθ = 1.
    double integral = 0.0;
    const int steps = 20000;
    for (int k = 0; k < steps; ++k) {
      const double th = (k + 0.5) * (kPi / 2) / steps;
      integral += phong_lobe_pdf(static_cast<float>(std::cos(th)), e) * 2 * kPi * std::sin(th) * (kPi / 2) / steps;
    }
    EXPECT_NEAR(integral, 1.0, 2e-3) << e;
  }
}

TEST(Sampling, OnbIsOrthonormal) {
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 n = sample_uniform_cone(random_float2(i, 0, 0, 9), -1.0f);
    const Onb b(n);
    EXPECT_NEAR(glm::dot(b.t, b.b), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(b.t, b.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(b.b, b.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(b.t), 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(b.to_world(glm::vec3(0, 0, 1)) - n), 0.0f, 1e-6f);
  }
}

TEST(Shading, EquirectRoundTripsAndLights) {
  // The inverse mapping: u = 0.5 + φ/2π with φ = atan2(x, -z), v = θ/π with cos θ = y.
  const auto equirect_direction = [](glm::vec2 uv) {
    const float phi = (uv.x - 0.5f) * 2.0f * kPi;
    const float theta = uv.y * kPi;
    const float st = std::sin(theta);
    return glm::vec3(st * std::sin(phi), std::cos(theta), -st * std::cos(phi));
  };
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 d = sample_uniform_cone(random_float2(i, 0, 0, 11), -1.0f);
    EXPECT_NEAR(glm::length(equirect_direction(equirect_uv(d)) - d), 0.0f, 1e-4f);
  }
  EXPECT_NEAR(equirect_uv(glm::vec3(0, 0, -1)).x, 0.5f, 1e-6f);
  EXPECT_NEAR(equirect_uv(glm::vec3(0, 1, 0)).y, 0.0f, 1e-6f);
  Light point;
  point.intensity = 8.0f;
  point.position = glm::vec3(0, 2, 0);
  const LightSample s = sample_light(point, glm::vec3(0));
  EXPECT_NEAR(s.irradiance.x, 2.0f, 1e-6f);  // I / d²
  Light spot = point;
  spot.type = LightType::Spot;
  spot.direction = glm::vec3(0, -1, 0);
  spot.inner_cone = 0.2f;
  spot.outer_cone = 0.4f;
  EXPECT_NEAR(sample_light(spot, glm::vec3(0)).irradiance.x, 2.0f, 1e-6f);
  EXPECT_EQ(sample_light(spot, glm::vec3(2, 0, 0)).irradiance.x, 0.0f);
  // A white Lambert surface under normal-incidence E reflects about E/π (minus Fresnel).
  SurfaceParams white;
  const glm::vec3 l = shade_light(white, glm::vec3(0, 1, 0), glm::vec3(0, 1, 0), s);
  EXPECT_GT(l.x, 2.0f * 0.9f / kPi);
  EXPECT_LT(l.x, 2.0f / kPi + 0.05f);
}

}  // namespace
}  // namespace speculum
