// `speculum bench raster MESH|SCENE --json`: times `visibility` + `gbuffer` K times after a
// warm-up and prints one JSON object (the rasterizer's yardstick, beside llvmpipe's);
// per-kernel medians come from the executor's launch records.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/bench/bench_workloads.h"
#include "apps/cli/camera_options.h"
#include "apps/cli/json_output.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/scene_loader.h"
#include "raster/gbuffer.h"
#include "raster/visibility.h"

namespace speculum::cli {
namespace {

struct BenchRasterOptions {
  std::string scene = "bench:spheres-room";
  int width = 1920;
  int height = 1080;
  int repeat = 10;
  bool json = false;
  std::string write_ply;
  std::string write_ids;
  std::string cull = "none";
  std::string gbuffer_source = "records";
  bool plane_hashes = false;
  pipeline::CameraOverrides camera;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The visibility buffer as the llvmpipe yardstick's --write-ids writes its primitive ids:
// width × height little-endian uint32, top row first, triangle index + 1 (0: nothing), so
// the two rasterizers can be compared pixel by pixel.
void write_triangle_ids(const std::string& path, const raster::VisibilityBuffer& vis) {
  std::vector<std::uint32_t> ids(vis.triangle.size());
  for (std::size_t i = 0; i < ids.size(); ++i)
    ids[i] = vis.triangle.pixels[i] == kNoId ? 0u : vis.triangle.pixels[i] + 1u;
  const std::string bytes(reinterpret_cast<const char*>(ids.data()), ids.size() * sizeof(std::uint32_t));
  write_text_file(path, bytes);  // the host is little-endian (x86-64)
}

// FNV-1a 64 of a plane's bytes (every byte of both buffers is defined, background included).
template <class Plane>
std::string plane_hash(const Plane& p) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* b = reinterpret_cast<const unsigned char*>(p.pixels.data());
  for (std::size_t i = 0; i < p.pixels.size() * sizeof(p.pixels[0]); ++i) h = (h ^ b[i]) * 1099511628211ull;
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

// The surface plane hashed as the parameters of every sample in turn: the bytes a plane of
// per-sample parameters would hold, whatever the samples share.
std::string plane_hash(const SurfacePlane& p) {
  Buffer2D<SurfaceParams> values(p.width(), p.height());
  for (std::size_t i = 0; i < p.size(); ++i) values.pixels[i] = p[i];
  return plane_hash(values);
}

void run_bench_raster(const BenchRasterOptions& o, const GlobalOptions& global) {
  if (o.repeat < 1) throw InputError("--repeat", "must be at least 1");
  if (double(o.width) * o.height > double(1 << 26))  // ~110 bytes per sample
    throw InputError("--width/--height", "more than 67M samples");
  const Scene scene = pipeline::is_bench_workload(o.scene) ? pipeline::make_bench_workload(o.scene)
                                                           : load_scene(o.scene);
  if (!o.write_ply.empty()) pipeline::write_ply(o.write_ply, scene);
  const Camera camera = pipeline::resolve_camera(scene, o.camera, float(o.width) / float(o.height));
  raster::RasterOptions raster_options;
  if (o.cull == "back") raster_options.cull = raster::CullMode::Back;
  else if (o.cull == "front") raster_options.cull = raster::CullMode::Front;
  else if (o.cull != "none") throw InputError("--cull", "expected none, back or front");
  par::Executor executor(global.threads, global.lanes);
  std::vector<double> frame_ms;
  std::map<std::string, std::vector<double>> kernel_ms;
  std::size_t covered = 0;
  // What reaches the tile pass (from the warm-up frame's bins): set-up triangles kept for
  // binning (after off-screen, back-face, zero-area and no-sample rejection) and their
  // references in the tiles' lists.
  std::size_t binned = 0, tile_refs = 0, max_tile_refs = 0;
  OrderedJson hashes = OrderedJson::object();
  // Render targets and bins persist across frames, as a GPU application's would.
  raster::RasterWorkspace workspace;
  raster::VisibilityBuffer vis;
  raster::GBuffer g;
  // The per-triangle G-buffer records are scene-static (built once, like a vertex-buffer
  // upload): timed here, outside the frame, and reported as gbuffer_prepare_ms.
  if (o.gbuffer_source != "records" && o.gbuffer_source != "mesh")
    throw InputError("--gbuffer-source", "expected records or mesh");
  const bool use_records = o.gbuffer_source == "records";
  const auto p0 = executor.now_ns();
  const raster::GBufferTriangles records =
      use_records ? raster::GBufferTriangles(executor, scene) : raster::GBufferTriangles();
  const double prepare_ms = (executor.now_ns() - p0) * 1e-6;
  for (int run = 0; run <= o.repeat; ++run) {  // run 0 is the warm-up
    executor.clear_launches();
    const auto t0 = executor.now_ns();
    raster::render_visibility(executor, scene, camera, o.width, o.height, raster_options,
                              workspace, vis);
    raster::resolve_gbuffer(executor, scene, use_records ? &records : nullptr, vis, camera.eye, g);
    const auto t1 = executor.now_ns();
    if (run == 0) {
      for (std::size_t i = 0; i < g.object.size(); ++i) covered += g.covered(i);
      const raster::TileBins& bins = workspace.bins;
      for (const raster::BinnedChunk& c : bins.chunks) binned += c.count;
      for (std::size_t t = 0; t + 1 < bins.tile_offsets.size(); ++t)
        max_tile_refs = std::max<std::size_t>(max_tile_refs, bins.tile_offsets[t + 1] - bins.tile_offsets[t]);
      tile_refs = bins.tile_offsets.empty() ? 0 : bins.tile_offsets.back();
      if (!o.write_ids.empty()) write_triangle_ids(o.write_ids, vis);
      if (o.plane_hashes) {
        hashes["vis.triangle"] = plane_hash(vis.triangle), hashes["vis.object"] = plane_hash(vis.object);
        hashes["vis.depth"] = plane_hash(vis.depth), hashes["vis.bary"] = plane_hash(vis.bary);
        hashes["gbuffer.object"] = plane_hash(g.object), hashes["gbuffer.position"] = plane_hash(g.position);
        hashes["gbuffer.normal"] = plane_hash(g.normal), hashes["gbuffer.uv"] = plane_hash(g.uv);
        hashes["gbuffer.surface"] = plane_hash(g.surface), hashes["gbuffer.reflector"] = plane_hash(g.reflector);
      }
      continue;
    }
    frame_ms.push_back((t1 - t0) * 1e-6);
    std::map<std::string, double> per_kernel;
    for (const auto& l : executor.launches()) per_kernel[l.name] += l.duration_ns * 1e-6;
    for (const auto& [name, ms] : per_kernel) kernel_ms[name].push_back(ms);
  }
  const double med = median(frame_ms);
  const double lo = *std::min_element(frame_ms.begin(), frame_ms.end());
  const double hi = *std::max_element(frame_ms.begin(), frame_ms.end());
  const std::size_t triangles = scene.mesh.triangle_count();
  if (o.json) {
    OrderedJson kernels = OrderedJson::object();
    for (const auto& [name, v] : kernel_ms) kernels[name] = rounded(median(v), 3);
    OrderedJson j{{"scene", scene.name}, {"triangles", triangles}, {"width", o.width},
                        {"height", o.height}, {"threads", executor.threads()}, {"lanes", executor.lanes()},
                        {"cull", o.cull}, {"repeat", o.repeat}, {"ms_median", rounded(med, 3)},
                        {"ms_min", rounded(lo, 3)}, {"ms_max", rounded(hi, 3)},
                        {"mtris_per_s", rounded(triangles / (med * 1e-3) / 1e6, 3)},
                        {"covered_fraction", rounded(double(covered) / (double(o.width) * o.height), 4)},
                        {"binned_triangles", binned}, {"tile_refs", tile_refs},
                        {"tile_refs_max", max_tile_refs},
                        {"gbuffer_source", o.gbuffer_source}, {"gbuffer_prepare_ms", rounded(prepare_ms, 3)},
                        {"kernels_ms_median", kernels}};
    if (o.plane_hashes) j["plane_hashes"] = hashes;
    std::printf("%s\n", json_line(j).c_str());
  } else {
    std::printf("%s: %zu triangles at %dx%d, %d threads: median %.2f ms (min %.2f, max %.2f), "
                "%.1f Mtris/s\n",
                scene.name.c_str(), triangles, o.width, o.height, executor.threads(), med, lo, hi,
                triangles / (med * 1e-3) / 1e6);
    std::printf("  %zu triangles binned, %zu tile references (at most %zu in one 64x64 tile)\n",
                binned, tile_refs, max_tile_refs);
    for (const auto& [name, v] : kernel_ms) std::printf("  %-22s %8.2f ms\n", name.c_str(), median(v));
    if (use_records) std::printf("  (scene-static gbuffer.prepare, once: %.2f ms)\n", prepare_ms);
  }
}

}  // namespace

void add_bench_raster_subcommand(CLI::App& bench, GlobalOptions& global) {
  auto o = std::make_shared<BenchRasterOptions>();
  auto* cmd = bench.add_subcommand(
      "raster", "Time visibility + gbuffer on a mesh, scene or yardstick workload "
                "(bench:spheres-room, bench:random-triangles)");
  cmd->footer("Example: speculum --threads 2 bench raster bench:spheres-room --width 1920 --height 1080 --repeat 5 --json");
  cmd->add_option("scene", o->scene, "PLY/OBJ/glTF file, built-in scene or bench:* workload")
      ->capture_default_str();
  cmd->add_option("--width", o->width, "Target width")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--height", o->height, "Target height")->check(CLI::Range(1, 16384))->capture_default_str();
  cmd->add_option("--repeat", o->repeat, "Timed repetitions after one warm-up")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print one JSON object");
  cmd->add_option("--cull", o->cull, "Face culling: none (as the llvmpipe yardstick), back, front")
      ->capture_default_str();
  cmd->add_option("--gbuffer-source", o->gbuffer_source,
                  "Where gbuffer reads triangles: records (scene-static per-triangle records, "
                  "built once and timed as gbuffer_prepare_ms) or mesh (index/vertex arrays)")
      ->capture_default_str();
  cmd->add_option("--write-ply", o->write_ply, "Also write the triangles as binary PLY");
  cmd->add_option("--write-ids", o->write_ids,
                  "Also write the visible triangle per pixel (raw little-endian uint32, top row "
                  "first, triangle index + 1, 0 for nothing; as speculum_llvmpipe_bench --write-ids)");
  cmd->add_flag("--plane-hashes", o->plane_hashes,
               "Add the FNV-1a hash of every visibility and G-buffer plane to --json (to check "
               "that two builds write the same bytes)");
  pipeline::add_camera_options(*cmd, o->camera);
  cmd->callback([o, &global] { run_bench_raster(*o, global); });
}

}  // namespace speculum::cli
