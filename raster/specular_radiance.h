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

// n: unit shading normal; v: unit direction towards the eye; lookup(d, exponent) → radiance
// arriving along d, prefiltered for a Phong lobe of that exponent.
template <class Lookup>
glm::vec3 specular_radiance(const SurfaceParams& s, glm::vec3 n, const glm::vec3& v,
                            const Lookup& lookup) {
  const glm::vec3 incident = -v;
  if (!s.is_refractor()) {
    const glm::vec3 r = reflect(incident, n);
    return specular_reflectance(s, glm::dot(n, v)) * lookup(r, s.phong_exponent);
  }
  // Entering when the normal faces the viewer; leaving flips n and the index ratio.
  const bool entering = glm::dot(n, v) >= 0.0f;
  if (!entering) n = -n;
  const float nu = entering ? s.ior : 1.0f / s.ior;
  const glm::vec3 r = reflect(incident, n);
  glm::vec3 t;
  if (!refract(incident, n, nu, t)) return lookup(r, kSharpLookupExponent);  // TIR: F = 1
  // Schlick with F0 of the interface.
  const float f = fresnel_schlick(glm::dot(n, v), fresnel_f0(nu));
  const glm::vec3 reflected = lookup(r, kSharpLookupExponent);
  const glm::vec3 transmitted = lookup(t, kSharpLookupExponent);
  return f * reflected + (1.0f - f) * s.base_color * transmitted;
}

}  // namespace speculum::raster
