// The frame options `render`, `inspect` and `profile` share (scene, technique, size, spp,
// technique parameters, map sizes, camera) and the FrameSettings they make.
#pragma once

#include <map>
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
  int bounces = 1;
  std::vector<std::string> params;
  int cube_map_size = 256;
  int shadow_map_size = 512;
  CameraOverrides camera;
};

void add_frame_options(CLI::App& cmd, FrameOptions& options);

// What can be checked before the scene is loaded: the frame's sample count against its
// limit and the technique parameters (parsed). Throws InputError naming the option.
std::map<std::string, double> check_frame_options(const FrameOptions& options);

// Validates (InputError on bad values; check_frame_options included) and resolves the
// camera. A square spp is k×k supersampling; other counts reach only sample-based techniques
// through FrameSettings::spp.
FrameSettings make_frame_settings(const FrameOptions& options, const Scene& scene);

}  // namespace speculum::pipeline
