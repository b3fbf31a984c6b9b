// `speculum render [SCENE] --technique T -o out.png|exr`: loads a scene, runs the
// technique's graph (apps/pipeline_techniques.h) and writes the image (issue 4).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "apps/pipeline_camera_options.h"
#include "apps/pipeline_techniques.h"
#include "apps/progress.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "parallel/lanes.h"

namespace speculum::cli {
namespace {

struct RenderOptions {
  std::string scene;
  std::string technique = "envmap";
  std::string output = "speculum.png";
  int width = 640;
  int height = 480;
  int spp = 1;
  std::uint32_t seed = 0;
  float exposure = 1.0f;
  bool timings = false;
  float alpha = 0.0f;
  int bounces = 1;
  std::vector<std::string> params;
  pipeline::CameraOverrides camera;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// --param name=value (repeatable) → FrameSettings::params.
std::map<std::string, double> parse_technique_params(const std::vector<std::string>& items) {
  std::map<std::string, double> out;
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    char* end = nullptr;
    const double v = eq == std::string::npos ? 0.0 : std::strtod(item.c_str() + eq + 1, &end);
    if (eq == std::string::npos || eq == 0 || end == item.c_str() + eq + 1 || *end != '\0' ||
        !std::isfinite(v))
      throw InputError("--param", "expected name=number, got '" + item + "'");
    out[item.substr(0, eq)] = v;
  }
  return out;
}

void run_render(const RenderOptions& o, const GlobalOptions& global) {
  if (global.lanes != 0) par::set_default_lanes(global.lanes);
  const pipeline::Technique& technique = pipeline::find_technique(o.technique);
  const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (o.spp < 1 || (k * k != o.spp && technique.name != "reference" &&
                     technique.name != "yu-lod"))
    throw InputError("--spp", "must be a square (1, 4, 9, 16, ...) for k×k supersampling, got " +
                                  std::to_string(o.spp));
  // About 200 bytes per sample pass through the feed-forward pipeline: refuse sizes that
  // could only end in the out-of-memory killer.
  constexpr double kMaxSamples = double(1 << 26);
  if (double(o.width) * o.height * o.spp > kMaxSamples)
    throw InputError("--width/--height/--spp", "more than 67M samples (" + std::to_string(o.width) +
                                                   "x" + std::to_string(o.height) + " x spp " +
                                                   std::to_string(o.spp) + ")");
  if (!ends_with(o.output, ".png") && !ends_with(o.output, ".exr"))
    throw InputError(o.output, "output must end in .png or .exr");
  const Scene scene = load_scene(o.scene.empty() ? default_scene_name() : o.scene);
  pipeline::FrameSettings f;
  f.width = o.width;
  f.height = o.height;
  f.supersample = k;
  f.spp = o.spp;
  f.seed = o.seed;
  f.exposure = o.exposure;
  f.alpha = o.alpha;
  f.bounces = o.bounces;
  f.params = parse_technique_params(o.params);
  f.camera = pipeline::resolve_camera(scene, o.camera);
  par::Executor executor(global.threads);
  par::Graph graph;
  technique.add_passes(graph, &scene, f);
  const bool exr = ends_with(o.output, ".exr");
  graph.request(exr ? pipeline::kRadiance : pipeline::kDisplay);
  // Progress per finished node (a node's first captured output), only for long renders.
  graph.compile();
  Progress progress("render " + technique.name, graph.order().size(), global.quiet);
  std::string last_node;
  const par::RunReport report = graph.run(executor, [&](const par::CapturedOutput& out) {
    if (out.node != last_node) progress.step(out.node), last_node = out.node;
  });
  progress.finish();
  write_image(o.output, graph.get<ImageRGBA>(exr ? pipeline::kRadiance : pipeline::kDisplay));
  if (!global.quiet)
    std::fprintf(stderr, "speculum: %s %s %dx%d spp %d in %.1f ms\n", technique.name.c_str(),
                 scene.name.c_str(), o.width, o.height, o.spp, report.duration_ns * 1e-6);
  if (o.timings)
    for (const auto& node : report.nodes)
      std::fprintf(stderr, "  %-20s %9.2f ms\n", node.name.c_str(), node.duration_ns * 1e-6);
  std::printf("%s\n", std::filesystem::absolute(o.output).string().c_str());
}

}  // namespace

void add_render_command(CLI::App& app, GlobalOptions& global) {
  auto opts = std::make_shared<RenderOptions>();
  auto* cmd = app.add_subcommand("render", "Render a scene with one technique to PNG or EXR");
  cmd->footer(
      "Example: speculum render glossy-plane --technique envmap --width 800 --height 600 --spp 4 -o out.png\n"
      "         speculum render sphere-in-room --technique reference --spp 64 -o ref.exr");
  cmd->fallthrough();  // accept --threads/--lanes after the subcommand too
  cmd->add_option("scene", opts->scene, "glTF/OBJ/PLY file or built-in scene name (default: "
                                        "the default built-in scene)");
  cmd->add_option("--technique,-t", opts->technique, "Technique (see `speculum techniques`)")
      ->capture_default_str();
  cmd->add_option("-o,--output", opts->output, "Output image: .png (tone-mapped) or .exr (linear)")
      ->capture_default_str();
  cmd->add_option("--width", opts->width, "Image width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", opts->height, "Image height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--spp", opts->spp, "Samples per pixel (k×k supersampling: 1, 4, 9, 16)")
      ->capture_default_str();
  cmd->add_option("--seed", opts->seed, "Random seed")->capture_default_str();
  cmd->add_option("--exposure", opts->exposure, "Exposure multiplier before tone mapping")
      ->capture_default_str();
  cmd->add_option("--alpha", opts->alpha, "yu-lod: LOD threshold α of YU eq.7 (0: LOD off)")
      ->check(CLI::Range(0.0f, 1e6f))->capture_default_str();
  cmd->add_option("--bounces", opts->bounces, "Specular bounces (ray-hierarchy, recursive techniques)")
      ->check(CLI::Range(1, 16))->capture_default_str();
  cmd->add_option("--param", opts->params,
                  "Technique parameter name=value, repeatable (see `speculum techniques`)");
  cmd->add_flag("--timings", opts->timings, "Print each pass's wall time on stderr");
  pipeline::add_camera_options(*cmd, opts->camera);
  cmd->callback([opts, &global] { run_render(*opts, global); });
}

}  // namespace speculum::cli
