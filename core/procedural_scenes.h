// The built-in procedural scenes, named after the papers' set-ups: each scales from ~1K to
// ~10M triangles with its size parameter.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/scene.h"

namespace speculum {

constexpr std::uint64_t kMinSceneSize = 1000;
constexpr std::uint64_t kMaxSceneSize = 10'000'000;

struct BuiltinParams {
  std::uint64_t size = 0;                // requested triangles (already range-checked)
  std::map<std::string, double> extra;   // scene-specific, e.g. bumpy-sphere's n
  double get(const std::string& key, double fallback) const {
    auto it = extra.find(key);
    return it == extra.end() ? fallback : it->second;
  }
};

struct BuiltinScene {
  const char* name;
  const char* description;
  std::uint64_t default_size;
  const char* extra_params;  // "" or e.g. "n=8 (bump frequency), amplitude=0.06"
  Scene (*build)(const BuiltinParams&);
};

std::span<const BuiltinScene> builtin_scenes();

// A named camera path through a built-in scene (SOFF §4 measures two per scene): key
// cameras spaced evenly over `frames` frames, eye and target interpolated linearly between
// neighbouring keys (field of view and clip planes are the first key's). Every frame is a
// pure function of its index, so frames render independently.
struct CameraPath {
  std::string name;
  int frames = 60;
  std::vector<Camera> keys;
  Camera at(int frame) const;  // frame in [0, frames)
};

// The paths of built-in scene `name` (a bare name, no ":size=" suffix); empty: none.
std::vector<CameraPath> builtin_camera_paths(std::string_view name);
const BuiltinScene* find_builtin_scene(std::string_view name);

}  // namespace speculum
