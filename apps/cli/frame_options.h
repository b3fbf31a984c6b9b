// The frame options `render`, `inspect` and `profile` share (scene, technique, size, spp,
// technique parameters, map sizes, camera, exposure, environment and default light) and the
// FrameSettings they make.
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
  int spp = 0;  // 0: the technique's default
  std::uint32_t seed = 0;
  std::string exposure = "1";  // a multiplier > 0, or "auto" (render's default)
  std::string env;             // --env FILE|sky|COLOR; empty: the scene's own environment
  float env_intensity = 1.0f;
  float env_rotate = 0.0f;     // degrees about +Y
  bool no_default_light = false;
  float alpha = 0.0f;
  int bounces = 0;  // 0: the technique's default
  std::vector<std::string> params;
  int cube_map_size = 256;
  int shadow_map_size = 512;
  CameraOverrides camera;
  bool allow_external_files = false;  // --allow-external-files
  bool strict = false;  // --strict: a missing texture or .mtl is an error, not a warning
  // Set by add_frame_options: whether --width/--height were given (a file camera's aspect
  // ratio decides the other side otherwise).
  const CLI::Option* width_option = nullptr;
  const CLI::Option* height_option = nullptr;
};

void add_frame_options(CLI::App& cmd, FrameOptions& options);

// Loads the frame's scene (the default built-in one when none is given) and prints each
// loader warning once on stderr as `speculum: warning: FILE: message`, unless `quiet`.
Scene load_frame_scene(const FrameOptions& options, bool quiet);

// What can be checked before the scene is loaded: the frame's sample count against its
// limit and the technique parameters (parsed). Throws InputError naming the option.
std::map<std::string, double> check_frame_options(const FrameOptions& options);

// Validates (InputError on bad values; check_frame_options included) and resolves the
// camera. A square spp is k×k supersampling; other counts reach only sample-based techniques
// through FrameSettings::spp. Without --width/--height, a file camera's aspect ratio sets the
// height from the width.
FrameSettings make_frame_settings(const FrameOptions& options, const Scene& scene);

// --exposure: "auto" (metered by the tonemap pass, raster/composite.h) or a multiplier, finite
// and > 0. InputError naming --exposure otherwise.
struct Exposure {
  bool automatic = false;
  float value = 1.0f;
};
Exposure parse_exposure(const std::string& text);

// --env: "sky" (core/lighting_presets.h clear sky, its sun turned by `rotate_degrees`), a
// colour "r,g,b" or a grey "v" (linear radiance, finite, >= 0), or an equirect image file
// (EXR/HDR/PNG/... through OpenImageIO; non-finite pixels rejected, negative ones clamped to
// 0). Images are turned by `rotate_degrees` about +Y. InputError naming --env or the file.
Environment parse_environment(const std::string& text, float rotate_degrees = 0.0f);

// Applies --env, --env-intensity and --env-rotate to `scene`, then, when the scene has no
// light and a black environment and --no-default-light is not given, adds the default
// studio light (core/lighting_presets.h) placed for `camera`. Returns the warning lines to
// print ("speculum: warning: SCENE: ..."), empty when nothing was substituted.
std::vector<std::string> apply_light_options(const FrameOptions& options, Scene& scene,
                                             const Camera& camera);

}  // namespace speculum::pipeline
