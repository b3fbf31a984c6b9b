// The radiance a specular G-buffer sample sends towards the viewer, given a lookup of the
// radiance arriving along a direction: mirror/glossy reflection weighted by the lobe's
// directional albedo (specular_reflectance: Schlick F for a mirror, the split-sum E(F0) of
// a prefiltered glossy lookup), or a refractor's Schlick-weighted reflection + transmission
// (SURVEY §3.1, §2.4). Shared by every raster reflection node that differs only in its lookup.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/optics.h"
#include "core/shading.h"

namespace speculum::raster {

// Phong exponent used to read a map "sharply" (the mirror-like lookups of refractors).
constexpr float kSharpLookupExponent = 1e6f;

// specular_radiance in two steps, for callers that look many samples' directions up together:
// the lookups a sample makes (at most two: R, and T for a refractor), and the radiance from
// what they found. specular_radiance(s, n, v, lookup) is plan.radiance of the lookups of
// plan = SpecularLookups(s, n, v), in their order, bit for bit.
struct SpecularLookups {
  int count = 0;
  glm::vec3 direction[2];
  float exponent[2] = {0.0f, 0.0f};
  // How the found radiance combines: reflectance × found[0] (a reflector, or a refractor
  // under total internal reflection: F = 1, and 1 × x is x exactly), else the refractor's
  // f found[0] + (1 − f) base found[1].
  bool refracts = false;
  glm::vec3 reflectance{1.0f}, base_color{0.0f};
  float f = 0.0f;

  SpecularLookups() = default;
  // n: unit shading normal; v: unit direction towards the eye.
  SpecularLookups(const SurfaceParams& s, glm::vec3 n, const glm::vec3& v) {
    const glm::vec3 incident = -v;
    if (!s.is_refractor()) {
      reflectance = specular_reflectance(s, glm::dot(n, v));
      add(reflect(incident, n), s.phong_exponent);
      return;
    }
    // Entering when the normal faces the viewer; leaving flips n and the index ratio.
    const bool entering = glm::dot(n, v) >= 0.0f;
    if (!entering) n = -n;
    const float nu = entering ? s.ior : 1.0f / s.ior;
    const glm::vec3 r = reflect(incident, n);
    glm::vec3 t;
    if (!refract(incident, n, nu, t)) {
      add(r, kSharpLookupExponent);
      return;
    }
    // Schlick with F0 of the interface.
    refracts = true;
    f = fresnel_schlick(glm::dot(n, v), fresnel_f0(nu));
    base_color = s.base_color;
    add(r, kSharpLookupExponent);
    add(t, kSharpLookupExponent);
  }
  // found[k]: the radiance arriving along direction[k], prefiltered for exponent[k].
  glm::vec3 radiance(const glm::vec3* found) const {
    return refracts ? f * found[0] + (1.0f - f) * base_color * found[1] : reflectance * found[0];
  }

 private:
  void add(const glm::vec3& d, float e) { direction[count] = d, exponent[count] = e, ++count; }
};

// n: unit shading normal; v: unit direction towards the eye; lookup(d, exponent) → radiance
// arriving along d, prefiltered for a Phong lobe of that exponent.
template <class Lookup>
glm::vec3 specular_radiance(const SurfaceParams& s, glm::vec3 n, const glm::vec3& v,
                            const Lookup& lookup) {
  const SpecularLookups plan(s, n, v);
  glm::vec3 found[2];
  for (int k = 0; k < plan.count; ++k) found[k] = lookup(plan.direction[k], plan.exponent[k]);
  return plan.radiance(found);
}

}  // namespace speculum::raster
