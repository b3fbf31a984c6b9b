// `speculum inspect SCENE --technique T -o DIR`: one frame with every node output written
// as PNG + EXR, the graph as DOT/SVG, manifest.json and index.html.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "apps/cli/commands.h"
#include "apps/cli/frame_options.h"
#include "apps/cli/json_output.h"
#include "apps/inspect/inspect_images.h"
#include "apps/inspect/inspect_report.h"
#include "apps/inspect/inspect_run.h"
#include "apps/techniques/render_frame.h"
#include "apps/cli/progress.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

namespace fs = std::filesystem;

struct InspectOptions {
  pipeline::FrameOptions frame;
  std::string output = "inspect";
  bool no_svg = false;
};

// File-name safe: letters, digits, '-', '_' and '.'.
std::string safe(const std::string& s) {
  std::string out;
  for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  return out;
}

void write_text(const fs::path& path, const std::string& text) {
  write_text_file(path.string(), text);  // whole or nothing, with the real reason on failure
}

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

bool have_graphviz() { return std::system("command -v dot >/dev/null 2>&1") == 0; }

}  // namespace

fs::path write_inspect_report(const pipeline::FrameOptions& options, const fs::path& dir,
                              const GlobalOptions& global, bool svg) {
  const pipeline::Technique& technique = pipeline::find_technique(options.technique);
  Scene scene = pipeline::load_frame_scene(options, global.quiet);
  const pipeline::FrameSettings settings = pipeline::make_frame_settings(options, scene);
  for (const std::string& warning : pipeline::apply_light_options(options, scene, settings.camera))
    if (!global.quiet) std::fprintf(stderr, "%s\n", warning.c_str());
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) throw InputError(dir.string(), "cannot create the output directory");

  // The same recipe as render_frame builds, compiled but not run: names, ports,
  // parameters and descriptions in execution order.
  par::Graph meta;
  const pipeline::FrameOutputs outputs = technique.add_passes(meta, &scene, settings);
  meta.request(outputs.radiance);
  meta.request(outputs.display);
  meta.compile();
  const std::vector<std::string> order = meta.order();
  std::map<std::string, std::size_t> position;
  for (std::size_t i = 0; i < order.size(); ++i) position[order[i]] = i;

  inspect::Report report;
  report.scene = scene.name;
  report.technique = technique.name;
  report.settings = {{"width", std::to_string(settings.width)},
                     {"height", std::to_string(settings.height)},
                     {"spp", std::to_string(settings.spp)},
                     {"seed", std::to_string(settings.seed)},
                     {"exposure", settings.auto_exposure ? std::string("auto") : std::to_string(settings.exposure)},
                     {"threads", std::to_string(global.threads)}};
  for (const auto& [k, v] : settings.params) {
    std::string text = std::to_string(v);
    for (const pipeline::TechniqueParam& p : technique.params)
      if (p.name == k && !p.choices.empty()) text = p.value_text(v);  // a mode by its name
    report.settings.emplace_back("param " + k, text);
  }

  // Outputs as they are produced: drawn and written at once (values die with the graph).
  std::map<std::pair<std::string, std::string>, inspect::PortInfo> captured;  // (node, port)
  std::map<std::string, std::string> size_of_resource;
  par::Executor draw_executor(1, global.lanes);  // tone mapping for pictures stays out of the profile
  Progress progress("inspect " + technique.name, order.size(), global.quiet);
  std::string last_node;
  auto capture = [&](const par::CapturedOutput& out) {
    if (out.node != last_node) progress.step(out.node), last_node = out.node;
    inspect::Drawing d = inspect::draw_output(out, draw_executor);
    inspect::PortInfo info{out.port, out.resource, out.type_name, d.size, false, d.drawable, {}};
    char index[8];
    std::snprintf(index, sizeof index, "%02zu", position.count(out.node) ? position[out.node] + 1 : 0);
    for (const auto& v : d.views) {
      const std::string stem = std::string(index) + "_" + safe(out.node) + "." + safe(out.port) +
                               (v.label.empty() ? "" : "." + safe(v.label));
      inspect::ImageFile file{v.label, v.encoding, stem + ".png", stem + ".exr"};
      write_image((dir / file.png).string(), v.picture);
      if (!v.raw_scalar.empty())
        write_image((dir / file.exr).string(), v.raw_scalar);
      else
        write_image((dir / file.exr).string(), v.raw_rgba);
      report.files.push_back(file.png);
      report.files.push_back(file.exr);
      info.images.push_back(std::move(file));
    }
    if (!out.resource.empty()) size_of_resource[out.resource] = d.size;
    captured[{out.node, out.port}] = std::move(info);
  };

  par::Executor executor(global.threads, global.lanes);
  executor.clear_launches();
  const pipeline::FrameResult frame = [&] {
    WorkPoller poller(executor, progress);  // the bar moves inside long passes too
    return pipeline::render_frame(scene, technique, settings, executor, capture);
  }();
  progress.finish();
  const auto launches = executor.launches();
  report.frame_ms = frame.report.duration_ns * 1e-6;
  report.culled = frame.report.culled;

  for (const par::NodeRecord& rec : frame.report.nodes) {
    inspect::NodeInfo n;
    n.name = rec.name;
    n.ms = rec.duration_ns * 1e-6;
    n.counters.insert(rec.counters.begin(), rec.counters.end());
    for (const auto& entry : meta.nodes()) {
      if (entry.name != rec.name) continue;
      n.description = entry.description;
      n.parameters = entry.params.items();
      for (const auto& p : entry.ports) {
        if (p.output) {
          auto it = captured.find({rec.name, p.port});
          n.outputs.push_back(it != captured.end()
                                  ? it->second
                                  : inspect::PortInfo{p.port, p.resource, p.type_name, "", false, false, {}});
        } else {
          const auto s = size_of_resource.find(p.resource);
          n.inputs.push_back({p.port, p.resource, p.type_name,
                              s == size_of_resource.end() ? "" : s->second, p.previous_frame, false, {}});
        }
      }
    }
    // What the node published beyond its outputs (NodeContext::publish: no resource).
    for (const auto& [key, info] : captured)
      if (key.first == rec.name && info.resource.empty()) n.outputs.push_back(info);
    for (const auto& l : launches)
      if (l.scope == rec.name) n.launches.push_back({l.name, l.elements, l.chunks, l.duration_ns * 1e-6});
    report.nodes.push_back(std::move(n));
  }

  report.dot = "graph.dot";
  write_text(dir / report.dot, meta.to_dot());
  report.files.push_back(report.dot);
  if (svg && have_graphviz()) {
    const std::string cmd = "dot -Tsvg " + shell_quote((dir / "graph.dot").string()) + " -o " +
                            shell_quote((dir / "graph.svg").string()) + " >/dev/null 2>&1";
    if (std::system(cmd.c_str()) == 0 && fs::exists(dir / "graph.svg")) {
      report.svg = "graph.svg";
      report.files.push_back(report.svg);
    } else if (!global.quiet) {
      std::fprintf(stderr, "speculum: inspect: Graphviz dot failed; no graph.svg\n");
    }
  }
  report.files.push_back("manifest.json");
  report.files.push_back("index.html");
  write_text(dir / "manifest.json", json_document(inspect::manifest_json(report)));
  write_text(dir / "index.html", inspect::index_html(report));
  if (!global.quiet)
    std::fprintf(stderr, "speculum: inspect %s %s: %zu passes, %zu files in %.1f ms\n",
                 technique.name.c_str(), scene.name.c_str(), report.nodes.size(), report.files.size(),
                 report.frame_ms);
  return dir / "index.html";
}

namespace {

void run_inspect(const InspectOptions& o, const GlobalOptions& global) {
  const fs::path index = write_inspect_report(o.frame, o.output, global, !o.no_svg);
  std::printf("%s\n", fs::absolute(index).string().c_str());
}

}  // namespace

void add_inspect_command(CLI::App& app, GlobalOptions& global) {
  auto opts = std::make_shared<InspectOptions>();
  auto* cmd = app.add_subcommand(
      "inspect",
      "Run one frame and write every pass's outputs (PNG + EXR), the graph (DOT, SVG),\n"
      "manifest.json and an index.html that shows the passes in execution order");
  cmd->footer(
      "Example: speculum inspect sphere-in-room --technique envmap --width 160 --height 120 -o insp\n"
      "         then open insp/index.html in a browser (no server needed)");
  pipeline::add_frame_options(*cmd, opts->frame);
  cmd->add_option("-o,--output", opts->output, "Output directory (created; files are overwritten)")
      ->capture_default_str();
  cmd->add_flag("--no-svg", opts->no_svg, "Do not run Graphviz `dot` for graph.svg");
  cmd->callback([opts, &global] { run_inspect(*opts, global); });
}

}  // namespace speculum::cli
