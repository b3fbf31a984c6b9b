// One entry point for every scene source: glTF 2.0 (.gltf/.glb), OBJ/PLY/OFF/STL meshes,
// or a built-in procedural scene by name.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/procedural_scenes.h"
#include "core/scene.h"

namespace speculum {

// What a loader skipped or repaired; never fatal (fatal problems throw InputError).
// Messages do not repeat the file name (the caller prefixes it) and each is kept once.
struct LoadReport {
  std::vector<std::string> warnings;
  std::uint64_t skipped_primitives = 0;  // points/lines/unsupported primitives
  // --strict: content the loader would replace by a fallback (a missing or undecodable
  // texture, a missing .mtl file) is an InputError instead of a warning.
  bool strict = false;
  // --allow-external-files: a file a scene refers to (glTF image or buffer URI, OBJ .mtl or
  // texture) may lie outside the scene file's folder. Off by default: a service rendering
  // submitted scenes must not read the rest of the disk.
  bool allow_external_files = false;
  void warn(std::string message);
  // A missing or unreadable part of `source` replaced by a documented fallback: a warning,
  // or InputError(source, message) when strict.
  void substitute(const std::string& source, std::string message);
};

struct SceneOptions {
  // Built-in scenes: approximate triangle count (0: the scene's default). A size given in
  // the name ("bowl:size=20000") wins over this field. Ignored for files.
  std::uint64_t size = 0;
  LoadReport* report = nullptr;  // optional: receives warnings
  bool strict = false;           // see LoadReport::strict (sets report->strict too)
  bool allow_external_files = false;  // see LoadReport::allow_external_files
};

// Loads `file_or_name`: a path ending in .gltf/.glb/.obj/.ply/.off/.stl, or a built-in
// scene name with an optional ":size=N" suffix. The result has passed Scene::validate()
// and has at least one material and one camera. Throws InputError naming the source.
Scene load_scene(const std::string& file_or_name, const SceneOptions& options = {});

// A built-in scene spec "NAME[:size=N][,key=value...]" checked and parsed, not yet built:
// the scene, and its parameters with size in [kMinSceneSize, kMaxSceneSize] (`default_size`,
// when not 0, replaces the scene's default; a size in the spec wins). Throws InputError(spec,
// problem) for an unknown name or key, a value that is not a number, or one out of range.
struct BuiltinSpec {
  const BuiltinScene* scene = nullptr;
  BuiltinParams params;
};
BuiltinSpec parse_builtin_spec(const std::string& spec, std::uint64_t default_size = 0);

// The scene `speculum render` uses when none is given.
const char* default_scene_name();

// True when `file_or_name` names a built-in scene (with or without ":size=N").
bool is_builtin_scene_name(const std::string& file_or_name);

// The most triangles and vertices a scene may hold (files after instancing; built-in scenes
// stop at 10M triangles). They bound memory: a 10M-triangle scene rendered at 1×1 peaks at
// 2.1 GB (rasterized techniques), 2.7 GB (reference) and 3.6 GB (yu-lod, its LOD BVH), so a
// scene at the limit stays within about 6 GB. Loaders check them before reading the
// geometry where a header gives the counts (glTF accessors, OFF, PLY, STL); OBJ is read
// first (memory a few times the file's size) and refused after.
inline constexpr std::uint64_t kMaxSceneTriangles = std::uint64_t{1} << 24;
inline constexpr std::uint64_t kMaxSceneVertices = std::uint64_t{1} << 25;

// Adds what every loaded scene must have: a default material when there is none, a
// framing camera when there is none; then validates (kMaxSceneTriangles and
// kMaxSceneVertices too). Used by all loaders.
void finish_scene(Scene& scene);

}  // namespace speculum
