// Command-line environments and the default studio light: see lighting_presets.h.
#include "core/lighting_presets.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "core/sampling.h"
#include "core/shading.h"

namespace speculum {

bool environment_is_black(const Environment& env) {
  if (!(env.intensity > 0.0f)) return true;
  if (!env.has_image()) return !(env.constant.x > 0.0f || env.constant.y > 0.0f || env.constant.z > 0.0f);
  for (const glm::vec4& p : env.equirect.pixels)
    if (p.x > 0.0f || p.y > 0.0f || p.z > 0.0f) return false;
  return true;
}

bool scene_is_unlit(const Scene& scene) {
  return scene.lights.empty() && environment_is_black(scene.environment);
}

namespace {

// CIE S 011 clear sky (type 12) in Perez form: gradation φ(θ) and indicatrix f(γ).
constexpr float kA = -1.0f, kB = -0.32f, kC = 10.0f, kD = -3.0f, kE = 0.45f;
float gradation(float cos_theta) {
  return cos_theta > 0.0f ? 1.0f + kA * std::exp(kB / cos_theta) : 1.0f;
}
float indicatrix(float gamma) {
  const float c = std::cos(gamma);
  return 1.0f + kC * (std::exp(kD * gamma) - std::exp(kD * kPi * 0.5f)) + kE * c * c;
}

}  // namespace

glm::vec3 default_sky_sun() {
  const float elevation = 40.0f * kPi / 180.0f;
  return glm::normalize(glm::vec3(std::cos(elevation) * std::sqrt(0.5f), std::sin(elevation),
                                  std::cos(elevation) * std::sqrt(0.5f)));
}

ImageRGBA clear_sky_equirect(int width, int height, const glm::vec3& toward_sun) {
  const glm::vec3 sun = glm::normalize(toward_sun);
  const float sun_zenith = std::acos(std::clamp(sun.y, -1.0f, 1.0f));
  const float norm = 1.0f / (indicatrix(sun_zenith) * gradation(1.0f));
  const glm::vec3 zenith_tint(0.45f, 0.65f, 1.0f), horizon_tint(1.0f), ground(0.10f, 0.09f, 0.08f);
  constexpr float kZenithRadiance = 0.25f;
  const float disk_cos = std::cos(kSkySunRadiusDegrees * kPi / 180.0f);
  ImageRGBA img(width, height);
  std::vector<std::size_t> disk;
  double disk_solid_angle = 0.0;
  std::size_t nearest = 0;
  float nearest_cos = -2.0f;
  for (int y = 0; y < height; ++y) {
    const double row_solid_angle = equirect_pixel_solid_angle(y, width, height);
    for (int x = 0; x < width; ++x) {
      const glm::vec3 d = equirect_direction((x + 0.5f) / width, (y + 0.5f) / height);
      glm::vec3 c = ground;
      if (d.y > 0.0f) {
        const float gamma = std::acos(std::clamp(glm::dot(d, sun), -1.0f, 1.0f));
        const float relative = indicatrix(gamma) * gradation(d.y) * norm;
        c = kZenithRadiance * relative * glm::mix(horizon_tint, zenith_tint, std::sqrt(d.y));
      }
      img.at(x, y) = glm::vec4(c, 1.0f);
      const float cos_sun = glm::dot(d, sun);
      const std::size_t i = std::size_t(y) * width + x;
      if (cos_sun >= disk_cos) disk.push_back(i), disk_solid_angle += row_solid_angle;
      if (cos_sun > nearest_cos) nearest_cos = cos_sun, nearest = i;
    }
  }
  // A map too coarse to hold the disk gets the sun in the pixel nearest to it.
  if (disk.empty()) {
    disk.push_back(nearest);
    const int y = int(nearest / width);
    disk_solid_angle = equirect_pixel_solid_angle(y, width, height);
  }
  const float sun_radiance = float(kSkySunIrradiance / disk_solid_angle);
  for (std::size_t i : disk) img.pixels[i] += glm::vec4(sun_radiance, sun_radiance, sun_radiance, 0.0f);
  return img;
}

ImageRGBA rotate_equirect(const ImageRGBA& src, float degrees) {
  if (src.empty()) return src;
  ImageRGBA out(src.width, src.height);
  // R_y(θ) maps longitude φ to φ − θ (equirect_uv), so the rotated map at u reads the
  // original at u + θ/360.
  const double shift = double(degrees) / 360.0 * src.width;
  for (int x = 0; x < src.width; ++x) {
    const double fx = x + shift;
    const double x0 = std::floor(fx);
    const float t = float(fx - x0);
    const int a = int(((long long)x0 % src.width + src.width) % src.width);
    const int b = (a + 1) % src.width;
    for (int y = 0; y < src.height; ++y)
      out.at(x, y) = src.at(a, y) * (1.0f - t) + src.at(b, y) * t;
  }
  return out;
}

Environment studio_environment() {
  Environment env;
  env.equirect = ImageRGBA(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const float l = 0.5f + 0.3f * equirect_direction((x + 0.5f) / 64.0f, (y + 0.5f) / 32.0f).y;
      env.equirect.at(x, y) = glm::vec4(l, l, l, 1.0f);
    }
  env.source = "default studio light";
  env.intensity = 1.0f;
  return env;
}

Light studio_key_light(const Camera& camera) {
  glm::vec3 back = camera.eye - camera.target;
  back = glm::length(back) > 0.0f ? glm::normalize(back) : glm::vec3(0, 0, 1);
  glm::vec3 right = glm::cross(-back, glm::vec3(0, 1, 0));
  if (glm::length(right) < 1e-3f) right = glm::cross(-back, camera.up);
  if (glm::length(right) < 1e-3f) right = glm::vec3(1, 0, 0);
  right = glm::normalize(right);
  const glm::vec3 up = glm::normalize(glm::cross(right, -back));
  Light key;
  key.name = "studio key light";
  key.type = LightType::Directional;
  key.direction = -glm::normalize(-0.5f * right + 0.8f * up + 0.6f * back);
  key.intensity = kStudioKeyIrradiance;
  key.color = glm::vec3(1.0f);
  return key;
}

void add_studio_light(Scene& scene, const Camera& camera) {
  scene.environment = studio_environment();
  scene.lights.push_back(studio_key_light(camera));
}

}  // namespace speculum
