// Geometric optics shared by every technique: mirror reflection, refraction with total
// internal reflection, and Fresnel reflectance (SURVEY §1.1, eq.1–2).
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace speculum {

// R = V - 2 (N·V) N. V points towards the surface (incident direction), N is unit.
inline glm::vec3 reflect(const glm::vec3& v, const glm::vec3& n) {
  return v - 2.0f * glm::dot(n, v) * n;
}

// Refraction of the unit incident direction V at a surface with unit normal N facing the
// incident side (N·V <= 0), relative index nu = n_transmitted / n_incident:
// c = -N·V, T = V/nu + (c/nu - sqrt(1 - (1-c²)/nu²)) N  (Snell's law in vector form).
// Returns false (and leaves `t` untouched) on total internal reflection.
inline bool refract(const glm::vec3& v, const glm::vec3& n, float nu, glm::vec3& t) {
  const float c = -glm::dot(n, v);
  const float radicand = 1.0f - (1.0f - c * c) / (nu * nu);
  if (radicand < 0.0f) return false;
  t = v / nu + (c / nu - std::sqrt(radicand)) * n;
  return true;
}

// Normal-incidence reflectance from the relative index nu and extinction kappa
// (SURVEY eq.2): F0 = ((nu-1)² + kappa²) / ((nu+1)² + kappa²). nu=1.5, kappa=0 -> 0.04.
inline float fresnel_f0(float nu, float kappa = 0.0f) {
  const float k2 = kappa * kappa;
  return ((nu - 1.0f) * (nu - 1.0f) + k2) / ((nu + 1.0f) * (nu + 1.0f) + k2);
}

// Schlick's approximation F(θ) = F0 + (1-F0)(1-cosθ)^5 (SURVEY eq.2); cos_theta is clamped
// to [0, 1] so grazing round-off cannot push F outside [F0, 1].
inline float fresnel_schlick(float cos_theta, float f0) {
  const float m = 1.0f - std::clamp(cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  return f0 + (1.0f - f0) * (m2 * m2 * m);
}
inline glm::vec3 fresnel_schlick(float cos_theta, const glm::vec3& f0) {
  const float m = 1.0f - std::clamp(cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  return f0 + (glm::vec3(1.0f) - f0) * (m2 * m2 * m);
}

// Exact unpolarized Fresnel reflectance of a dielectric interface: cos_i is the cosine of
// the incidence angle (> 0), nu = n_transmitted / n_incident. Returns 1 on total internal
// reflection. The mean of the s and p reflectances.
inline float fresnel_dielectric(float cos_i, float nu) {
  cos_i = std::clamp(cos_i, 0.0f, 1.0f);
  const float sin_t2 = (1.0f - cos_i * cos_i) / (nu * nu);
  if (sin_t2 >= 1.0f) return 1.0f;
  const float cos_t = std::sqrt(1.0f - sin_t2);
  const float rs = (cos_i - nu * cos_t) / (cos_i + nu * cos_t);
  const float rp = (nu * cos_i - cos_t) / (nu * cos_i + cos_t);
  return 0.5f * (rs * rs + rp * rp);
}

}  // namespace speculum
