// `speculum render [SCENE] --technique T -o out.png|exr`: loads a scene, runs the
// technique's graph (apps/techniques/technique_table.h) and writes the image.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/cli/aov_output.h"
#include "apps/cli/commands.h"
#include "apps/cli/frame_options.h"
#include "apps/techniques/technique_table.h"
#include "apps/cli/progress.h"
#include "core/error.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "raster/visibility.h"

namespace speculum::cli {
namespace {

struct RenderOptions {
  pipeline::FrameOptions frame;  // scene, technique, size, spp, parameters, camera
  std::string output = "speculum.png";
  std::string aov;  // "albedo,normal,depth": G-buffer layers of the EXR
  bool aov_given = false;
  bool timings = false;
  std::string path;    // --path NAME: a built-in scene's camera path
  std::string frames;  // --frames A..B of that path
};

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "A..B" (or "A"): the inclusive frame range of --frames.
std::pair<int, int> parse_frame_range(const std::string& text) {
  const auto dots = text.find("..");
  const std::string a = text.substr(0, dots), b = dots == std::string::npos ? a : text.substr(dots + 2);
  const auto whole = [&](const std::string& s) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos)
      throw InputError("--frames", "expected A..B with whole numbers A <= B, got '" + text + "'");
    return std::stoi(s);
  };
  const int first = whole(a), last = whole(b);
  if (first > last) throw InputError("--frames", "empty range '" + text + "' (the first frame is after the last)");
  return {first, last};
}

// The output name of `frame`: the run of '#' in `pattern` replaced by the zero-padded number.
std::string frame_file(const std::string& pattern, int frame) {
  const auto first = pattern.find('#');
  const auto last = pattern.find_first_not_of('#', first);
  const std::size_t width = (last == std::string::npos ? pattern.size() : last) - first;
  std::string number = std::to_string(frame);
  if (number.size() < width) number.insert(0, width - number.size(), '0');
  return pattern.substr(0, first) + number + (last == std::string::npos ? "" : pattern.substr(last));
}

// --path NAME --frames A..B: each frame of the path rendered independently (the same bytes
// as rendering that camera alone) and written to the output pattern, a progress bar over
// the frames.
void run_render_path(const RenderOptions& opts, const GlobalOptions& global) {
  const pipeline::FrameOptions& o = opts.frame;
  const pipeline::Technique& technique = pipeline::find_technique(o.technique);
  if (opts.output.find('#') == std::string::npos)
    throw InputError("-o", "a --path render needs a file pattern with '#' for the frame number, e.g. f_####.png; got '" +
                               opts.output + "'");
  if (opts.aov_given) throw InputError("--aov", "not available with --path");
  if (opts.frames.empty()) throw InputError("--frames", "--path needs --frames A..B");
  const auto [first, last] = parse_frame_range(opts.frames);
  const std::string base = o.scene.substr(0, o.scene.find(':'));
  const std::vector<CameraPath> paths = builtin_camera_paths(base);
  const CameraPath* path = nullptr;
  std::string known;
  for (const CameraPath& p : paths) {
    if (p.name == opts.path) path = &p;
    known += (known.empty() ? "" : ", ") + p.name;
  }
  if (!path)
    throw InputError("--path", "unknown path '" + opts.path + "' for scene '" + base + "' (" +
                                   (known.empty() ? std::string("it has no camera paths") : "known: " + known) + ")");
  if (last >= path->frames)
    throw InputError("--frames", "frame " + std::to_string(last) + " is past the end of path '" + path->name +
                                     "' (frames 0.." + std::to_string(path->frames - 1) + ")");
  pipeline::check_frame_options(o);
  Scene scene = pipeline::load_frame_scene(o, global.quiet);
  const pipeline::FrameSettings base_settings = pipeline::make_frame_settings(o, scene);
  par::Executor executor(global.threads, global.lanes);
  const bool exr = ends_with(opts.output, ".exr");
  Progress progress("render " + path->name, std::size_t(last - first + 1), global.quiet);
  for (int frame = first; frame <= last; ++frame) {
    pipeline::FrameSettings f = base_settings;
    f.camera = path->at(frame);
    par::Graph graph;
    const pipeline::FrameOutputs outputs = technique.add_passes(graph, &scene, f);
    const par::Resource<ImageRGBA>& image = exr ? outputs.radiance : outputs.display;
    graph.request(image);
    graph.run(executor);
    const std::string file = frame_file(opts.output, frame);
    write_image(file, graph.get(image));
    progress.step(file);
    std::printf("%s\n", std::filesystem::absolute(file).string().c_str());
  }
  progress.finish();
}

void run_render(const RenderOptions& opts, const GlobalOptions& global) {
  if (!opts.path.empty()) return run_render_path(opts, global);
  if (!opts.frames.empty()) throw InputError("--frames", "needs --path NAME (a built-in scene's camera path)");
  const pipeline::FrameOptions& o = opts.frame;
  const pipeline::Technique& technique = pipeline::find_technique(o.technique);
  const int k = static_cast<int>(std::lround(std::sqrt(static_cast<double>(o.spp))));
  if (k * k != o.spp && technique.name != "reference" && technique.name != "yu-lod")
    throw InputError("--spp", "must be a square (1, 4, 9, 16, ...) for k×k supersampling, got " +
                                  std::to_string(o.spp));
  if (!ends_with(opts.output, ".png") && !ends_with(opts.output, ".exr"))
    throw InputError(opts.output, "output must end in .png or .exr");
  const std::vector<std::string> aovs = opts.aov_given ? parse_aovs(opts.aov) : std::vector<std::string>{};
  if (!aovs.empty() && !ends_with(opts.output, ".exr"))
    throw InputError("--aov", "layers need an .exr output, got '" + opts.output + "'");
  pipeline::check_frame_options(o);  // before a possibly long scene load
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
  // --aov: the technique's own G-buffer (the node `gbuffer` of the rasterized techniques),
  // taken as it is produced; a technique without one (the reference tracer) gets the same two
  // raster passes at the output size: its first hits at the pixel centres.
  AovLayers layers;
  par::Resource<raster::GBuffer> own_gbuffer;
  if (!aovs.empty()) {
    const auto& nodes = graph.nodes();
    if (std::none_of(nodes.begin(), nodes.end(), [](const auto& n) { return n.name == "gbuffer"; })) {
      auto vis = graph.add("aov_visibility", raster::VisibilityPass{&scene, f.camera, f.width, f.height});
      own_gbuffer = graph.add("aov_gbuffer", raster::GBufferPass{&scene, f.camera.eye}, vis);
      graph.request(own_gbuffer);
    }
  }
  auto take_aovs = [&](const raster::GBuffer& g) {
    layers = make_aov_layers(g, std::max(1, g.width / f.width), f.camera, aovs);
  };
  // Progress per finished node (a node's first captured output), only for long renders.
  graph.compile();
  Progress progress("render " + technique.name, graph.order().size(), global.quiet);
  std::string last_node;
  par::RunReport report;
  {
    WorkPoller poller(executor, progress);  // the bar moves inside long passes too
    report = graph.run(executor, [&](const par::CapturedOutput& out) {
      if (out.node != last_node) progress.step(out.node), last_node = out.node;
      if (!aovs.empty() && !own_gbuffer && out.node == "gbuffer")
        if (const auto* g = out.as<raster::GBuffer>()) take_aovs(*g);
    });
  }
  progress.finish();
  if (own_gbuffer) take_aovs(graph.get(own_gbuffer));
  if (aovs.empty()) {
    write_image(opts.output, graph.get(image));
  } else {
    const ImageRGBA& beauty = graph.get(image);
    const std::size_t nc = 4 + layers.names.size();
    std::vector<std::string> names = {"R", "G", "B", "A"};
    names.insert(names.end(), layers.names.begin(), layers.names.end());
    std::vector<float> data(beauty.size() * nc);
    for (std::size_t i = 0; i < beauty.size(); ++i) {
      const glm::vec4 c = beauty.pixels[i];
      float* p = &data[i * nc];
      p[0] = c.x, p[1] = c.y, p[2] = c.z, p[3] = c.w;
      std::copy_n(&layers.data[i * layers.names.size()], layers.names.size(), p + 4);
    }
    write_exr_channels(opts.output, beauty.width, beauty.height, names, data);
  }
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
      "         speculum render model.glb --env sky --view three-quarter -o model.png\n"
      "         speculum render bathroom --technique soff --path walk --frames 0..59 -o f_####.png");
  opts->frame.width = 640;  // render's defaults; inspect and profile use smaller frames
  opts->frame.height = 480;
  opts->frame.exposure = "auto";  // a user's own scene in any units; comparisons pass 1
  pipeline::add_frame_options(*cmd, opts->frame);
  cmd->add_option("-o,--output", opts->output, "Output image: .png (tone-mapped) or .exr (linear)")
      ->capture_default_str();
  cmd->add_option("--aov", opts->aov,
                  "G-buffer layers to add to the .exr output, comma-separated: albedo (base colour), "
                  "normal (world), depth (camera-space Z; +inf on the background), position "
                  "(world), roughness; named albedo.R, normal.X, depth.Z, ... For a denoiser or a "
                  "compositor. The reference tracer's are its first hits at the pixel centres");
  cmd->add_flag("--timings", opts->timings, "Print each pass's wall time on stderr");
  cmd->add_option("--path", opts->path,
                  "A built-in scene's camera path (bathroom: walk, pan; living-room: walk, orbit): renders "
                  "--frames A..B of it, each frame to -o with its number in place of the '#'s");
  cmd->add_option("--frames", opts->frames, "Frames of --path, e.g. 0..59 (inclusive)");
  cmd->callback([opts, cmd, &global] {
    opts->aov_given = cmd->count("--aov") > 0;
    run_render(*opts, global);
  });
}

}  // namespace speculum::cli
