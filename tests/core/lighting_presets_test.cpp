// core/lighting_presets.h: the equirect direction inverts equirect_uv, a rotated map is the
// original turned about +Y, the clear sky's sun carries exactly its stated irradiance, the
// studio environment is its formula, and the key light comes from the camera's upper left.
#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "core/lighting_presets.h"
#include "core/sampling.h"
#include "core/shading.h"

namespace speculum {
namespace {

TEST(LightingPresets, EquirectDirectionInvertsEquirectUv) {
  for (float u : {0.03f, 0.25f, 0.5f, 0.71f, 0.97f})
    for (float v : {0.05f, 0.3f, 0.5f, 0.8f, 0.95f}) {
      const glm::vec3 d = equirect_direction(u, v);
      EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
      const glm::vec2 uv = equirect_uv(d);
      EXPECT_NEAR(uv.x, u, 1e-5f) << u << " " << v;
      EXPECT_NEAR(uv.y, v, 1e-5f) << u << " " << v;
    }
}

// The rotated map seen towards R_y(θ)·d is the original seen towards d. At a whole number
// of pixels and at pixel centres the bilinear lookups are exact, so the equality is too.
TEST(LightingPresets, RotateEquirectTurnsAboutPlusY) {
  Environment env;
  env.equirect = ImageRGBA(64, 32);
  // Smooth and periodic in x, so lookups a rounding error off a pixel centre stay close.
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      env.equirect.at(x, y) = glm::vec4(2.0f + std::sin(2.0f * kPi * x / 64.0f),
                                        2.0f + std::cos(6.0f * kPi * x / 64.0f) + 0.1f * y,
                                        0.5f * y, 1.0f);
  for (float degrees : {90.0f, -45.0f, 360.0f + 22.5f}) {
    SCOPED_TRACE(degrees);
    Environment turned = env;
    turned.equirect = rotate_equirect(env.equirect, degrees);
    const float t = degrees * kPi / 180.0f;
    for (int y = 2; y < 30; y += 3)
      for (int x = 0; x < 64; x += 5) {
        const glm::vec3 d = equirect_direction((x + 0.5f) / 64.0f, (y + 0.5f) / 32.0f);
        const glm::vec3 r(std::cos(t) * d.x + std::sin(t) * d.z, d.y, -std::sin(t) * d.x + std::cos(t) * d.z);
        const glm::vec3 a = environment_radiance(turned, r), b = environment_radiance(env, d);
        EXPECT_NEAR(a.x, b.x, 2e-3f) << x << "," << y;
        EXPECT_NEAR(a.y, b.y, 2e-3f) << x << "," << y;
        EXPECT_NEAR(a.z, b.z, 2e-3f) << x << "," << y;
      }
  }
}

TEST(LightingPresets, ClearSkySunCarriesItsIrradianceAndTheSkyFollowsCie) {
  const glm::vec3 sun = default_sky_sun();
  EXPECT_NEAR(std::asin(sun.y) * 180.0f / kPi, 40.0f, 1e-3f);
  const int w = 512, h = 256;
  const ImageRGBA sky = clear_sky_equirect(w, h, sun);
  const float disk_cos = std::cos(kSkySunRadiusDegrees * kPi / 180.0f);
  double disk_energy = 0.0, brightest = 0.0;
  glm::vec3 brightest_dir(0.0f);
  for (int y = 0; y < h; ++y) {
    const double omega = 2.0 * kPi / w * (std::cos(kPi * y / h) - std::cos(kPi * (y + 1) / h));
    for (int x = 0; x < w; ++x) {
      const glm::vec3 d = equirect_direction((x + 0.5f) / w, (y + 0.5f) / h);
      const glm::vec4 p = sky.at(x, y);
      EXPECT_TRUE(std::isfinite(p.x) && p.x >= 0.0f && p.y >= 0.0f && p.z >= 0.0f);
      if (glm::dot(d, sun) >= disk_cos) disk_energy += p.y * omega;
      if (p.y > brightest) brightest = p.y, brightest_dir = d;
    }
  }
  // The disk's pixels hold exactly 3.0; the sky under the disk adds well under 1 %.
  EXPECT_NEAR(disk_energy, kSkySunIrradiance, 0.03);
  EXPECT_GT(glm::dot(brightest_dir, sun), disk_cos);
  // CIE clear sky: the zenith (sun 50° away) is darker than the horizon opposite the sun
  // only by the gradation, and the sky is brightest around the sun.
  const glm::vec3 zenith = glm::vec3(environment_radiance(Environment{{}, sky, "", 1.0f}, {0, 1, 0}));
  const glm::vec3 near_sun =
      environment_radiance(Environment{{}, sky, "", 1.0f}, glm::normalize(sun + glm::vec3(0, 0.12f, 0)));
  EXPECT_NEAR(zenith.z, 0.25f, 0.01f);  // zenith radiance 0.25, blue channel untinted
  EXPECT_GT(near_sun.y, 2.0f * zenith.y);
  // Below the horizon: the constant ground.
  const glm::vec3 ground = environment_radiance(Environment{{}, sky, "", 1.0f}, {0.3f, -0.8f, 0.2f});
  EXPECT_NEAR(ground.x, 0.10f, 1e-6f);
}

TEST(LightingPresets, StudioEnvironmentIsItsFormulaAndTheKeyLightComesFromUpperLeft) {
  const Environment env = studio_environment();
  ASSERT_TRUE(env.has_image());
  for (int y = 0; y < env.equirect.height; ++y) {
    const glm::vec3 d = equirect_direction(0.5f / env.equirect.width, (y + 0.5f) / env.equirect.height);
    EXPECT_NEAR(env.equirect.at(3, y).x, 0.5f + 0.3f * d.y, 1e-6f);
  }
  Camera cam;
  cam.eye = {3, 1, 4};
  cam.target = {0, 0.5f, 0};
  const Light key = studio_key_light(cam);
  EXPECT_EQ(key.type, LightType::Directional);
  EXPECT_EQ(key.intensity, kStudioKeyIrradiance);
  const glm::vec3 toward = -key.direction;
  const glm::vec3 back = glm::normalize(cam.eye - cam.target);
  const glm::vec3 right = glm::normalize(glm::cross(-back, glm::vec3(0, 1, 0)));
  EXPECT_NEAR(glm::length(toward), 1.0f, 1e-6f);
  EXPECT_LT(glm::dot(toward, right), -0.3f);  // from the left
  EXPECT_GT(toward.y, 0.5f);                  // from above
  EXPECT_GT(glm::dot(toward, back), 0.3f);    // from behind the camera: the front is lit
  // Looking straight down still gives a valid light.
  cam.eye = {0, 5, 0};
  cam.target = {0, 0, 0};
  cam.up = {0, 0, -1};
  const Light down = studio_key_light(cam);
  EXPECT_NEAR(glm::length(down.direction), 1.0f, 1e-5f);
}

TEST(LightingPresets, UnlitMeansNoLightAndABlackEnvironment) {
  Scene s;
  EXPECT_TRUE(scene_is_unlit(s));
  s.environment.constant = glm::vec3(0.0f, 0.01f, 0.0f);
  EXPECT_FALSE(scene_is_unlit(s));
  s.environment.intensity = 0.0f;
  EXPECT_TRUE(scene_is_unlit(s));
  s.environment.intensity = 1.0f;
  s.environment.equirect = ImageRGBA(4, 2);  // an all-black image
  EXPECT_TRUE(scene_is_unlit(s));
  s.environment.equirect.at(3, 1) = glm::vec4(0.0f, 0.0f, 1.0f, 1.0f);
  EXPECT_FALSE(scene_is_unlit(s));
  s.environment = Environment{};
  s.lights.push_back(Light{});
  EXPECT_FALSE(scene_is_unlit(s));
  add_studio_light(s, Camera{});
  EXPECT_EQ(s.lights.size(), 2u);
  EXPECT_FALSE(environment_is_black(s.environment));
}

}  // namespace
}  // namespace speculum
