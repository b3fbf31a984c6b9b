// `speculum experiment survey`: the SURVEY techniques (§3.1, §4.1–4.5, §5) on
// the scenes where each applies — ms per frame (median of --runs) and error against the
// reference tracer (mae8, rmse, psnr on 8-bit PNG values, core/image_metrics.h), plus the
// search steps used and the mean distance-map reads per searched ray.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/techniques/recipes.h"
#include "apps/techniques/render_frame.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "core/error.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

struct SurveyOptions {
  std::vector<std::string> scenes;  // empty: every scene of the plan
  std::vector<std::string> techniques;  // empty: the fixed list
  int width = 200;
  int height = 0;  // 0: width · 3/4
  int reference_spp = 16;
  int runs = 3;
  int cube_size = 256;
  std::string reference_cache;  // directory; empty: no disk cache
  bool json = false;
};

// The fixed technique list and the scenes where each applies (envmap is the baseline
// everywhere). Names not in the technique table are skipped.
const std::vector<std::string> kTechniques = {"envmap", "distance-map", "multi-reflection",
                                              "refraction", "layered-distance-map",
                                              "planar-mirror"};
const std::vector<std::string> kReflectionScenes = {"sphere-in-room", "bowl", "living-room"};
bool applies(const std::string& technique, const std::string& scene) {
  const bool reflection_scene =
      std::find(kReflectionScenes.begin(), kReflectionScenes.end(), scene) != kReflectionScenes.end();
  if (technique == "envmap") return true;
  if (technique == "refraction") return scene == "glass-sphere";
  if (technique == "planar-mirror") return scene == "mirror-corridor";
  return reflection_scene;
}

// The steps column: what the technique's search does with these settings.
std::string steps_of(const std::string& technique, const pipeline::FrameSettings& settings) {
  const pipeline::FrameSettings f = pipeline::find_technique(technique).with_defaults(settings);
  if (technique == "distance-map") return raster::describe_search(pipeline::distance_search_options(f));
  if (technique == "multi-reflection")
    return raster::describe_search(pipeline::distance_search_options(f)) +
           " rounds=" + std::to_string(int(f.param("rounds")));
  if (technique == "layered-distance-map") return pipeline::describe_layered(f);
  return "-";
}

// Sum of a counter over the run's nodes.
std::uint64_t counter(const par::RunReport& r, const std::string& name) {
  std::uint64_t sum = 0;
  for (const auto& n : r.nodes)
    if (auto it = n.counters.find(name); it != n.counters.end()) sum += it->second;
  return sum;
}

ImageRGBA reference_image(const Scene& scene, const std::string& scene_name,
                          const pipeline::FrameSettings& base, const SurveyOptions& o,
                          par::Executor& executor) {
  std::string cached;
  if (!o.reference_cache.empty()) {
    std::filesystem::create_directories(o.reference_cache);
    cached = (std::filesystem::path(o.reference_cache) /
              (scene_name + "_" + std::to_string(base.width) + "x" + std::to_string(base.height) +
               "_spp" + std::to_string(o.reference_spp) + ".png")).string();
    if (std::filesystem::exists(cached)) return read_image(cached);
  }
  pipeline::FrameSettings f = base;
  f.spp = o.reference_spp;
  f.supersample = 1;
  ImageRGBA display =
      pipeline::render_frame(scene, pipeline::find_technique("reference"), f, executor).display;
  if (!cached.empty()) write_image(cached, display);
  return display;
}

void run_survey(const SurveyOptions& o, const GlobalOptions& global) {
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty()) scenes = {"sphere-in-room", "bowl", "living-room", "glass-sphere", "mirror-corridor"};
  const std::vector<std::string>& wanted = o.techniques.empty() ? kTechniques : o.techniques;
  std::vector<const pipeline::Technique*> known;
  for (const std::string& name : wanted)
    for (const pipeline::Technique& t : pipeline::techniques())
      if (t.name == name) known.push_back(&t);
  par::Executor executor(global.threads, global.lanes);
  ResultTable table(o.json);
  std::size_t rows = 0;
  for (const std::string& scene_name : scenes)
    for (const pipeline::Technique* t : known) rows += applies(t->name, scene_name) ? 1 : 0;
  Progress progress("survey", rows, global.quiet);
  table.set_progress(&progress);
  for (const std::string& scene_name : scenes) {
    const Scene scene = load_scene(scene_name);
    if (scene.cameras.empty()) throw InputError(scene_name, "the scene has no camera");
    pipeline::FrameSettings f;
    f.width = o.width;
    f.height = o.height > 0 ? o.height : std::max(1, o.width * 3 / 4);
    f.camera = scene.cameras.front();
    f.cube_map_size = o.cube_size;
    const ImageRGBA reference = reference_image(scene, scene_name, f, o, executor);
    for (const pipeline::Technique* t : known) {
      if (!applies(t->name, scene_name)) continue;
      std::vector<double> ms;
      pipeline::FrameResult frame;
      for (int run = 0; run < std::max(1, o.runs); ++run) {
        const auto start = std::chrono::steady_clock::now();
        frame = pipeline::render_frame(scene, *t, f, executor);
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      }
      std::sort(ms.begin(), ms.end());
      const ImageError e = image_error(frame.display, reference, t->name + " vs reference");
      const std::uint64_t searches = counter(frame.report, "searches");
      const std::uint64_t lookups = counter(frame.report, "distance_lookups");
      table.cell("technique", t->name)
          .cell("scene", scene_name)
          .cell("ms", ms[ms.size() / 2], 1)
          .cell("mae8", e.mae8, 2)
          .cell("rmse", e.rmse, 4)
          .cell("psnr", e.psnr, 2)
          .cell("steps", steps_of(t->name, f))
          .cell("reads_per_search", searches ? double(lookups) / double(searches) : 0.0, 1);
      table.end_row();
    }
  }
}

}  // namespace

void add_experiment_survey_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<SurveyOptions>();
  auto* cmd = experiment.add_subcommand(
      "survey",
      "SURVEY techniques vs the reference tracer: ms/frame, mae8, rmse, psnr, search steps.\n"
      "Example: speculum experiment survey --width 160 --reference-spp 16 --json");
  cmd->add_option("--scene", o->scenes,
                  "Scene(s) to run (repeatable; default: sphere-in-room, bowl, living-room, "
                  "glass-sphere, mirror-corridor)");
  cmd->add_option("--technique", o->techniques,
                  "Technique(s) (repeatable; default: envmap, distance-map, multi-reflection, "
                  "refraction, layered-distance-map, planar-mirror; unknown names are skipped)");
  cmd->add_option("--width", o->width, "Image width")->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_option("--height", o->height, "Image height (0: width·3/4)")
      ->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_option("--reference-spp", o->reference_spp, "Reference tracer samples per pixel")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--runs", o->runs, "Frames timed per row (the median is printed)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  cmd->add_option("--cube-size", o->cube_size, "Cube map face size of the distance maps")
      ->check(CLI::Range(8, 2048))->capture_default_str();
  cmd->add_option("--reference-cache", o->reference_cache,
                  "Directory caching reference PNGs per scene/size/spp (default: none)");
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_survey(*o, global); });
}

}  // namespace speculum::cli
