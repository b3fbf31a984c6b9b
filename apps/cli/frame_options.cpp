// Frame options of `render`, `inspect` and `profile`: see frame_options.h.
#include "apps/cli/frame_options.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.h"
#include "core/lighting_presets.h"
#include "core/scene_loader.h"

namespace speculum::pipeline {

void add_frame_options(CLI::App& cmd, FrameOptions& o) {
  cmd.add_option("scene", o.scene, "glTF/OBJ/PLY/OFF/STL file or built-in scene NAME[:size=N] (size at most 10M; "
                                   "default: the default built-in scene). Any scene holds at most 2^24 triangles "
                                   "and 2^25 vertices, which bounds memory (a few GB)");
  cmd.add_option("--technique,-t", o.technique, "Technique (see `speculum techniques`)")
      ->capture_default_str();
  o.width_option =
      cmd.add_option("--width", o.width,
                     "Image width; width × height × spp at most 2^23 samples (2^22 for ray-hierarchy, "
                     "2^26 for reference and yu-lod) to bound memory")
          ->check(CLI::Range(1, 16384))->capture_default_str();
  o.height_option =
      cmd.add_option("--height", o.height,
                     "Image height (default: from a glTF camera's aspect ratio when it has one)")
          ->check(CLI::Range(1, 16384))->capture_default_str();
  cmd.add_option("--spp", o.spp,
                 "Samples per pixel (a square is k×k supersampling for feed-forward techniques; yu-lod: glossy "
                 "rays per pixel; 0: the technique's default: 8 for yu-lod, else 1)")
      ->check(CLI::Range(0, 65536))->capture_default_str();
  cmd.add_option("--seed", o.seed, "Random seed")->capture_default_str();
  cmd.add_option("--exposure", o.exposure,
                 "Exposure before tone mapping: a multiplier > 0 (1: the radiance unscaled), or auto (meters the frame's "
                 "log-average luminance to middle grey 0.18 and prints the value)")
      ->capture_default_str();
  cmd.add_option("--env", o.env,
                 "Environment light: an equirectangular image (EXR, HDR, PNG, ...), 'sky' (a "
                 "clear sky with a sun) or a colour r,g,b / grey value (linear radiance); "
                 "replaces the scene's own");
  cmd.add_option("--env-intensity", o.env_intensity, "Multiplies the environment's radiance")
      ->capture_default_str();
  cmd.add_option("--env-rotate", o.env_rotate, "Turns the environment about +Y, degrees")
      ->capture_default_str();
  cmd.add_flag("--no-default-light", o.no_default_light,
               "Keep a scene without lights and environment black (default: a studio "
               "environment and key light, with a warning)");
  cmd.add_option("--alpha", o.alpha, "yu-lod: LOD threshold α of YU eq.7 (0: LOD off)")
      ->check(CLI::Range(0.0f, 1e6f))->capture_default_str();
  cmd.add_option("--bounces", o.bounces,
                 "Specular bounces (ray-hierarchy, recursive techniques, reference, specular-reference;\n"
                 "0: the technique's default: 1, reference 8)")
      ->check(CLI::Range(0, 16))->capture_default_str();
  cmd.add_option("--param", o.params,
                 "Technique parameter name=value (a number, or a mode by name), repeatable (see `speculum techniques`)");
  // The maxima bound memory: living-room (the built-in scene with most reflectors) peaks
  // near 2.1 GB at --cube-size 1024 (7.8 GB at 2048) and 1.7 GB at --shadow-size 4096 (6.2 GB
  // at 8192).
  cmd.add_option("--cube-size", o.cube_map_size, "Side of the per-reflector cube maps (~2 GB for many reflectors at 1024; distance-map, planar-mirror, caustics and multi-reflection hold about half as much again, each face's visibility, until their searches have run); envmap, refraction and vertex-projection size each map from its reflector's footprint on screen, up to this")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd.add_option("--shadow-size", o.shadow_map_size, "Side of the shadow maps")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  add_camera_options(cmd, o.camera);
  cmd.add_flag("--strict", o.strict,
               "A missing or undecodable texture, or a missing .mtl file, is an error (exit 2)\n"
               "instead of a warning with the texture or material left out");
  cmd.add_flag("--allow-external-files", o.allow_external_files,
               "Let the scene's image/buffer URIs and .mtl files point outside the scene\n"
               "file's folder (refused by default: one line, exit 2 for glTF)");
  // The technique parameters, from the technique table (after the command's own footer).
  std::string params = "\n\nTechnique parameters (--param name=value: default, valid range or the modes by name, meaning):";
  for (const Technique& t : techniques())
    if (!t.params.empty()) params += "\n  " + t.name + "\n" + t.describe_params("    ");
  cmd.footer(cmd.get_footer() + params);
}

Scene load_frame_scene(const FrameOptions& o, bool quiet) {
  const std::string name = o.scene.empty() ? default_scene_name() : o.scene;
  LoadReport report;
  SceneOptions so;
  so.report = &report;
  so.strict = o.strict;
  so.allow_external_files = o.allow_external_files;
  Scene scene = load_scene(name, so);
  if (!quiet)
    for (const std::string& w : report.warnings)
      std::fprintf(stderr, "speculum: warning: %s: %s\n", name.c_str(), w.c_str());
  return scene;
}

namespace {

// The technique's sample limit bounds memory (rasterized frames keep every sample) or time
// (reference and yu-lod keep pixels); see Technique::max_samples.
void check_sample_count(const Technique& technique, int width, int height, int spp) {
  const double samples = double(width) * double(height) * double(spp);
  if (samples > technique.max_samples)
    throw InputError("--width/--height/--spp",
                     std::to_string(width) + "×" + std::to_string(height) + " at " + std::to_string(spp) +
                         " spp is " + std::to_string(static_cast<long long>(samples)) + " samples; " +
                         technique.name + " takes at most " +
                         std::to_string(static_cast<long long>(technique.max_samples)) + " (2^" +
                         std::to_string(std::ilogb(technique.max_samples)) + ")");
}

}  // namespace

std::map<std::string, double> check_frame_options(const FrameOptions& o) {
  const Technique& technique = find_technique(o.technique);
  check_sample_count(technique, o.width, o.height, technique.resolve_spp(o.spp, o.width, o.height));
  std::map<std::string, double> params;
  for (const std::string& item : o.params) {
    const auto [name, value] = parse_technique_param(technique, item);
    params[name] = value;
  }
  check_technique_params(technique, params);
  return params;
}

FrameSettings make_frame_settings(const FrameOptions& o, const Scene& scene) {
  // A square spp is k×k supersampling for feed-forward techniques; any other count only
  // reaches sample-based techniques (reference, yu-lod) through FrameSettings::spp.
  int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (o.spp <= 0 || k * k != o.spp) k = 1;
  FrameSettings f;
  f.width = o.width;
  f.height = o.height;
  f.camera = resolve_camera(scene, o.camera, float(o.width) / float(o.height));
  // A file camera's aspect ratio decides the side the user did not give; the camera is
  // then resolved again for the final shape (--fit and --view depend on it).
  const bool width_given = o.width_option && o.width_option->count() > 0;
  const bool height_given = o.height_option && o.height_option->count() > 0;
  if (f.camera.aspect > 0.0f && !(width_given && height_given)) {
    auto side = [](double v) { return int(std::clamp(std::lround(v), 1l, 16384l)); };
    if (height_given) f.width = side(o.height * double(f.camera.aspect));
    else f.height = side(o.width / double(f.camera.aspect));
    f.camera = resolve_camera(scene, o.camera, float(f.width) / float(f.height));
  }
  // The side a camera's aspect ratio derived counts against the same limit.
  f.spp = find_technique(o.technique).resolve_spp(o.spp, f.width, f.height);
  check_sample_count(find_technique(o.technique), f.width, f.height, f.spp);
  f.supersample = k;
  f.seed = o.seed;
  const Exposure exposure = parse_exposure(o.exposure);
  f.exposure = exposure.value;
  f.auto_exposure = exposure.automatic;
  f.alpha = o.alpha;
  f.bounces = o.bounces;
  f.cube_map_size = o.cube_map_size;
  f.shadow_map_size = o.shadow_map_size;
  f.params = check_frame_options(o);
  return f;
}

Exposure parse_exposure(const std::string& text) {
  if (text == "auto") return {true, 1.0f};
  char* end = nullptr;
  const float v = std::strtof(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || !(v > 0.0f))
    throw InputError("--exposure", "expected auto or a finite number > 0, got '" + text + "'");
  return {false, v};
}

namespace {

// "v" or "r,g,b" → a colour; false when `text` is not a list of 1 or 3 numbers.
bool parse_colour(const std::string& text, glm::vec3& colour) {
  std::vector<float> values;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, comma - begin);
    char* end = nullptr;
    const float v = std::strtof(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) return false;
    values.push_back(v);
    begin = comma + 1;
  }
  if (values.size() == 1) values = {values[0], values[0], values[0]};
  if (values.size() != 3) return false;
  colour = glm::vec3(values[0], values[1], values[2]);
  return true;
}

glm::vec3 rotate_y(const glm::vec3& d, float degrees) {
  const float t = glm::radians(degrees), c = std::cos(t), s = std::sin(t);
  return {c * d.x + s * d.z, d.y, -s * d.x + c * d.z};
}

}  // namespace

Environment parse_environment(const std::string& text, float rotate_degrees) {
  Environment env;
  glm::vec3 colour;
  if (text == "sky") {
    // The sun is turned before baking, so the disk stays sharp and its energy exact.
    env.equirect = clear_sky_equirect(512, 256, rotate_y(default_sky_sun(), rotate_degrees));
    env.source = "sky";
  } else if (parse_colour(text, colour)) {
    for (int i = 0; i < 3; ++i)
      if (!(std::isfinite(colour[i]) && colour[i] >= 0.0f))
        throw InputError("--env", "a colour needs finite values >= 0, got '" + text + "'");
    env.constant = colour;
    env.source = "--env " + text;
  } else {
    if (text.empty()) throw InputError("--env", "expected an image file, 'sky' or a colour r,g,b");
    env.equirect = read_image(text);
    for (glm::vec4& p : env.equirect.pixels) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw InputError(text, "the environment image has non-finite pixels");
      p = glm::vec4(glm::max(glm::vec3(p), glm::vec3(0.0f)), 1.0f);
    }
    if (rotate_degrees != 0.0f) env.equirect = rotate_equirect(env.equirect, rotate_degrees);
    env.source = text;
  }
  return env;
}

std::vector<std::string> apply_light_options(const FrameOptions& o, Scene& scene, const Camera& camera) {
  if (!std::isfinite(o.env_intensity) || o.env_intensity < 0.0f)
    throw InputError("--env-intensity", "expected a finite number >= 0");
  if (!std::isfinite(o.env_rotate)) throw InputError("--env-rotate", "expected a finite angle in degrees");
  if (!o.env.empty()) {
    scene.environment = parse_environment(o.env, o.env_rotate);
  } else if (o.env_rotate != 0.0f && scene.environment.has_image()) {
    scene.environment.equirect = rotate_equirect(scene.environment.equirect, o.env_rotate);
  }
  scene.environment.intensity *= o.env_intensity;
  std::vector<std::string> warnings;
  if (!o.no_default_light && scene_is_unlit(scene)) {
    add_studio_light(scene, camera);
    warnings.push_back("speculum: warning: " + scene.name +
                       ": no lights and no environment; using the default studio light "
                       "(see --env, --no-default-light)");
  }
  return warnings;
}

}  // namespace speculum::pipeline
