// Frame options of `render`, `inspect` and `profile`: see frame_options.h.
#include "apps/cli/frame_options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum::pipeline {

void add_frame_options(CLI::App& cmd, FrameOptions& o) {
  cmd.add_option("scene", o.scene, "glTF/OBJ/PLY file or built-in scene name (default: the "
                                   "default built-in scene)");
  cmd.add_option("--technique,-t", o.technique, "Technique (see `speculum techniques`)")
      ->capture_default_str();
  cmd.add_option("--width", o.width, "Image width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd.add_option("--height", o.height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd.add_option("--spp", o.spp, "Samples per pixel (a square is k×k supersampling for feed-forward techniques)")
      ->check(CLI::Range(1, 65536))->capture_default_str();
  cmd.add_option("--seed", o.seed, "Random seed")->capture_default_str();
  cmd.add_option("--exposure", o.exposure, "Exposure multiplier before tone mapping")
      ->capture_default_str();
  cmd.add_option("--alpha", o.alpha, "yu-lod: LOD threshold α of YU eq.7 (0: LOD off)")
      ->check(CLI::Range(0.0f, 1e6f))->capture_default_str();
  cmd.add_option("--bounces", o.bounces,
                 "Specular bounces (ray-hierarchy, recursive techniques, reference, specular-reference;\n"
                 "0: the technique's default: 1, reference 8)")
      ->check(CLI::Range(0, 16))->capture_default_str();
  cmd.add_option("--param", o.params,
                 "Technique parameter name=value, repeatable (see `speculum techniques`)");
  cmd.add_option("--cube-size", o.cube_map_size, "Side of the per-reflector cube maps")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd.add_option("--shadow-size", o.shadow_map_size, "Side of the shadow maps")
      ->check(CLI::Range(1, 8192))->capture_default_str();
  add_camera_options(cmd, o.camera);
  cmd.add_flag("--strict", o.strict,
               "A missing or undecodable texture, or a missing .mtl file, is an error (exit 2)\n"
               "instead of a warning with the texture or material left out");
  // The technique parameters, from the technique table (after the command's own footer).
  std::string params = "\n\nTechnique parameters (--param name=value; default, [valid range]):";
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
  Scene scene = load_scene(name, so);
  if (!quiet)
    for (const std::string& w : report.warnings)
      std::fprintf(stderr, "speculum: warning: %s: %s\n", name.c_str(), w.c_str());
  return scene;
}

FrameSettings make_frame_settings(const FrameOptions& o, const Scene& scene) {
  // A square spp is k×k supersampling for feed-forward techniques; any other count only
  // reaches sample-based techniques (reference, yu-lod) through FrameSettings::spp.
  int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (k * k != o.spp) k = 1;
  if (double(o.width) * o.height * o.spp > double(1 << 26))
    throw InputError("--width/--height/--spp", "more than 67M samples");
  FrameSettings f;
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
  for (const std::string& item : o.params) {
    const auto eq = item.find('=');
    char* end = nullptr;
    const double v = eq == std::string::npos ? 0.0 : std::strtod(item.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || end == item.c_str() + eq + 1 || *end != '\0' ||
        !std::isfinite(v))
      throw InputError("--param", "expected name=number, got '" + item + "'");
    f.params[item.substr(0, eq)] = v;
  }
  check_technique_params(find_technique(o.technique), f.params);
  f.camera = resolve_camera(scene, o.camera);
  return f;
}

}  // namespace speculum::pipeline
