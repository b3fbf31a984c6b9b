// Camera selection shared by `render` and `bench raster`: --camera NAME|INDEX picks one of
// the scene's cameras; --eye/--target/--up x,y,z and --fov DEG (vertical) override it;
// --view DIR and --fit reframe it around the scene's bounds (core/scene.h framing_camera).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "core/scene.h"

namespace speculum::pipeline {

struct CameraOverrides {
  std::string camera;  // name or index; empty: the scene's first camera
  std::string eye, target, up;
  float fov = 0.0f;    // 0: keep (programmatic callers)
  std::string fov_text;  // --fov as typed; must be a number in (0, 180)
  std::string view;      // --view: front|back|left|right|top|three-quarter; empty: keep
  bool fit = false;      // --fit: move the camera along its axis to frame the bounds
};

void add_camera_options(CLI::App& cmd, CameraOverrides& overrides);

// "x,y,z" → a vector; InputError naming `option` unless three finite numbers.
glm::vec3 parse_vec3(const std::string& option, const std::string& text);

// "front", ... → a View; InputError naming --view otherwise.
View parse_view(const std::string& text);

// The chosen camera with overrides applied, for an image of `aspect` = width / height.
// Order: --camera, --fov, --eye/--target/--up, then --view (a framing camera from that
// direction, keeping the fov) or --fit (the same direction, moved to frame the bounds). A
// scene without a camera of its own gets the three-quarter framing camera fitted to
// `aspect`. With --eye or --target the near/far planes are refitted to the scene's bounds
// (fit_clip_planes), otherwise the scene's are kept. Throws InputError for unknown names,
// bad vectors, a field of view outside (0, 180) or a degenerate result.
Camera resolve_camera(const Scene& scene, const CameraOverrides& overrides, float aspect = 4.0f / 3.0f);

}  // namespace speculum::pipeline
