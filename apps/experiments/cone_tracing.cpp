// `speculum experiment cone-tracing`: the measurements of ROGER §5.3 — the cost of cone
// tracing with anti-aliasing against ray tracing the same pixels with the ray hierarchy
// (Fig.5.10(a,b), Fig.5.11: 1.6–2.6×), the gloss-angle sweep 0.01 / 0.05 / 0.1 rad (Fig.5.10:
// time and kept triangles rise), the triangle-count sweep (Fig.5.13: about linear), and the
// anti-aliasing quality against supersampled ray tracing at equal time. Frame times are whole
// frames (rasterized G-buffer and direct light included, the same for both techniques);
// mae8 is against ray-hierarchy at --reference-supersample² samples per pixel.
#include <algorithm>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "apps/techniques/render_frame.h"
#include "core/error.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "trace/cone_tracing.h"

namespace speculum::cli {
namespace {

struct ConeTracingExperimentOptions {
  std::string scene = "sphere-in-room";
  int width = 160, height = 120;
  int runs = 3;
  int reference_supersample = 8;
  bool quick = false;
  bool json = false;
};

struct Measured {
  double ms = 0.0;
  double kept_median = 0.0, found_median = 0.0;
  ImageRGBA display;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

Measured measure(const Scene& scene, const std::string& technique, int width, int height, int supersample,
                 const std::map<std::string, double>& params, int runs, par::Executor& ex) {
  const pipeline::Technique& t = pipeline::find_technique(technique);
  pipeline::FrameSettings f;
  f.width = width;
  f.height = height;
  f.supersample = supersample;
  f.spp = supersample * supersample;
  f.camera = scene.cameras.front();
  f.params = params;
  Measured m;
  std::vector<double> times;
  for (int r = 0; r < std::max(1, runs); ++r) {
    std::vector<double> kept, found;
    const pipeline::FrameResult fr = pipeline::render_frame(scene, t, f, ex, [&](const par::CapturedOutput& o) {
      if (const auto* h = o.as<trace::ConeHits>()) {
        for (std::size_t p = 0; p < h->count.size(); ++p)
          if (h->total[p] > 0) kept.push_back(h->count[p]), found.push_back(h->total[p]);
      }
    });
    times.push_back(double(fr.report.duration_ns) * 1e-6);
    if (r == 0) {
      m.display = fr.display;
      m.kept_median = median(kept);
      m.found_median = median(found);
    }
  }
  m.ms = median(times);
  return m;
}

void run_cone_tracing_experiment(const ConeTracingExperimentOptions& o, const GlobalOptions& global) {
  par::Executor ex(global.threads, global.lanes);
  ResultTable table(o.json);
  const int w = o.quick ? 48 : o.width, h = o.quick ? 36 : o.height;
  const int runs = o.quick ? 1 : o.runs;
  const int ref_k = o.quick ? 4 : o.reference_supersample;
  const std::vector<double> glosses = {0.01, 0.05, 0.1};
  const std::vector<std::uint64_t> sizes =
      o.quick ? std::vector<std::uint64_t>{2500, 5000} : std::vector<std::uint64_t>{2500, 5000, 18000, 71000};
  Progress progress("cone-tracing", 1 + glosses.size() + sizes.size() + 1, global.quiet);
  table.set_progress(&progress);

  SceneOptions so;
  const Scene scene = load_scene(o.scene, so);
  const ImageRGBA reference = measure(scene, "ray-hierarchy", w, h, ref_k, {}, 1, ex).display;
  const std::map<std::string, double> aa = {{"gloss_angle", 0.0}};
  const Measured ray = measure(scene, "ray-hierarchy", w, h, 1, {}, runs, ex);
  const Measured cone = measure(scene, "cone-tracing", w, h, 1, aa, runs, ex);
  auto row = [&](const char* kind, const std::string& scene_name, const Measured& c, const Measured& r,
                 const ImageRGBA& ref) -> ResultTable& {
    return table.cell("kind", kind)
        .cell("scene", scene_name)
        .cell("width", w)
        .cell("height", h)
        .cell("ms_cone", c.ms, 1)
        .cell("ms_ray", r.ms, 1)
        .cell("ratio", r.ms > 0 ? c.ms / r.ms : 0.0, 2)
        .cell("kept_median", c.kept_median, 1)
        .cell("found_median", c.found_median, 1)
        .cell("mae8", image_error(ref, c.display).mae8, 3)
        .cell("mae8_ray", image_error(ref, r.display).mae8, 3);
  };
  row("cost", o.scene, cone, ray, reference).cell("gloss_angle", 0.0, 2)
      .cell("triangles", std::int64_t(scene.mesh.triangle_count())).cell("ray_supersample", 1);
  table.end_row();

  for (double g : glosses) {
    const Measured c = measure(scene, "cone-tracing", w, h, 1, {{"gloss_angle", g}}, runs, ex);
    row("gloss", o.scene, c, ray, reference).cell("gloss_angle", g, 2)
        .cell("triangles", std::int64_t(scene.mesh.triangle_count())).cell("ray_supersample", 1);
    table.end_row();
  }

  for (std::uint64_t size : sizes) {
    SceneOptions sized;
    sized.size = size;
    const Scene s = load_scene(o.scene, sized);
    const ImageRGBA ref = measure(s, "ray-hierarchy", w, h, ref_k, {}, 1, ex).display;
    const Measured r = measure(s, "ray-hierarchy", w, h, 1, {}, runs, ex);
    const Measured c = measure(s, "cone-tracing", w, h, 1, aa, runs, ex);
    row("triangles", o.scene, c, r, ref).cell("gloss_angle", 0.0, 2)
        .cell("triangles", std::int64_t(s.mesh.triangle_count())).cell("ray_supersample", 1);
    table.end_row();
  }

  // Equal time: the largest k×k supersampled ray-hierarchy frame that is not slower than the
  // cone-traced one.
  Measured equal = ray;
  int k_equal = 1;
  for (int k = 2; k <= 8; ++k) {
    const Measured r = measure(scene, "ray-hierarchy", w, h, k, {}, runs, ex);
    if (r.ms > cone.ms) break;
    equal = r;
    k_equal = k;
  }
  row("aa", o.scene, cone, equal, reference).cell("gloss_angle", 0.0, 2)
      .cell("triangles", std::int64_t(scene.mesh.triangle_count()))
      .cell("ray_supersample", k_equal);
  table.end_row();
}

}  // namespace

void add_experiment_cone_tracing_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<ConeTracingExperimentOptions>();
  auto* cmd = experiment.add_subcommand(
      "cone-tracing",
      "ROGER ch.5 cone tracing (§5.3): rows of kind cost (anti-aliased cones against one ray "
      "per pixel with the ray hierarchy; ROGER 1.6–2.6×), gloss (0.01/0.05/0.1 rad: time and "
      "kept triangles per pixel), triangles (2.5K–71K) and aa (quality against supersampled "
      "ray tracing at equal time). mae8 and mae8_ray: the cone and ray frames against "
      "ray-hierarchy at --reference-supersample² samples per pixel.\n"
      "Example: speculum experiment cone-tracing --quick --json");
  cmd->add_option("--scene", o->scene, "Built-in scene (its size is swept for the triangles rows)")
      ->capture_default_str();
  cmd->add_option("--width", o->width, "Image width")->check(CLI::Range(8, 1024))->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->check(CLI::Range(8, 1024))->capture_default_str();
  cmd->add_option("--runs", o->runs, "Timed frames per measurement (the median is printed)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  cmd->add_option("--reference-supersample", o->reference_supersample,
                  "k of the k×k supersampled ray-hierarchy reference")
      ->check(CLI::Range(2, 16))->capture_default_str();
  cmd->add_flag("--quick", o->quick, "48×36, one run, sizes 2.5K and 5K, 4×4 reference: a smoke check");
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_cone_tracing_experiment(*o, global); });
}

}  // namespace speculum::cli
