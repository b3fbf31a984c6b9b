// `speculum render [SCENE] --technique T -o out.png|exr`: loads a scene, runs the
// technique's graph (apps/techniques/technique_table.h) and writes the image.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/cli/commands.h"
#include "apps/cli/frame_options.h"
#include "apps/techniques/technique_table.h"
#include "apps/cli/progress.h"
#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

struct RenderOptions {
  pipeline::FrameOptions frame;  // scene, technique, size, spp, parameters, camera
  std::string output = "speculum.png";
  bool timings = false;
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

void run_render(const RenderOptions& opts, const GlobalOptions& global) {
  const pipeline::FrameOptions& o = opts.frame;
  const pipeline::Technique& technique = pipeline::find_technique(o.technique);
  const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (k * k != o.spp && technique.name != "reference" && technique.name != "yu-lod")
    throw InputError("--spp", "must be a square (1, 4, 9, 16, ...) for k×k supersampling, got " +
                                  std::to_string(o.spp));
  if (!ends_with(opts.output, ".png") && !ends_with(opts.output, ".exr"))
    throw InputError(opts.output, "output must end in .png or .exr");
  Scene scene = pipeline::load_frame_scene(o, global.quiet);
  const pipeline::FrameSettings f = pipeline::make_frame_settings(o, scene);
  for (const std::string& warning : pipeline::apply_light_options(o, scene, f.camera))
    if (!global.quiet) std::fprintf(stderr, "%s\n", warning.c_str());
  par::Executor executor(global.threads, global.lanes);
  par::Graph graph;
  const pipeline::FrameOutputs outputs = technique.add_passes(graph, &scene, f);
  const bool exr = ends_with(opts.output, ".exr");
  const par::Resource<ImageRGBA>& image = exr ? outputs.radiance : outputs.display;
  graph.request(image);
  // Progress per finished node (a node's first captured output), only for long renders.
  graph.compile();
  Progress progress("render " + technique.name, graph.order().size(), global.quiet);
  std::string last_node;
  const par::RunReport report = graph.run(executor, [&](const par::CapturedOutput& out) {
    if (out.node != last_node) progress.step(out.node), last_node = out.node;
  });
  progress.finish();
  write_image(opts.output, graph.get(image));
  // The metered exposure (the tonemap pass records it; an EXR skips that pass).
  for (const auto& node : report.nodes)
    if (const auto it = node.counters.find("exposure");
        f.auto_exposure && !global.quiet && it != node.counters.end())
      std::fprintf(stderr, "speculum: exposure auto: %.6g\n", it->second);
  if (!global.quiet)
    std::fprintf(stderr, "speculum: %s %s %dx%d spp %d in %.1f ms\n", technique.name.c_str(),
                 scene.name.c_str(), f.width, f.height, o.spp, report.duration_ns * 1e-6);
  if (opts.timings)
    for (const auto& node : report.nodes)
      std::fprintf(stderr, "  %-20s %9.2f ms\n", node.name.c_str(), node.duration_ns * 1e-6);
  std::printf("%s\n", std::filesystem::absolute(opts.output).string().c_str());
}

}  // namespace

void add_render_command(CLI::App& app, GlobalOptions& global) {
  auto opts = std::make_shared<RenderOptions>();
  auto* cmd = app.add_subcommand("render", "Render a scene with one technique to PNG or EXR");
  cmd->footer(
      "Example: speculum render glossy-plane --technique envmap --width 800 --height 600 --spp 4 -o out.png\n"
      "         speculum render sphere-in-room --technique reference --spp 64 -o ref.exr\n"
      "         speculum render model.glb --env sky --view three-quarter -o model.png");
  opts->frame.width = 640;  // render's defaults; inspect and profile use smaller frames
  opts->frame.height = 480;
  opts->frame.exposure = "auto";  // a user's own scene in any units; comparisons pass 1
  pipeline::add_frame_options(*cmd, opts->frame);
  cmd->add_option("-o,--output", opts->output, "Output image: .png (tone-mapped) or .exr (linear)")
      ->capture_default_str();
  cmd->add_flag("--timings", opts->timings, "Print each pass's wall time on stderr");
  cmd->callback([opts, &global] { run_render(*opts, global); });
}

}  // namespace speculum::cli
