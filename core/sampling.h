// Deterministic sampling: a counter-based hash RNG keyed by (pixel, sample, dimension,
// seed), the 2-D Hamersley set, and direction sampling (cosine hemisphere, uniform cone,
// normalized Phong lobe of YU eq.4) with their pdfs.
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace speculum {

constexpr float kPi = 3.14159265358979323846f;

// A well-mixing 32-bit integer hash (the "lowbias32" constants of C. Wellons' hash
// prospector); bijective, so distinct inputs never collide.
inline std::uint32_t hash_u32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// The random number for (pixel, sample, dimension, seed): no state, so any thread may
// compute any sample and the image never depends on the schedule (docs/architecture.md,
// "Determinism"). Each key is folded in with a hash so nearby keys decorrelate.
inline std::uint32_t hash_key(std::uint32_t pixel, std::uint32_t sample, std::uint32_t dimension,
                              std::uint32_t seed) {
  std::uint32_t h = hash_u32(seed ^ 0x9e3779b9u);
  h = hash_u32(h ^ pixel);
  h = hash_u32(h ^ sample);
  h = hash_u32(h ^ dimension);
  return h;
}

// 24 high bits -> float in [0, 1) exactly representable, never 1.0.
inline float u32_to_unit_float(std::uint32_t bits) {
  return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f);
}

inline float random_float(std::uint32_t pixel, std::uint32_t sample, std::uint32_t dimension,
                          std::uint32_t seed) {
  return u32_to_unit_float(hash_key(pixel, sample, dimension, seed));
}

// Two consecutive dimensions (dimension, dimension+1).
inline glm::vec2 random_float2(std::uint32_t pixel, std::uint32_t sample, std::uint32_t dimension,
                               std::uint32_t seed) {
  return {random_float(pixel, sample, dimension, seed),
          random_float(pixel, sample, dimension + 1, seed)};
}

// Van der Corput radical inverse in base 2 (bit reversal).
inline float radical_inverse_base2(std::uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
  return u32_to_unit_float(i);
}

// Point i of the n-point 2-D Hamersley set: (i/n, radical_inverse(i)) — YU §3.3 samples.
inline glm::vec2 hamersley(std::uint32_t i, std::uint32_t n) {
  return {static_cast<float>(i) / static_cast<float>(n), radical_inverse_base2(i)};
}

// Cranley–Patterson rotation: shifts a point set by a per-pixel offset (mod 1), so each
// pixel gets a decorrelated copy of the same low-discrepancy set.
inline glm::vec2 rotate_unit_square(glm::vec2 p, glm::vec2 offset) {
  p += offset;
  if (p.x >= 1.0f) p.x -= 1.0f;
  if (p.y >= 1.0f) p.y -= 1.0f;
  return p;
}

// Orthonormal basis (t, b, n) around a unit vector n, branchless and continuous except at
// n.z = -1 (Duff et al. 2017, "Building an orthonormal basis, revisited").
struct Onb {
  glm::vec3 t, b, n;
  explicit Onb(const glm::vec3& unit_n) : n(unit_n) {
    const float sign = std::copysign(1.0f, unit_n.z);
    const float a = -1.0f / (sign + unit_n.z);
    const float bb = unit_n.x * unit_n.y * a;
    t = glm::vec3(1.0f + sign * unit_n.x * unit_n.x * a, sign * bb, -sign * unit_n.x);
    b = glm::vec3(bb, sign + unit_n.y * unit_n.y * a, -unit_n.y);
  }
  glm::vec3 to_world(const glm::vec3& local) const { return local.x * t + local.y * b + local.z * n; }
};

// A direction with polar cosine cos_theta about +Z and azimuth 2π u.
inline glm::vec3 spherical_local(float cos_theta, float u) {
  const float sin_theta = std::sqrt(std::fmax(0.0f, 1.0f - cos_theta * cos_theta));
  const float phi = 2.0f * kPi * u;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

// Cosine-weighted hemisphere about +Z: pdf = cosθ / π.
inline glm::vec3 sample_cosine_hemisphere(glm::vec2 u) {
  return spherical_local(std::sqrt(1.0f - u.x), u.y);
}

// Uniform within a cone of half-angle acos(cos_max) about +Z: pdf = 1 / (2π (1 - cos_max)).
inline glm::vec3 sample_uniform_cone(glm::vec2 u, float cos_max) {
  return spherical_local(1.0f - u.x * (1.0f - cos_max), u.y);
}

// Normalized Phong lobe about +Z (the lobe axis, e.g. the mirror direction R), YU eq.4:
// cosθ = u1^(1/(n+1)), φ = 2π u2; pdf(θ) = (n+1)/(2π) cos^n θ over the hemisphere about the
// axis, so the mean solid angle of one of N samples is 2π/N: the solid angle of the pdf's
// domain over N (YU §3.2 states 4π/N, a whole sphere's).
inline glm::vec3 sample_phong_lobe(glm::vec2 u, float exponent) {
  // 1 - u keeps u1 in (0, 1] so pow never sees 0 (which would give cosθ = 0 exactly).
  return spherical_local(std::pow(1.0f - u.x, 1.0f / (exponent + 1.0f)), u.y);
}
inline float phong_lobe_pdf(float cos_theta, float exponent) {
  if (cos_theta <= 0.0f) return 0.0f;
  return (exponent + 1.0f) / (2.0f * kPi) * std::pow(cos_theta, exponent);
}

}  // namespace speculum
