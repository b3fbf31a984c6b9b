// load_scene: dispatch by extension or built-in name, then finish_scene (see scene_loader.h).
#include "core/scene_loader.h"

#include <algorithm>
#include <set>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "core/camera_rays.h"
#include "core/did_you_mean.h"
#include "core/error.h"
#include "core/gltf_loader.h"
#include "core/mesh_loader.h"
#include "core/obj_loader.h"
#include "core/procedural_scenes.h"

namespace speculum {
namespace {

// " (did you mean 'sphere-in-room'?)" for a misspelt built-in scene name, else "".
std::string scene_suggestion(const std::string& spec) {
  std::vector<std::string> names;
  for (const BuiltinScene& s : builtin_scenes()) names.emplace_back(s.name);
  return did_you_mean(spec.substr(0, spec.find(':')), names);
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// "12000", "20k", "1.5M" → a number; throws on anything else.
double parse_number(const std::string& source, const std::string& key, const std::string& text) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    throw InputError(source, "option " + key + "='" + text + "' is not a number");
  }
  const std::string rest = text.substr(used);
  if (rest == "k" || rest == "K") v *= 1e3;
  else if (rest == "m" || rest == "M") v *= 1e6;
  else if (!rest.empty()) throw InputError(source, "option " + key + "='" + text + "' is not a number");
  if (!std::isfinite(v)) throw InputError(source, "option " + key + " is not finite");
  return v;
}

// True when `key` is one of the names in `extra_params` ("n=8 (bump frequency), amplitude=0.06"):
// a whole name, so "" or "mplitude" is an unknown option rather than a match inside one.
bool takes_option(std::string_view extra_params, const std::string& key) {
  if (key.empty()) return false;
  for (std::size_t at = extra_params.find(key + "="); at != std::string_view::npos;
       at = extra_params.find(key + "=", at + 1))
    if (at == 0 || extra_params[at - 1] == ' ') return true;
  return false;
}

}  // namespace

BuiltinSpec parse_builtin_spec(const std::string& spec, std::uint64_t default_size) {
  const std::size_t colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  const BuiltinScene* def = find_builtin_scene(name);
  if (!def)
    throw InputError(spec, "no such built-in scene" + scene_suggestion(spec) + " (see `speculum scenes list`)");
  BuiltinParams params;
  params.size = default_size ? default_size : def->default_size;
  if (colon != std::string::npos) {
    std::string rest = spec.substr(colon + 1);
    std::replace(rest.begin(), rest.end(), ':', ',');
    std::size_t at = 0;
    std::set<std::string> seen;
    while (at <= rest.size()) {
      const std::size_t end = std::min(rest.find(',', at), rest.size());
      const std::string item = rest.substr(at, end - at);
      at = end + 1;
      if (item.empty()) continue;
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos) throw InputError(spec, "expected key=value, got '" + item + "'");
      const std::string key = item.substr(0, eq);
      // A key given twice is a typo or a generated spec gone wrong: which one was meant is unknowable.
      if (!seen.insert(key).second) throw InputError(spec, "option '" + key + "' is given twice");
      const double value = parse_number(spec, key, item.substr(eq + 1));
      if (key == "size") {
        if (value < 0 || value > 1e12) throw InputError(spec, "size out of range");
        if (value != std::floor(value)) throw InputError(spec, "size must be a whole number");
        params.size = static_cast<std::uint64_t>(value);
      } else if (takes_option(def->extra_params, key)) {
        params.extra[key] = value;
      } else {
        throw InputError(spec, "unknown option '" + key + "' (scene takes size=N" +
                                   (*def->extra_params ? std::string(", ") + def->extra_params : "") + ")");
      }
    }
  }
  if (params.size < kMinSceneSize || params.size > kMaxSceneSize)
    throw InputError(spec, "size " + std::to_string(params.size) + " outside [" +
                               std::to_string(kMinSceneSize) + ", " + std::to_string(kMaxSceneSize) + "]");
  if (const double n = params.get("n", 8.0); !(n >= 0.0 && n <= 1000.0))
    throw InputError(spec, "n must be in [0, 1000]");
  if (const double a = params.get("amplitude", 0.06); !(a >= 0.0 && a <= 0.5))
    throw InputError(spec, "amplitude must be in [0, 0.5]");
  if (const double r = params.get("reflectors", 8.0); !(r >= 8.0 && r <= 40.0 && r == std::floor(r)))
    throw InputError(spec, "reflectors must be a whole number in [8, 40]");
  return {def, std::move(params)};
}

namespace {

Scene build_builtin(const std::string& spec, const SceneOptions& options) {
  const BuiltinSpec parsed = parse_builtin_spec(spec, options.size);
  Scene scene = parsed.scene->build(parsed.params);
  scene.name = spec;
  return scene;
}

}  // namespace

void LoadReport::warn(std::string message) {
  if (std::find(warnings.begin(), warnings.end(), message) == warnings.end())
    warnings.push_back(std::move(message));
}

void LoadReport::substitute(const std::string& source, std::string message) {
  if (strict) throw InputError(source, message + " (--strict)");
  warn(std::move(message));
}

const char* default_scene_name() { return "sphere-in-room"; }

bool is_builtin_scene_name(const std::string& file_or_name) {
  return find_builtin_scene(file_or_name.substr(0, file_or_name.find(':'))) != nullptr;
}

void finish_scene(Scene& scene) {
  if (scene.mesh.triangle_count() > kMaxSceneTriangles)
    throw InputError(scene.name, std::to_string(scene.mesh.triangle_count()) + " triangles: more than the limit of " +
                                     std::to_string(kMaxSceneTriangles) + " (2^24)");
  if (scene.mesh.vertex_count() > kMaxSceneVertices)
    throw InputError(scene.name, std::to_string(scene.mesh.vertex_count()) + " vertices: more than the limit of " +
                                     std::to_string(kMaxSceneVertices) + " (2^25)");
  if (scene.materials.empty()) scene.materials.push_back(default_material());
  if (scene.cameras.empty()) scene.cameras.push_back(framing_camera(scene.bounds()));
  for (const Camera& c : scene.cameras) validate_camera(c, scene.name);
  scene.validate();
}

Scene load_scene(const std::string& file_or_name, const SceneOptions& options) {
  if (file_or_name.empty()) throw InputError("(empty)", "no scene file or name given");
  const std::string ext = lower_extension(file_or_name);
  // Loaders always get a report, so --strict holds even when the caller keeps no warnings.
  LoadReport local;
  LoadReport* report = options.report ? options.report : &local;
  report->strict = report->strict || options.strict;
  report->allow_external_files = report->allow_external_files || options.allow_external_files;
  Scene scene;
  if (ext == ".gltf" || ext == ".glb") {
    scene = load_gltf(file_or_name, report);
  } else if (ext == ".obj") {
    scene = load_obj(file_or_name, *report);
  } else if (ext == ".ply" || ext == ".off" || ext == ".stl") {
    scene = load_mesh_file(file_or_name, report);
  } else if (is_builtin_scene_name(file_or_name)) {
    scene = build_builtin(file_or_name, options);
  } else {
    std::error_code ec;
    if (std::filesystem::exists(file_or_name, ec))
      throw InputError(file_or_name, "unsupported file extension '" + ext +
                                         "' (expected .gltf, .glb, .obj, .ply, .off or .stl)");
    throw InputError(file_or_name, "no such file or built-in scene" + scene_suggestion(file_or_name) +
                                       " (see `speculum scenes list`)");
  }
  finish_scene(scene);
  return scene;
}

}  // namespace speculum
