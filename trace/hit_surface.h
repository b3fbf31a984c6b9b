// The surface at a closest hit — position, facing normals and material — decoded the same
// way by the reference tracer and the ray-hierarchy shading.
#pragma once

#include <glm/vec3.hpp>

#include "core/scene.h"
#include "core/shading.h"
#include "trace/traversal.h"

namespace speculum::trace {

// The surface at a closest hit: position from the barycentrics, geometric and interpolated
// shading normal (both facing the incident side; the shading normal perturbed by the
// material's normal texture, core/normal_mapping.h), material at the hit's uv.
struct HitSurface {
  glm::vec3 p{0.0f}, ng{0.0f, 0.0f, 1.0f}, n{0.0f, 0.0f, 1.0f};
  SurfaceParams s;
  bool entering = true;  // the ray arrived on the front (geometric-normal) side
};
HitSurface hit_surface(const Scene& scene, const Hit& hit, const glm::vec3& ray_direction);

}  // namespace speculum::trace
