// See fuzz_entries.h.
#include "tests/fuzz/fuzz_entries.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/image.h"
#include "core/scene_loader.h"
#include "trace/ray_file.h"

namespace speculum::fuzz {
namespace {

namespace fs = std::filesystem;

// One folder per process, so fuzzers running side by side (libFuzzer -jobs) do not share files.
const fs::path& work_dir() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("speculum-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void write_file(const fs::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("fuzz harness: cannot write " + path.string());
}

std::string_view as_text(std::span<const std::uint8_t> bytes) {
  return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

// Writes `bytes` as fuzz<ext>; the part after kPartMarker, if any, as fuzz<companion_ext>
// (removed otherwise, so a previous input's companion never leaks into this one).
std::string write_parts(std::span<const std::uint8_t> bytes, const char* ext, const char* companion_ext) {
  const std::string_view text = as_text(bytes);
  const fs::path main = work_dir() / (std::string("fuzz") + ext);
  const std::size_t at = companion_ext ? text.find(kPartMarker) : std::string_view::npos;
  if (!companion_ext) {
    write_file(main, text);
    return main.string();
  }
  const fs::path companion = work_dir() / (std::string("fuzz") + companion_ext);
  std::error_code ec;
  fs::remove(companion, ec);
  if (at == std::string_view::npos) {
    write_file(main, text);
  } else {
    write_file(main, text.substr(0, at));
    write_file(companion, text.substr(at + kPartMarker.size()));
  }
  return main.string();
}

Outcome load_as(std::span<const std::uint8_t> bytes, const char* ext, const char* companion_ext) {
  const std::string path = write_parts(bytes, ext, companion_ext);
  try {
    LoadReport report;
    SceneOptions options;
    options.report = &report;
    (void)load_scene(path, options);
    return Outcome::loaded;
  } catch (const InputError&) {
    return Outcome::rejected;
  }
}

Outcome run_gltf(std::span<const std::uint8_t> b) { return load_as(b, ".gltf", ".bin"); }
Outcome run_glb(std::span<const std::uint8_t> b) { return load_as(b, ".glb", ".bin"); }
Outcome run_obj(std::span<const std::uint8_t> b) { return load_as(b, ".obj", ".mtl"); }
Outcome run_ply(std::span<const std::uint8_t> b) { return load_as(b, ".ply", nullptr); }
Outcome run_off(std::span<const std::uint8_t> b) { return load_as(b, ".off", nullptr); }
Outcome run_stl(std::span<const std::uint8_t> b) { return load_as(b, ".stl", nullptr); }

Outcome run_ray_file(std::span<const std::uint8_t> b) {
  const std::string path = write_parts(b, ".spry", nullptr);
  try {
    (void)trace::read_ray_file(path);
    return Outcome::loaded;
  } catch (const InputError&) {
    return Outcome::rejected;
  }
}

// OpenImageIO picks its reader by extension and falls back to trying every format, as it
// does for a user's --env file; the extension follows the magic so each reader is reached.
const char* image_extension(std::string_view t) {
  if (t.starts_with("\x89PNG")) return ".png";
  if (t.starts_with("\xff\xd8")) return ".jpg";
  if (t.starts_with("\x76\x2f\x31\x01")) return ".exr";
  if (t.starts_with("#?")) return ".hdr";
  return ".tga";
}

Outcome run_image(std::span<const std::uint8_t> b) {
  const std::string path = write_parts(b, image_extension(as_text(b)), nullptr);
  try {
    (void)read_image(path);
    return Outcome::loaded;
  } catch (const InputError&) {
    return Outcome::rejected;
  }
}

Outcome run_scene_spec(std::span<const std::uint8_t> b) {
  const std::string spec(as_text(b));
  try {
    const BuiltinSpec parsed = parse_builtin_spec(spec);
    if (parsed.params.size <= kMaxFuzzSceneSize) {
      Scene scene = parsed.scene->build(parsed.params);
      scene.name = spec;
      finish_scene(scene);
    }
    return Outcome::loaded;
  } catch (const InputError&) {
    return Outcome::rejected;
  }
}

constexpr Target kTargets[] = {
    {"gltf", ".gltf JSON (data URIs; an external buffer after the part marker)", run_gltf},
    {"glb", "binary glTF (an external buffer after the part marker)", run_glb},
    {"obj", "Wavefront OBJ (its .mtl after the part marker)", run_obj},
    {"ply", "PLY, ASCII or binary", run_ply},
    {"off", "OFF", run_off},
    {"stl", "STL, ASCII or binary", run_stl},
    {"ray_file", "SPRY ray file", run_ray_file},
    {"image", "environment image (OpenImageIO: PNG, JPEG, EXR, HDR, TGA, ...)", run_image},
    {"scene_spec", "built-in scene spec NAME:size=N,key=value", run_scene_spec},
};

}  // namespace

std::span<const Target> targets() { return kTargets; }

const Target* find_target(std::string_view name) {
  for (const Target& t : kTargets)
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace speculum::fuzz
