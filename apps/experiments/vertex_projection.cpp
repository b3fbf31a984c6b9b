// `speculum experiment vertex-projection`: ROGER ch.2's measurements on this CPU — secant
// iterations per vertex by where the reflection lands (centre, middle, silhouette: §2.3.2),
// the projection's time against the reflected scene's vertex count (×1, ×4, ×16 by edge
// splitting: linear, Fig.2.15), and the specular error against the exact specular reference
// beside envmap, distance-map and planar-mirror, with the cost relative to envmap.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/geometric.hpp>

#include "apps/cli/commands.h"
#include "apps/cli/result_table.h"
#include "apps/matrix/matrix.h"
#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/camera_rays.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "raster/vertex_projection.h"

namespace speculum::cli {
namespace {

struct VertexProjectionOptions {
  int width = 320;
  int height = 240;
  bool quick = false;
  bool json = false;
  std::string reference_cache;  // matrix output directory reused for the references; empty: a temporary one
};

constexpr double kPi = 3.14159265358979323846;

// Zones by the angle of incidence at P (between the normal and the direction to the eye):
// the reflector's centre as seen from the eye under 15°, its silhouette over 75°.
const char* zone_of(double incidence_degrees) {
  return incidence_degrees < 15.0 ? "centre" : incidence_degrees > 75.0 ? "silhouette" : "middle";
}

void iteration_rows(const std::string& scene_name, const VertexProjectionOptions& o, par::Executor& executor,
                    ResultTable& table) {
  const Scene scene = load_scene(scene_name);
  const Camera camera = scene.cameras.front();
  const double diagonal = glm::length(scene.bounds().extent());
  const raster::ReflectedGeometry geometry = raster::tessellate_reflected(scene, diagonal / 64.0, std::size_t(1) << 22);
  const raster::ReflectorParams params = raster::build_reflector_params(executor, scene, 256);
  const glm::mat4 vp = projection_matrix(camera, o.width, o.height) * view_matrix(camera);
  auto project = [&](const glm::dvec3& p) {
    const glm::vec4 c = vp * glm::vec4(glm::vec3(p), 1.0f);
    if (!(c.w > 0.0f)) return glm::dvec2(1e30);
    return glm::dvec2((double(c.x) / c.w * 0.5 + 0.5) * o.width, (double(c.y) / c.w * 0.5 + 0.5) * o.height);
  };
  std::vector<std::uint32_t> vertex_object(geometry.mesh.vertex_count(), kNoId);
  for (std::size_t t = 0; t < geometry.mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) vertex_object[geometry.mesh.indices[3 * t + k]] = geometry.mesh.triangle_object[t];
  const glm::dvec3 eye(camera.eye);
  std::vector<int> zones[3];  // centre, middle, silhouette
  for (const raster::ReflectorParam& param : params.reflectors) {
    const std::size_t n = geometry.mesh.vertex_count();
    std::vector<int> iterations(n, -1);
    std::vector<float> incidence(n, 0.0f);
    executor.parallel_for("experiment.vertex_project", n, 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        if (vertex_object[v] == param.object) continue;
        const raster::FermatResult r = raster::fermat_project(param, param.centre, eye, glm::dvec3(geometry.mesh.positions[v]),
                                                              project, raster::FermatSettings{});
        if (r.status != raster::ProjectionStatus::Converged) continue;
        iterations[v] = r.iterations;
        const double c = std::fabs(glm::dot(r.normal, glm::normalize(eye - r.point)));
        incidence[v] = float(std::acos(std::min(1.0, c)) * 180.0 / kPi);
      }
    });
    for (std::size_t v = 0; v < n; ++v) {
      if (iterations[v] < 0) continue;
      const std::string z = zone_of(incidence[v]);
      zones[z == "centre" ? 0 : z == "middle" ? 1 : 2].push_back(iterations[v]);
    }
  }
  const char* names[3] = {"centre", "middle", "silhouette"};
  for (int z = 0; z < 3; ++z) {
    std::vector<int>& it = zones[z];
    std::sort(it.begin(), it.end());
    table.cell("kind", "iterations")
        .cell("scene", scene_name)
        .cell("zone", names[z])
        .cell("vertices", std::int64_t(it.size()))
        .cell("median", it.empty() ? 0 : it[it.size() / 2])
        .cell("max", it.empty() ? 0 : it.back());
    table.end_row();
  }
}

double node_ms(const par::RunReport& r, const char* node) {
  const par::NodeRecord* n = r.find(node);
  return n ? double(n->duration_ns) * 1e-6 : 0.0;
}

double counter(const par::RunReport& r, const char* node, const char* name) {
  const par::NodeRecord* n = r.find(node);
  if (!n) return 0.0;
  const auto it = n->counters.find(name);
  return it == n->counters.end() ? 0.0 : it->second;
}

void scaling_rows(const std::string& scene_name, const VertexProjectionOptions& o, par::Executor& executor,
                  ResultTable& table) {
  const Scene scene = load_scene(scene_name);
  const pipeline::Technique& technique = pipeline::find_technique("vertex-projection");
  // Halving the longest edge about quadruples the reflected vertices: ×1, ×4, ×16.
  const std::vector<double> edges = o.quick ? std::vector<double>{1.0 / 32, 1.0 / 64}
                                            : std::vector<double>{1.0 / 32, 1.0 / 64, 1.0 / 128};
  for (double edge : edges) {
    pipeline::FrameSettings f;
    f.width = o.width;
    f.height = o.height;
    f.camera = scene.cameras.front();
    f.params["edge"] = edge;
    f = technique.with_defaults(f);
    std::vector<double> ms;
    double vertices = 0.0, frame_ms = 0.0;
    for (int run = 0; run < (o.quick ? 1 : 3); ++run) {
      const pipeline::FrameResult r = pipeline::render_frame(scene, technique, f, executor);
      ms.push_back(node_ms(r.report, "vertex_project"));
      frame_ms = double(r.report.duration_ns) * 1e-6;
      vertices = counter(r.report, "vertex_project", "projections");
    }
    std::sort(ms.begin(), ms.end());
    table.cell("kind", "scaling")
        .cell("scene", scene_name)
        .cell("edge", edge, 4)
        .cell("vertices", std::int64_t(vertices))
        .cell("ms", ms[ms.size() / 2], 1)
        .cell("us_per_vertex", vertices > 0 ? 1e3 * ms[ms.size() / 2] / vertices : 0.0, 3)
        .cell("frame_ms", frame_ms, 1);
    table.end_row();
  }
}

void run_vertex_projection_experiment(const VertexProjectionOptions& o, const GlobalOptions& global) {
  par::Executor executor(global.threads, global.lanes);
  const std::vector<std::string> scenes = o.quick ? std::vector<std::string>{"ellipsoid", "sphere-in-room"}
                                                  : std::vector<std::string>{"sphere-in-room", "ellipsoid",
                                                                             "bumpy-sphere", "bowl"};
  {
    ResultTable table(o.json);
    for (const std::string& s : scenes) iteration_rows(s, o, executor, table);
  }
  if (!o.json) std::printf("\n");
  {
    ResultTable table(o.json);
    scaling_rows("sphere-in-room", o, executor, table);
  }
  if (!o.json) std::printf("\n");
  // The errors through the matrix's cells: its exact specular reference and mask.
  namespace fs = std::filesystem;
  const bool temporary = o.reference_cache.empty();
  const fs::path dir = temporary ? fs::temp_directory_path() / ("speculum-vertex-projection-" + std::to_string(::getpid()))
                                 : fs::path(o.reference_cache);
  matrix::MatrixOptions m;
  m.width = o.width;
  m.height = o.height;
  m.repeat = o.quick ? 1 : 3;
  m.spp_reference = o.quick ? 4 : 16;
  m.glossy_samples = o.quick ? 16 : 256;
  m.output = dir.string();
  matrix::prepare_output(dir);
  const std::vector<std::string> techniques = o.quick ? std::vector<std::string>{"vertex-projection", "envmap"}
                                                      : std::vector<std::string>{"vertex-projection", "envmap",
                                                                                 "distance-map", "planar-mirror"};
  ResultTable table(o.json);
  try {
    for (const std::string& s : scenes) {
      double envmap_ms = 0.0;
      std::vector<std::pair<std::string, nlohmann::ordered_json>> cells;
      for (const std::string& t : techniques) {
        const nlohmann::ordered_json c = matrix::run_cell(m, {t, s}, executor, true);
        if (t == "envmap") envmap_ms = c["ms"].get<double>();
        cells.emplace_back(t, c);
      }
      for (const auto& [t, c] : cells) {
        table.cell("kind", "error")
            .cell("scene", s)
            .cell("technique", t)
            .cell("mae8_specular", c["specular"]["mae8"].get<double>(), 2)
            .cell("ms", c["ms"].get<double>(), 1)
            .cell("cost_vs_envmap", envmap_ms > 0.0 ? c["ms"].get<double>() / envmap_ms : 0.0, 2);
        table.end_row();
      }
    }
  } catch (...) {
    if (temporary) fs::remove_all(dir);
    throw;
  }
  if (temporary) fs::remove_all(dir);
}

}  // namespace

void add_experiment_vertex_projection_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<VertexProjectionOptions>();
  auto* cmd = experiment.add_subcommand(
      "vertex-projection",
      "ROGER ch.2 vertex projection: iterations per vertex by zone (centre, middle, silhouette),\n"
      "ms against the reflected vertex count (x1, x4, x16 by edge splitting), and the specular\n"
      "error against the exact reference beside envmap, distance-map and planar-mirror.\n"
      "Example: speculum experiment vertex-projection --quick --json");
  cmd->add_option("--width", o->width, "Image width")->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_flag("--quick", o->quick,
                "Smoke check: two scenes, two edge lengths, envmap beside, one run, 4-spp references");
  cmd->add_option("--reference-cache", o->reference_cache,
                  "Matrix output directory that keeps the traced references (default: a temporary one)");
  cmd->add_flag("--json", o->json,
                "One JSON object per row: kind iterations (scene, zone, median, max), scaling "
                "(scene, vertices, ms) or error (scene, technique, mae8_specular)");
  cmd->callback([o, &global] { run_vertex_projection_experiment(*o, global); });
}

}  // namespace speculum::cli
