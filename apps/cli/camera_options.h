// Camera selection shared by `render` and `bench raster`: --camera NAME|INDEX picks one of
// the scene's cameras; --eye/--target/--up x,y,z and --fov DEG (vertical) override it.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "core/scene.h"

namespace speculum::pipeline {

struct CameraOverrides {
  std::string camera;  // name or index; empty: the scene's first camera
  std::string eye, target, up;
  float fov = 0.0f;    // 0: keep
};

void add_camera_options(CLI::App& cmd, CameraOverrides& overrides);

// "x,y,z" → a vector; InputError naming `option` unless three finite numbers.
glm::vec3 parse_vec3(const std::string& option, const std::string& text);

// The chosen camera with overrides applied; with --eye or --target its near/far planes are
// refitted to the scene's bounds (fit_clip_planes), otherwise the scene's are kept. Throws
// InputError for unknown names, bad vectors or a degenerate result.
Camera resolve_camera(const Scene& scene, const CameraOverrides& overrides);

}  // namespace speculum::pipeline
