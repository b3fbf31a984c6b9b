// The frame options `render`, `inspect` and `profile` share (scene, technique, size, spp,
// technique parameters, map sizes, camera) and the FrameSettings they make.
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/cli/camera_options.h"
#include "apps/techniques/technique_table.h"
#include "core/scene.h"

namespace speculum::pipeline {

struct FrameOptions {
  std::string scene;
  std::string technique = "envmap";
  int width = 320;
  int height = 240;
  int spp = 1;
  std::uint32_t seed = 0;
  float exposure = 1.0f;
  float alpha = 0.0f;
  int bounces = 0;  // 0: the technique's default
  std::vector<std::string> params;
  int cube_map_size = 256;
  int shadow_map_size = 512;
  CameraOverrides camera;
  bool strict = false;  // --strict: a missing texture or .mtl is an error, not a warning
};

void add_frame_options(CLI::App& cmd, FrameOptions& options);

// Loads the frame's scene (the default built-in one when none is given) and prints each
// loader warning once on stderr as `speculum: warning: FILE: message`, unless `quiet`.
Scene load_frame_scene(const FrameOptions& options, bool quiet);

// Validates (InputError on bad values) and resolves the camera. A square spp is k×k
// supersampling; other counts reach only sample-based techniques through FrameSettings::spp.
FrameSettings make_frame_settings(const FrameOptions& options, const Scene& scene);

}  // namespace speculum::pipeline
