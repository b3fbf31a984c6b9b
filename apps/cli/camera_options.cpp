// Camera selection options: see camera_options.h.
#include "apps/cli/camera_options.h"

#include <cmath>
#include <cstdlib>
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
  cmd.add_option("--fov", o.fov_text, "Vertical field of view in degrees, in (0, 180)");
  cmd.add_option("--view", o.view,
                 "Reframe the scene's bounds from front|back|left|right|top|three-quarter "
                 "(without a camera in the file: three-quarter)");
  cmd.add_flag("--fit", o.fit, "Move the camera along its view axis until the scene's bounds fit");
}

View parse_view(const std::string& text) {
  for (View v : {View::Front, View::Back, View::Left, View::Right, View::Top, View::ThreeQuarter})
    if (text == to_string(v)) return v;
  throw InputError("--view", "expected front, back, left, right, top or three-quarter, got '" +
                                 text + "'");
}

namespace {

float parse_fov(const std::string& text) {
  char* end = nullptr;
  const float v = std::strtof(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !(v > 0.0f && v < 180.0f))
    throw InputError("--fov", "expected degrees in (0, 180), got '" + text + "'");
  return v;
}

}  // namespace

Camera resolve_camera(const Scene& scene, const CameraOverrides& o, float aspect) {
  const Bounds bounds = scene.bounds();
  Camera cam = scene.cameras.empty() ? framing_camera(bounds) : scene.cameras.front();
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
  if (!o.fov_text.empty()) cam.vfov_degrees = parse_fov(o.fov_text);
  const bool moved = !o.eye.empty() || !o.target.empty();
  if (!o.view.empty()) {
    cam = framing_camera(bounds, parse_view(o.view), aspect, cam.vfov_degrees);
  } else if (o.fit || (cam.framed && !moved)) {
    // The loader's framing camera assumed a square image; refit it to the real one.
    validate_camera(cam, "camera options");
    cam = fit_camera(cam, bounds, aspect);
  } else if (moved) {
    // The scene's near/far planes suit where the scene put its camera (a mesh file's framing
    // camera has them tight around the bounds): a moved or re-aimed camera gets its own.
    cam = fit_clip_planes(cam, bounds);
  }
  validate_camera(cam, "camera options");
  return cam;
}

}  // namespace speculum::pipeline
