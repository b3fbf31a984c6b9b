// Camera conventions shared by the rasterizer and the tracers, so that a rasterized
// pixel and a traced primary ray see exactly the same thing:
// - pixel (x, y) covers [x, x+1) x [y, y+1), y grows downwards, centre at +0.5;
// - vertical field of view, aspect = width / height;
// - right-handed view space (glm::lookAt), camera looks down -Z;
// - OpenGL clip space (glm::perspective, depth in [-1, 1]).
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"

namespace speculum {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // not necessarily unit
  float tmin = 0.0f;
  float tmax = 3.0e38f;
};

glm::mat4 view_matrix(const Camera& camera);
glm::mat4 projection_matrix(const Camera& camera, int width, int height);

// A ray from the eye through image-plane point (sx, sy) given in pixels (sx = x + 0.5 is
// the centre of pixel column x). Direction is unit length; tmin = 0.
Ray primary_ray(const Camera& camera, int width, int height, float sx, float sy);

// Throws InputError (naming `source`) for a degenerate camera: eye == target, up parallel
// to the view direction, fov outside (0, 180), znear <= 0 or zfar <= znear, non-finite.
void validate_camera(const Camera& camera, const std::string& source);

}  // namespace speculum
