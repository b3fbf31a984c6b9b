// Camera selection options: see camera_options.h.
#include "apps/cli/camera_options.h"

#include <cmath>
#include <sstream>

#include "core/camera_rays.h"
#include "core/error.h"

namespace speculum::pipeline {
glm::vec3 parse_vec3(const std::string& option, const std::string& text) {
  std::istringstream in(text);
  glm::vec3 v;
  char c1 = 0, c2 = 0;
  if (!(in >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() ||
      !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw InputError(option, "expected three finite numbers x,y,z, got '" + text + "'");
  return v;
}

void add_camera_options(CLI::App& cmd, CameraOverrides& o) {
  cmd.add_option("--camera", o.camera, "Scene camera by name or index (default: the first)");
  cmd.add_option("--eye", o.eye, "Camera position x,y,z (overrides the scene camera)");
  cmd.add_option("--target", o.target, "Point looked at x,y,z");
  cmd.add_option("--up", o.up, "Up vector x,y,z");
  cmd.add_option("--fov", o.fov, "Vertical field of view in degrees");
}

Camera resolve_camera(const Scene& scene, const CameraOverrides& o) {
  Camera cam = scene.cameras.empty() ? framing_camera(scene.bounds()) : scene.cameras.front();
  if (!o.camera.empty()) {
    bool found = false;
    for (const Camera& c : scene.cameras)
      if (c.name == o.camera) cam = c, found = true;
    if (!found) {
      char* end = nullptr;
      const long index = std::strtol(o.camera.c_str(), &end, 10);
      if (end && *end == '\0' && index >= 0 && index < long(scene.cameras.size()))
        cam = scene.cameras[index], found = true;
    }
    if (!found) throw InputError("--camera", "scene '" + scene.name + "' has no camera '" +
                                                 o.camera + "'");
  }
  if (!o.eye.empty()) cam.eye = parse_vec3("--eye", o.eye);
  if (!o.target.empty()) cam.target = parse_vec3("--target", o.target);
  if (!o.up.empty()) cam.up = parse_vec3("--up", o.up);
  if (o.fov != 0.0f) cam.vfov_degrees = o.fov;
  // The scene's near/far planes suit where the scene put its camera (a mesh file's framing
  // camera has them tight around the bounds): a moved or re-aimed camera gets its own.
  if (!o.eye.empty() || !o.target.empty()) cam = fit_clip_planes(cam, scene.bounds());
  validate_camera(cam, "camera options");
  return cam;
}

}  // namespace speculum::pipeline
