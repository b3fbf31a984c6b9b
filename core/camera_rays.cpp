#include "core/camera_rays.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"

namespace speculum {

glm::mat4 view_matrix(const Camera& camera) {
  return glm::lookAt(camera.eye, camera.target, camera.up);
}

glm::mat4 projection_matrix(const Camera& camera, int width, int height) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  return glm::perspective(glm::radians(camera.vfov_degrees), aspect, camera.znear, camera.zfar);
}

Ray primary_ray(const Camera& camera, int width, int height, float sx, float sy) {
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tan_half = std::tan(glm::radians(camera.vfov_degrees) * 0.5f);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float ndc_x = 2.0f * sx / static_cast<float>(width) - 1.0f;
  const float ndc_y = 1.0f - 2.0f * sy / static_cast<float>(height);
  Ray ray;
  ray.origin = camera.eye;
  ray.direction =
      glm::normalize(forward + right * (ndc_x * tan_half * aspect) + up * (ndc_y * tan_half));
  return ray;
}

void validate_camera(const Camera& c, const std::string& source) {
  auto finite = [](const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(c.eye) || !finite(c.target) || !finite(c.up))
    throw InputError(source, "camera '" + c.name + "' has a non-finite eye, target or up");
  const glm::vec3 f = c.target - c.eye;
  if (glm::length(f) <= 1e-12f)
    throw InputError(source, "camera '" + c.name + "' has its eye at its target");
  if (glm::length(glm::cross(glm::normalize(f), c.up)) <= 1e-6f)
    throw InputError(source, "camera '" + c.name + "' has an up vector parallel to its view");
  if (!(c.vfov_degrees > 0.0f && c.vfov_degrees < 180.0f))
    throw InputError(source, "camera '" + c.name + "' has field of view outside (0, 180)");
  if (!(c.znear > 0.0f && c.zfar > c.znear && std::isfinite(c.zfar)))
    throw InputError(source, "camera '" + c.name + "' has bad clip planes");
}

}  // namespace speculum
