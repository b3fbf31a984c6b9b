// Frame options of `render`, `inspect` and `profile`: see frame_options.h.
#include "apps/cli/frame_options.h"

#include <cmath>
#include <cstdlib>
#include <map>
#include <string>

#include "core/error.h"

namespace speculum::pipeline {

void add_frame_options(CLI::App& cmd, FrameOptions& o) {
  cmd.add_option("scene", o.scene, "glTF/OBJ/PLY file or built-in scene name (default: the "
                                   "default built-in scene)");
  cmd.add_option("--technique,-t", o.technique, "Technique (see `speculum techniques`)")
      ->capture_default_str();
  cmd.add_option("--width", o.width,
                 "Image width; width × height × spp at most 2^23 samples (2^22 for ray-hierarchy, "
                 "2^26 for reference and yu-lod) to bound memory")
      ->check(CLI::Range(1, 16384))->capture_default_str();
  cmd.add_option("--height", o.height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd.add_option("--spp", o.spp, "Samples per pixel (a square is k×k supersampling for feed-forward techniques)")
      ->check(CLI::Range(1, 65536))->capture_default_str();
  cmd.add_option("--seed", o.seed, "Random seed")->capture_default_str();
  cmd.add_option("--exposure", o.exposure, "Exposure multiplier before tone mapping")
      ->capture_default_str();
  cmd.add_option("--alpha", o.alpha, "yu-lod: LOD threshold α of YU eq.7 (0: LOD off)")
      ->check(CLI::Range(0.0f, 1e6f))->capture_default_str();
  cmd.add_option("--bounces", o.bounces, "Specular bounces (ray-hierarchy, recursive techniques)")
      ->check(CLI::Range(1, 16))->capture_default_str();
  cmd.add_option("--param", o.params,
                 "Technique parameter name=value, repeatable (see `speculum techniques`)");
  // The maxima bound memory: living-room (the built-in scene with most reflectors) peaks
  // near 2.1 GB at --cube-size 1024 (7.8 GB at 2048) and 1.7 GB at --shadow-size 4096 (6.2 GB
  // at 8192).
  cmd.add_option("--cube-size", o.cube_map_size, "Side of the per-reflector cube maps (~2 GB for many reflectors at 1024)")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd.add_option("--shadow-size", o.shadow_map_size, "Side of the shadow maps")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  add_camera_options(cmd, o.camera);
  // The technique parameters, from the technique table (after the command's own footer).
  std::string params = "\n\nTechnique parameters (--param name=value: default, type and valid range, meaning):";
  for (const Technique& t : techniques())
    if (!t.params.empty()) params += "\n  " + t.name + "\n" + t.describe_params("    ");
  cmd.footer(cmd.get_footer() + params);
}

std::map<std::string, double> check_frame_options(const FrameOptions& o) {
  const Technique& technique = find_technique(o.technique);
  // The technique's sample limit bounds memory (rasterized frames keep every sample) or time
  // (reference and yu-lod keep pixels); see Technique::max_samples.
  const double samples = double(o.width) * double(o.height) * double(o.spp);
  if (samples > technique.max_samples)
    throw InputError("--width/--height/--spp",
                     std::to_string(o.width) + "×" + std::to_string(o.height) + " at " + std::to_string(o.spp) +
                         " spp is " + std::to_string(static_cast<long long>(samples)) + " samples; " +
                         technique.name + " takes at most " +
                         std::to_string(static_cast<long long>(technique.max_samples)) + " (2^" +
                         std::to_string(std::ilogb(technique.max_samples)) + ")");
  std::map<std::string, double> params;
  for (const std::string& item : o.params) {
    const auto eq = item.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError("--param", "expected name=number, got '" + item + "'");
    const std::string name = item.substr(0, eq), text = item.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0')
      throw InputError("--param " + name, "expected a number, got '" + item + "'");
    if (!std::isfinite(v)) throw InputError("--param " + name, "expected a finite number, got '" + item + "'");
    params[name] = v;
  }
  check_technique_params(technique, params);
  return params;
}

FrameSettings make_frame_settings(const FrameOptions& o, const Scene& scene) {
  // A square spp is k×k supersampling for feed-forward techniques; any other count only
  // reaches sample-based techniques (reference, yu-lod) through FrameSettings::spp.
  int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (k * k != o.spp) k = 1;
  FrameSettings f;
  f.params = check_frame_options(o);
  f.width = o.width;
  f.height = o.height;
  f.supersample = k;
  f.spp = o.spp;
  f.seed = o.seed;
  f.exposure = o.exposure;
  f.alpha = o.alpha;
  f.bounces = o.bounces;
  f.cube_map_size = o.cube_map_size;
  f.shadow_map_size = o.shadow_map_size;
  f.camera = resolve_camera(scene, o.camera);
  return f;
}

}  // namespace speculum::pipeline
