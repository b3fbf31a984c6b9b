// `speculum experiment ray-hierarchy`: the measurements of ROGER §3.4
// — the ray hierarchy over a width sweep on smooth and bumpy reflectors: ms per frame's
// secondary rays, candidates per ray, cone-sphere tests, the stage split, and the same rays
// traced with the BVH (trace::closest_hit_stream) for the time ratio and the identity check.
#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "raster/gbuffer.h"
#include "raster/visibility.h"
#include "trace/bvh.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"

namespace speculum::cli {
namespace {

struct RayHierarchyExperimentOptions {
  std::vector<std::string> scenes;  // empty: the thesis's set
  int min_width = 128;
  int max_width = 1024;
  int runs = 3;
  std::uint64_t size = 0;  // scene triangles; 0: each scene's default
  std::size_t capacity = std::size_t(2048) * 2048;
  std::size_t block = 64;
  bool json = false;
};

const std::vector<std::string> kScenes = {"sphere-in-room", "bumpy-sphere:n=0", "bumpy-sphere:n=4",
                                          "bumpy-sphere:n=16", "living-room"};

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

struct HierarchyRun {
  double build_ms = 0, total_ms = 0;
  trace::HierarchyTraverseStats stats;
  trace::HitStream hits;
};

void run_row(const Scene& scene, const std::string& name, const trace::Bvh& bvh, int width,
             const RayHierarchyExperimentOptions& o, par::Executor& ex, ResultTable& table) {
  const Camera& cam = scene.cameras.front();
  const raster::VisibilityBuffer vis = raster::render_visibility(ex, scene, cam, width, width);
  const raster::GBuffer gb = raster::resolve_gbuffer(ex, scene, vis, cam.eye);
  const trace::SecondaryRays rays = trace::secondary_rays(ex, gb.position, gb.normal, gb.surface, gb.object, cam.eye);

  trace::HierarchyTraverseOptions topt;
  topt.pair_capacity = o.capacity;
  topt.block_size = o.block;
  std::vector<HierarchyRun> runs(std::max(1, o.runs));
  for (HierarchyRun& r : runs) {
    const auto t0 = std::chrono::steady_clock::now();
    const trace::RayHierarchy h = trace::build_ray_hierarchy(ex, rays.rays, rays.active, width, width);
    r.build_ms = ms_since(t0);
    trace::hierarchy_closest_hits(ex, scene.mesh.positions, scene.mesh.indices, h, rays.rays, r.hits, topt, &r.stats);
    r.total_ms = ms_since(t0);
  }
  std::sort(runs.begin(), runs.end(), [](const HierarchyRun& a, const HierarchyRun& b) { return a.total_ms < b.total_ms; });
  const HierarchyRun& med = runs[runs.size() / 2];

  // The same rays with the BVH (invalid/inactive rays made empty so both skip them).
  trace::RayStream bvh_rays = rays.rays;
  for (std::size_t i = 0; i < bvh_rays.size(); ++i)
    if (!rays.active[i]) bvh_rays.tmin[i] = 1.0f, bvh_rays.tmax[i] = 0.0f;
  std::vector<double> bvh_times;
  trace::HitStream bvh_hits;
  for (int k = 0; k < std::max(1, o.runs); ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    trace::closest_hit_stream(bvh, bvh_rays, bvh_hits, ex);
    bvh_times.push_back(ms_since(t0));
  }
  std::sort(bvh_times.begin(), bvh_times.end());
  const double bvh_ms = bvh_times[bvh_times.size() / 2];

  bool identical = true;
  for (std::size_t i = 0; i < bvh_hits.triangle.size() && identical; ++i) {
    const std::uint32_t tri = rays.active[i] ? bvh_hits.triangle[i] : trace::kNoHit;
    if (med.hits.triangle[i] != tri) identical = false;
    else if (tri != trace::kNoHit && std::memcmp(&med.hits.t[i], &bvh_hits.t[i], sizeof(float)) != 0)
      identical = false;
  }

  const auto& s = med.stats;
  std::ostringstream levels;
  for (std::size_t l = 0; l < s.pairs_per_level.size(); ++l) levels << (l ? "/" : "") << s.pairs_per_level[l];
  table.cell("scene", name)
      .cell("width", width)
      .cell("triangles", std::int64_t(scene.mesh.triangle_count()))
      .cell("rays", std::int64_t(rays.count))
      .cell("ms", med.total_ms, 1)
      .cell("candidates_per_ray", s.candidates_per_ray(), 2)
      .cell("cone_sphere_tests", std::int64_t(s.cone_sphere_tests))
      .cell("build_ms", med.build_ms, 1)
      .cell("tests_ms", s.tests_ms, 1)
      .cell("compaction_ms", s.compaction_ms, 1)
      .cell("exact_ms", s.exact_ms, 1)
      .cell("compaction_pct", med.total_ms > 0 ? 100.0 * s.compaction_ms / med.total_ms : 0.0, 0)
      .cell("overflow_batches", std::int64_t(s.overflow_batches))
      .cell("bvh_ms", bvh_ms, 1)
      .cell("ratio_to_bvh", bvh_ms > 0 ? med.total_ms / bvh_ms : 0.0, 1)
      .cell("identical_to_oracle", identical)
      .cell("compared_with", "bvh")
      .cell("pairs_per_level", levels.str());
  table.end_row();
}

void run_ray_hierarchy_experiment(const RayHierarchyExperimentOptions& o, const GlobalOptions& global) {
  if (o.min_width > o.max_width)
    throw InputError("--min-width", "must not exceed --max-width (" + std::to_string(o.max_width) + ")");
  par::Executor ex(global.threads, global.lanes);
  ResultTable table(o.json);
  const std::vector<std::string>& scenes = o.scenes.empty() ? kScenes : o.scenes;
  std::size_t widths = 0;
  for (int w = o.min_width; w <= o.max_width; w *= 2) ++widths;
  Progress progress("ray-hierarchy", scenes.size() * widths, global.quiet);
  table.set_progress(&progress);
  for (const std::string& name : scenes) {
    SceneOptions so;
    so.size = o.size;
    const Scene scene = load_scene(name, so);
    const trace::Bvh bvh = trace::Bvh::build(scene.mesh, ex);
    for (int w = o.min_width; w <= o.max_width; w *= 2) run_row(scene, name, bvh, w, o, ex, table);
  }
}

}  // namespace

void add_experiment_ray_hierarchy_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<RayHierarchyExperimentOptions>();
  auto* cmd = experiment.add_subcommand(
      "ray-hierarchy",
      "ROGER ch.3 ray hierarchy: width sweep (square images) of the secondary rays of a "
      "G-buffer — ms, candidates per ray, cone-sphere tests, stage split (build / tests / "
      "compaction / exact), the same rays with the BVH (bvh_ms) and whether the hits are "
      "identical to the BVH's (which equal the all-pairs oracle by the trace tests).\n"
      "Example: speculum experiment ray-hierarchy --scenes sphere-in-room --max-width 256 --json");
  cmd->add_option("--scenes", o->scenes,
                  "Scenes (repeat or comma-separate; default: sphere-in-room, bumpy-sphere:n=0, "
                  "bumpy-sphere:n=4, bumpy-sphere:n=16, living-room)")
      ->delimiter(',');
  cmd->add_option("--min-width", o->min_width, "Smallest width (doubles up to --max-width)")
      ->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_option("--max-width", o->max_width, "Largest width")->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_option("--runs", o->runs, "Timed runs per row (the median is printed)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  cmd->add_option("--size", o->size, "Scene triangle count (0: each scene's default)")->capture_default_str();
  cmd->add_option("--pair-capacity", o->capacity, "Pair buffer capacity (pairs; raised to 4·width² when smaller)")
      ->check(CLI::Range(std::size_t(1), std::size_t(1) << 30))->capture_default_str();
  cmd->add_option("--block", o->block, "Hierarchical compaction block size s")
      ->check(CLI::Range(std::size_t(1), std::size_t(1) << 20))->capture_default_str();
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_ray_hierarchy_experiment(*o, global); });
}

}  // namespace speculum::cli
