// Geometry transformation for planar mirrors (SURVEY §5): a plane, the camera reflected
// about it, and the scene clipped to the viewer's side of it (the user clip plane of the
// mirrored render, done on the triangle soup so the rasterizer stays untouched).
#pragma once

#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"

namespace speculum::raster {

// The plane n·x = offset (n unit).
struct Plane {
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float offset = 0.0f;
  float signed_distance(const glm::vec3& p) const { return glm::dot(normal, p) - offset; }
  glm::vec3 reflect_point(const glm::vec3& p) const {
    return p - 2.0f * signed_distance(p) * normal;
  }
  glm::vec3 reflect_direction(const glm::vec3& d) const {
    return d - 2.0f * glm::dot(normal, d) * normal;
  }
};

// The camera reflected about `plane`. A reflection flips handedness, and a look-at camera
// cannot represent that, so the returned camera sees the reflected rays mirrored
// left-right: pixel (x, y) of the original camera's reflected view is pixel
// (width − 1 − x, y) of this camera (exact for a symmetric frustum at pixel centres).
Camera mirrored_camera(const Camera& camera, const Plane& plane);

// `scene` with every triangle cut to the half-space where `side` · plane.signed_distance > 0
// (side = ±1): triangles behind are dropped, straddling ones are clipped
// (Sutherland–Hodgman; new vertices interpolate every attribute), and object `skip`
// (kNoId: none) is left out whole. Object ids, materials, textures, lights and environment
// are kept, so G-buffers and shadow maps of the original scene apply unchanged.
Scene clip_scene_to_half_space(const Scene& scene, const Plane& plane, float side,
                               std::uint32_t skip = kNoId);

}  // namespace speculum::raster
