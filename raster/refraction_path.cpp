// One refracted camera sample: see refraction_path.h.
#include "raster/refraction_path.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/optics.h"

namespace speculum::raster {

RefractionPath enter_refractor(const glm::vec3& p1, const glm::vec3& v, const glm::vec3& n1,
                               float ior) {
  RefractionPath p;
  p.entry_point = p1;
  p.reflected = reflect(v, n1);
  p.cos_i = std::clamp(-glm::dot(n1, v), 0.0f, 1.0f);
  glm::vec3 t;
  if (!refract(v, n1, ior, t)) {
    // Only possible for ior < 1 (a bubble): everything is reflected at the entry.
    p.f_entry = 1.0f;
    p.inside = v;
    p.cos_t = 0.0f;
    return p;
  }
  p.inside = glm::normalize(t);
  p.cos_t = std::clamp(-glm::dot(n1, p.inside), 0.0f, 1.0f);
  p.f_entry = fresnel_dielectric(p.cos_i, ior);
  p.exit_point = p1;
  p.exit_direction = p.inside;
  return p;
}

void leave_refractor(RefractionPath& path, const glm::vec3& p2, const glm::vec3& n2, float ior) {
  path.exit_point = p2;
  const glm::vec3 inward = -n2;  // the normal on the incident (inner) side
  path.internal = reflect(path.inside, inward);
  glm::vec3 t;
  if (refract(path.inside, inward, 1.0f / ior, t)) {
    path.total_internal = false;
    path.exit_direction = glm::normalize(t);
    path.f_exit = fresnel_dielectric(std::clamp(glm::dot(n2, path.inside), 0.0f, 1.0f), 1.0f / ior);
  } else {
    path.total_internal = true;
    path.exit_direction = path.internal;
    path.f_exit = 1.0f;
  }
}

float two_face_distance(float cos_i, float cos_t, float ior, float d_view, float d_normal) {
  const float theta_i = std::acos(std::clamp(cos_i, 0.0f, 1.0f));
  const float theta_t = std::acos(std::clamp(cos_t, 0.0f, 1.0f));
  const float ratio = theta_i > 1e-4f ? theta_t / theta_i : 1.0f / ior;
  return ratio * d_view + (1.0f - ratio) * d_normal;
}

}  // namespace speculum::raster
