// `speculum profile SCENE --technique T [--repeat K] [-o DIR]`: per-node median wall time,
// share of the frame and counters; DIR/trace.json (Chrome trace events, one per node and per
// named kernel launch, of the last run) and DIR/counters.json.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/cli/frame_options.h"
#include "apps/cli/json_output.h"
#include "apps/techniques/render_frame.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

namespace fs = std::filesystem;

struct ProfileOptions {
  pipeline::FrameOptions frame;
  int repeat = 5;
  int warmup = 1;
  std::string output;
  bool json = false;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void write_text(const fs::path& path, const std::string& text) {
  write_text_file(path.string(), text);  // whole or nothing, with the real reason on failure
}

void run_profile(const ProfileOptions& o, const GlobalOptions& global) {
  const pipeline::Technique& technique = pipeline::find_technique(o.frame.technique);
  Scene scene = pipeline::load_frame_scene(o.frame, global.quiet);
  const pipeline::FrameSettings settings = pipeline::make_frame_settings(o.frame, scene);
  for (const std::string& warning : pipeline::apply_light_options(o.frame, scene, settings.camera))
    if (!global.quiet) std::fprintf(stderr, "%s\n", warning.c_str());
  if (!o.output.empty()) {
    std::error_code ec;
    fs::create_directories(o.output, ec);
    if (ec || !fs::is_directory(o.output)) throw InputError(o.output, "cannot create the output directory");
  }
  par::Executor executor(global.threads, global.lanes);
  Progress progress("profile " + technique.name, std::size_t(o.warmup + o.repeat), global.quiet);
  WorkPoller poller(executor, progress);  // the bar moves inside long frames too
  for (int i = 0; i < o.warmup; ++i) {
    pipeline::render_frame(scene, technique, settings, executor);
    progress.step("warm-up");
  }
  std::vector<double> frame_ms;
  std::map<std::string, std::vector<double>> node_ms;
  par::RunReport last;
  std::vector<par::LaunchRecord> launches;
  for (int i = 0; i < o.repeat; ++i) {
    executor.clear_launches();
    pipeline::FrameResult r = pipeline::render_frame(scene, technique, settings, executor);
    frame_ms.push_back(r.report.duration_ns * 1e-6);
    for (const auto& n : r.report.nodes) node_ms[n.name].push_back(n.duration_ns * 1e-6);
    last = std::move(r.report);
    progress.step("run " + std::to_string(i + 1));
  }
  launches = executor.launches();
  progress.finish();

  const double frame_median = median(frame_ms);
  ResultTable table(o.json);
  nlohmann::json nodes = nlohmann::json::array();
  std::size_t name_width = 5;  // the text table sizes columns from its first row
  for (const auto& n : last.nodes) name_width = std::max(name_width, n.name.size());
  auto padded = [&](const std::string& name) {
    return o.json ? name : name + std::string(name_width - name.size(), ' ');
  };
  for (const auto& n : last.nodes) {  // execution order
    const double ms = median(node_ms[n.name]);
    const double share = frame_median > 0 ? ms / frame_median : 0.0;
    table.cell("node", padded(n.name)).cell("median_ms", ms, 3).cell("share_pct", 100.0 * share, 1)
        .cell("counters", counters_text(n.counters));
    table.end_row();
    nodes.push_back({{"name", n.name}, {"median_ms", ms}, {"share", share}, {"counters", counters_json(n.counters)}});
  }
  table.cell("node", padded("frame")).cell("median_ms", frame_median, 3).cell("share_pct", 100.0, 1)
      .cell("counters", "repeat=" + std::to_string(o.repeat));
  table.end_row();
  if (!global.quiet)
    std::fprintf(stderr, "speculum: profile %s %s %dx%d spp %d, %d threads: median frame %.2f ms "
                         "(min %.2f, max %.2f) over %d runs after %d warm-up\n",
                 technique.name.c_str(), scene.name.c_str(), settings.width, settings.height,
                 settings.spp, executor.threads(), frame_median,
                 *std::min_element(frame_ms.begin(), frame_ms.end()),
                 *std::max_element(frame_ms.begin(), frame_ms.end()), o.repeat, o.warmup);
  if (!o.output.empty()) {
    const fs::path dir = o.output;
    write_text(dir / "trace.json", par::chrome_trace_json(last, launches));
    const nlohmann::json counters{
        {"scene", scene.name}, {"technique", technique.name}, {"width", settings.width},
        {"height", settings.height}, {"spp", settings.spp}, {"threads", executor.threads()},
        {"repeat", o.repeat}, {"warmup", o.warmup}, {"frame_median_ms", frame_median},
        {"frame_ms", frame_ms}, {"nodes", nodes}};
    write_text(dir / "counters.json", json_document(counters));
    if (!global.quiet)
      std::fprintf(stderr, "speculum: wrote %s and %s (open trace.json in https://ui.perfetto.dev)\n",
                   (dir / "trace.json").c_str(), (dir / "counters.json").c_str());
  }
}

}  // namespace

void add_profile_command(CLI::App& app, GlobalOptions& global) {
  auto opts = std::make_shared<ProfileOptions>();
  auto* cmd = app.add_subcommand(
      "profile", "Time every pass of a technique: per-node median ms, share of the frame and\n"
                 "counters; with -o a Chrome trace (trace.json) and counters.json");
  cmd->footer("Example: speculum profile sphere-in-room --technique envmap --repeat 10 -o prof\n"
              "         (open prof/trace.json in Perfetto or chrome://tracing)");
  pipeline::add_frame_options(*cmd, opts->frame);
  cmd->add_option("--repeat", opts->repeat, "Timed frames; medians are reported")
      ->check(CLI::Range(1, 10000))->capture_default_str();
  cmd->add_option("--warmup", opts->warmup, "Untimed frames before the timed ones")
      ->check(CLI::Range(0, 100))->capture_default_str();
  cmd->add_option("-o,--output", opts->output,
                  "Directory for trace.json and counters.json (default: none, table only)");
  cmd->add_flag("--json", opts->json, "Print the table as one JSON object per row");
  cmd->callback([opts, &global] { run_profile(*opts, global); });
}

}  // namespace speculum::cli
