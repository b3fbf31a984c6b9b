// Where a ray leaving a surface point starts: the point pushed a little along a normal so
// the new ray does not hit the surface it leaves.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>

namespace speculum {

// p + n · 1e-4 · max(1, |p|∞), n a unit normal on the side the ray leaves towards. The
// offset scales with the position's magnitude because a float's spacing does: a fixed
// epsilon falls below one ulp of a coordinate far from the origin (the ray restarts on or
// behind its own surface) and is needlessly large near it. The floor of 1 keeps the
// offset from vanishing at the origin.
inline glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n) {
  const float m = std::max({1.0f, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  return p + n * (1e-4f * m);
}

}  // namespace speculum
