// The geometric optics of one refracted camera sample (SURVEY §4.4):
// the entry interface, Wyman's two-face thickness interpolation, and the exit interface
// with total internal reflection. Exact dielectric Fresnel, as the reference tracer.
#pragma once

#include <glm/vec3.hpp>

namespace speculum::raster {

struct RefractionPath {
  glm::vec3 entry_point{0.0f};      // P1
  glm::vec3 reflected{0.0f};        // R1 = reflect(V, N1)
  float f_entry = 1.0f;             // Fresnel reflectance at the entry
  glm::vec3 inside{0.0f};           // T1 (unit)
  float cos_i = 1.0f, cos_t = 1.0f; // incidence and refraction cosines at the entry
  glm::vec3 exit_point{0.0f};       // P2
  bool total_internal = false;      // T1 meets the exit beyond the critical angle
  glm::vec3 exit_direction{0.0f};   // T2, or the internally reflected direction under TIR
  glm::vec3 internal{0.0f};         // R2 = reflect(T1, N2), the internally reflected ray
  float f_exit = 0.0f;              // Fresnel at the exit (1 under TIR)
};

// Enters a refractor of index `ior` (relative to air) at P1: v is the unit incident
// direction (towards the surface), n1 the unit outward normal with n1·v < 0.
RefractionPath enter_refractor(const glm::vec3& p1, const glm::vec3& v, const glm::vec3& n1,
                               float ior);

// Leaves at P2 with unit outward normal n2: T2 = refract(T1, −N2, 1/ior), or the internal
// reflection reflect(T1, −N2) with f_exit = 1 when the radicand is negative.
void leave_refractor(RefractionPath& path, const glm::vec3& p2, const glm::vec3& n2, float ior);

// Wyman's thickness along T1 (SURVEY §4.4): d = (θt/θi) d_V + (1 − θt/θi) d_N,
// d_V the distance to the back face along the view ray, d_N the thickness along the
// normal. θt/θi → 1/ν at normal incidence (its small-angle limit).
float two_face_distance(float cos_i, float cos_t, float ior, float d_view, float d_normal);

}  // namespace speculum::raster
