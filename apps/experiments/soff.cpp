// `speculum experiment soff`: the measurements of SOFF §4 — per scene and camera path the
// specular error against the exact specular reference (same shading of the hits), the frame
// error against the path-traced reference, the disocclusion pixels, the clusters, the stage
// split and the speed against tracing the same reflected rays with our BVH (rebuilt every
// frame, as SOFF's Optix comparison, and prebuilt); with --sweeps the Table 3/4/5/8 trends.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/error.h"
#include "core/image_metrics.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "core/shading.h"
#include "raster/soff.h"
#include "raster/gbuffer.h"
#include "raster/visibility.h"
#include "trace/bvh.h"

namespace speculum::cli {
namespace {

struct SoffExperimentOptions {
  std::vector<std::string> scenes;  // "scene[:options]"; empty: SOFF's two
  std::vector<std::string> paths;   // empty: every path of each scene
  int frames = 30;                  // per path, spread evenly over the path
  int width = 512;                  // square output
  int supersample = 2;              // k×k samples per pixel (SOFF: 2×2)
  int glossy_rays = 8;
  int glossy_samples = 64;          // the specular reference's GGX samples per glossy pixel
  int reference_spp = 16;           // the frame reference (path tracer), first frame only
  bool sweeps = false;
  bool quick = false;
  bool json = false;
  std::string images;
  std::vector<std::string> params;  // soff's --param name=value (the path rows)
  std::map<std::string, double> soff_params;  // parsed               // write each frame's soff / exact / difference images here
};

// SOFF's scenes (§4): the living room with 25 reflectors at ~290K triangles and the bathroom at ~90K.
const std::vector<std::string> kScenes = {"living-room:size=240000:reflectors=25", "bathroom"};

double ms_of(const par::RunReport& r, const char* node) {
  const par::NodeRecord* n = r.find(node);
  return n ? double(n->duration_ns) * 1e-6 : 0.0;
}
double counter_of(const par::RunReport& r, const char* node, const char* counter) {
  const par::NodeRecord* n = r.find(node);
  if (!n) return 0.0;
  const auto it = n->counters.find(counter);
  return it == n->counters.end() ? 0.0 : it->second;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Mean absolute 8-bit difference over the pixels whose centre sample is specular: all of
// them, the mirror ones and the glossy ones.
struct SpecularError {
  double all = 0.0, mirror = 0.0, glossy = 0.0;
};
SpecularError specular_mae8(const Scene& scene, const Camera& camera, const ImageRGBA& a, const ImageRGBA& b,
                            par::Executor& ex) {
  const raster::VisibilityBuffer vis = raster::render_visibility(ex, scene, camera, a.width, a.height);
  const raster::GBuffer g = raster::resolve_gbuffer(ex, scene, vis, camera.eye);
  double sum[3] = {0.0, 0.0, 0.0};
  std::size_t n[3] = {0, 0, 0};
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const SurfaceParams& s = g.surface[i];
    if (!g.covered(i) || !raster::is_specular(s)) continue;
    double e = 0.0;
    for (int ch = 0; ch < 3; ++ch) e += std::abs(display_to_8bit(a.pixels[i][ch]) - display_to_8bit(b.pixels[i][ch]));
    const int kind = s.is_refractor() ? 0 : s.is_glossy_lobe() ? 2 : 1;
    sum[0] += e, ++n[0];
    if (kind) sum[kind] += e, ++n[kind];
  }
  const auto mean = [&](int k) { return n[k] ? sum[k] / (3.0 * double(n[k])) : 0.0; };
  return {mean(0), mean(1), mean(2)};
}

// The scene with every triangle of its reflectors (mirror and glossy materials) split into
// four at its edge midpoints, attributes interpolated: the same shapes and shading with 4×
// the reflector triangles (SOFF §4.2.1: the cost does not depend on the non-diffuse
// triangles, which only reach the G-buffer).
Scene with_reflectors_split(const Scene& in) {
  Scene out = in;
  const TriangleMesh& m = in.mesh;
  TriangleMesh& o = out.mesh;
  o.indices.clear(), o.triangle_material.clear(), o.triangle_object.clear();
  const auto mid = [&](std::uint32_t a, std::uint32_t b) {
    const auto index = static_cast<std::uint32_t>(o.positions.size());
    o.positions.push_back(0.5f * (m.positions[a] + m.positions[b]));
    const glm::vec3 n = m.normals[a] + m.normals[b];
    o.normals.push_back(glm::length(n) > 0.0f ? glm::normalize(n) : m.normals[a]);
    if (!m.tangents.empty()) {
      const glm::vec3 t = glm::vec3(m.tangents[a]) + glm::vec3(m.tangents[b]);
      o.tangents.push_back(glm::vec4(glm::length(t) > 0.0f ? glm::normalize(t) : glm::vec3(m.tangents[a]),
                                     m.tangents[a].w));
    }
    o.uvs.push_back(0.5f * (m.uvs[a] + m.uvs[b]));
    if (!m.uvs1.empty()) o.uvs1.push_back(0.5f * (m.uvs1[a] + m.uvs1[b]));
    return index;
  };
  for (Object& obj : out.objects) {
    const std::uint32_t first = obj.first_triangle, count = obj.triangle_count;
    obj.first_triangle = static_cast<std::uint32_t>(o.triangle_count());
    for (std::uint32_t t = first; t < first + count; ++t) {
      const std::uint32_t a = m.indices[3 * t], b = m.indices[3 * t + 1], c = m.indices[3 * t + 2];
      const std::uint32_t material = m.triangle_material[t], object = m.triangle_object[t];
      const auto add = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
        o.indices.insert(o.indices.end(), {x, y, z});
        o.triangle_material.push_back(material);
        o.triangle_object.push_back(object);
      };
      if (!raster::soff_reflects(surface_params(in.materials[material]))) {
        add(a, b, c);
        continue;
      }
      const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      add(a, ab, ca), add(ab, b, bc), add(ca, bc, c), add(ab, bc, ca);
    }
    obj.triangle_count = static_cast<std::uint32_t>(o.triangle_count()) - obj.first_triangle;
  }
  out.validate();
  return out;
}

std::size_t reflector_triangles(const Scene& scene) {
  std::size_t n = 0;
  for (std::uint32_t mat : scene.mesh.triangle_material) n += raster::soff_reflects(surface_params(scene.materials[mat]));
  return n;
}

struct Frame {
  pipeline::FrameResult soff;
  double samples = 0;
};

pipeline::FrameSettings settings_for(const Camera& camera, int width, int k, std::map<std::string, double> params,
                                     const std::string& technique) {
  pipeline::FrameSettings f;
  f.width = f.height = width;
  f.supersample = k;
  f.spp = k * k;
  f.camera = camera;
  f.exposure = 1.0f;
  f.params = std::move(params);
  return pipeline::find_technique(technique).with_defaults(f);
}

pipeline::FrameResult run(const Scene& scene, const std::string& technique, const pipeline::FrameSettings& f,
                          par::Executor& ex) {
  return pipeline::render_frame(scene, pipeline::find_technique(technique), f, ex);
}

void path_row(const Scene& scene, const std::string& scene_name, const CameraPath& path,
              const SoffExperimentOptions& o, par::Executor& ex, ResultTable& table, Progress& progress) {
  const int frames = std::max(1, std::min(o.frames, path.frames));
  std::vector<double> ms, ms_cl, ms_cam, ms_di, ms_is, ms_rebuild, ms_prebuilt, mae, mae_mirror, mae_glossy, dis,
      clusters, mae_trace, mae_trace_glossy;
  double mae_frame = -1.0;
  for (int k = 0; k < frames; ++k) {
    // Frames spread evenly over the path (the first and the last key included).
    const int index = frames == 1 ? 0 : int(std::lround(double(k) * double(path.frames - 1) / double(frames - 1)));
    const Camera cam = path.at(index);
    std::map<std::string, double> soff_params = o.soff_params;
    soff_params["glossy_rays"] = o.glossy_rays;
    const pipeline::FrameSettings f = settings_for(cam, o.width, o.supersample, soff_params, "soff");
    const pipeline::FrameResult soff = run(scene, "soff", f, ex);
    const par::RunReport& r = soff.report;
    ms.push_back(double(r.duration_ns) * 1e-6);
    ms_cl.push_back(ms_of(r, "soff_clusters"));
    ms_cam.push_back(ms_of(r, "soff_cameras"));
    ms_di.push_back(ms_of(r, "soff_depth_images"));
    ms_is.push_back(ms_of(r, "soff_intersect"));
    const double samples = double(f.width) * double(f.height) * double(f.supersample * f.supersample);
    dis.push_back(100.0 * counter_of(r, "soff_intersect", "disoccluded_samples") / samples);
    clusters.push_back(counter_of(r, "soff_clusters", "clusters"));
    // The same reflected rays traced through a BVH rebuilt in the frame (the specular
    // reference with as many lobe samples per glossy pixel as SOFF's rays), and the BVH
    // build alone, to subtract for a prebuilt BVH.
    const pipeline::FrameResult traced =
        run(scene, "specular-reference", settings_for(cam, o.width, o.supersample, {{"glossy_samples", o.glossy_rays}},
                                                      "specular-reference"),
            ex);
    const double rebuild = double(traced.report.duration_ns) * 1e-6;
    const auto t0 = std::chrono::steady_clock::now();
    const trace::Bvh bvh = trace::Bvh::build(scene.mesh, ex);
    const double build = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ms_rebuild.push_back(rebuild);
    ms_prebuilt.push_back(std::max(0.0, rebuild - build));
    // The error against the exact specular layer: with as many lobe samples as soff's rays
    // it is the frame just traced (the same rays: the depth images' error alone), with more
    // the glossy lobes converge (soff's sampling noise included).
    const pipeline::FrameResult exact =
        o.glossy_samples == o.glossy_rays
            ? traced
            : run(scene, "specular-reference",
                  settings_for(cam, o.width, o.supersample, {{"glossy_samples", o.glossy_samples}}, "specular-reference"),
                  ex);
    const SpecularError e = specular_mae8(scene, cam, soff.display, exact.display, ex);
    if (!o.images.empty()) {
      // SOFF Fig. 8: the two images and their absolute 8-bit difference, scaled by 8.
      std::string stem = o.images + "/" + scene_name.substr(0, scene_name.find(':')) + "_" + path.name + "_" +
                         std::to_string(index);
      ImageRGBA diff(soff.display.width, soff.display.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
      for (std::size_t i = 0; i < diff.pixels.size(); ++i)
        for (int ch = 0; ch < 3; ++ch) {
          const int d = std::abs(display_to_8bit(soff.display.pixels[i][ch]) - display_to_8bit(exact.display.pixels[i][ch]));
          diff.pixels[i][ch] = srgb_to_linear(std::min(1.0f, 8.0f * float(d) / 255.0f));
        }
      write_image(stem + "_soff.png", soff.display);
      write_image(stem + "_exact.png", exact.display);
      write_image(stem + "_diff8.png", diff);
    }
    mae.push_back(e.all), mae_mirror.push_back(e.mirror), mae_glossy.push_back(e.glossy);
    // The traced frame with soff's rays against the same reference: the sampling noise of
    // N lobe rays that any method tracing them has (0 when the reference uses those rays).
    const SpecularError et = specular_mae8(scene, cam, traced.display, exact.display, ex);
    mae_trace.push_back(et.all), mae_trace_glossy.push_back(et.glossy);
    if (k == 0 && o.reference_spp > 0) {
      pipeline::FrameSettings rf = settings_for(cam, o.width, 1, {}, "reference");
      rf.spp = o.reference_spp;
      const pipeline::FrameResult ref = run(scene, "reference", rf, ex);
      mae_frame = image_error(soff.display, ref.display).mae8;
    }
    progress.step(scene_name + " " + path.name);
  }
  const auto mean = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / double(v.size());
  };
  const double dis_avg = mean(dis), cl_avg = mean(clusters), mae_avg = mean(mae);
  const double m = median(ms), rebuild = median(ms_rebuild), prebuilt = median(ms_prebuilt);
  table.cell("row", "path")
      .cell("scene", scene_name)
      .cell("path", path.name)
      .cell("frames", int(ms.size()))
      .cell("width", o.width)
      .cell("supersample", o.supersample)
      .cell("triangles", std::int64_t(scene.mesh.triangle_count()))
      .cell("mae8_specular", mae_avg, 2)
      .cell("mae8_mirror", mean(mae_mirror), 2)
      .cell("mae8_glossy", mean(mae_glossy), 2)
      .cell("mae8_trace_specular", mean(mae_trace), 2)
      .cell("mae8_trace_glossy", mean(mae_trace_glossy), 2)
      .cell("mae8_frame", mae_frame, 2)
      .cell("disocclusion_pct_avg", dis_avg, 3)
      .cell("disocclusion_pct_max", *std::max_element(dis.begin(), dis.end()), 3)
      .cell("clusters_avg", cl_avg, 1)
      .cell("clusters_max", *std::max_element(clusters.begin(), clusters.end()), 0)
      .cell("ms", m, 1)
      .cell("ms_clustering", median(ms_cl), 2)
      .cell("ms_cameras", median(ms_cam), 2)
      .cell("ms_depth_images", median(ms_di), 1)
      .cell("ms_intersect", median(ms_is), 1)
      .cell("ms_trace_rebuild", rebuild, 1)
      .cell("ms_trace_prebuilt", prebuilt, 1)
      .cell("speedup_vs_rebuild", m > 0 ? rebuild / m : 0.0, 2)
      .cell("speedup_vs_prebuilt", m > 0 ? prebuilt / m : 0.0, 2);
  table.end_row();
}

// One frame of soff with `params`: a sweep row.
void sweep_row(const Scene& scene, const std::string& scene_name, const Camera& cam, const std::string& sweep,
               double value, int width, std::map<std::string, double> params, const SoffExperimentOptions& o,
               par::Executor& ex, ResultTable& table, Progress& progress) {
  const pipeline::FrameSettings f = settings_for(cam, width, o.supersample, std::move(params), "soff");
  std::vector<double> ms;
  pipeline::FrameResult last;
  for (int k = 0; k < 3; ++k) {
    last = run(scene, "soff", f, ex);
    ms.push_back(double(last.report.duration_ns) * 1e-6);
  }
  const par::RunReport& r = last.report;
  const double samples = double(f.width) * double(f.height) * double(f.supersample * f.supersample);
  table.cell("row", "sweep")
      .cell("scene", scene_name)
      .cell("sweep", sweep)
      .cell("value", value, 3)
      .cell("width", width)
      .cell("triangles", std::int64_t(scene.mesh.triangle_count()))
      .cell("reflector_triangles", std::int64_t(reflector_triangles(scene)))
      .cell("clusters", counter_of(r, "soff_clusters", "clusters"), 0)
      .cell("disocclusion_pct", 100.0 * counter_of(r, "soff_intersect", "disoccluded_samples") / samples, 3)
      .cell("depth_image_pixels", counter_of(r, "soff_cameras", "depth_image_pixels"), 0)
      .cell("ms", median(ms), 1)
      .cell("ms_clustering", ms_of(r, "soff_clusters"), 2)
      .cell("ms_cameras", ms_of(r, "soff_cameras"), 2)
      .cell("ms_depth_images", ms_of(r, "soff_depth_images"), 1)
      .cell("ms_intersect", ms_of(r, "soff_intersect"), 1);
  table.end_row();
  progress.step("sweep " + sweep);
}

void run_soff_experiment(SoffExperimentOptions o, const GlobalOptions& global) {
  if (o.quick) {
    if (o.scenes.empty()) o.scenes = {"bathroom"};
    o.frames = std::min(o.frames, 4);
    o.width = std::min(o.width, 256);
    o.glossy_samples = std::min(o.glossy_samples, 16);
  }
  for (const std::string& item : o.params) {
    const auto [name, v] = pipeline::parse_technique_param(pipeline::find_technique("soff"), item);
    if (name == "glossy_rays")
      throw InputError("--param glossy_rays", "use --glossy-rays (the trace columns use the same count)");
    o.soff_params[name] = v;
  }
  pipeline::check_technique_params(pipeline::find_technique("soff"), o.soff_params);
  const std::vector<std::string>& scenes = o.scenes.empty() ? kScenes : o.scenes;
  // Resolve every scene's paths before rendering anything: a bad name fails at once.
  std::vector<std::pair<std::string, std::vector<CameraPath>>> work;
  std::size_t steps = 0;
  for (const std::string& name : scenes) {
    const std::string base = name.substr(0, name.find(':'));
    std::vector<CameraPath> paths = builtin_camera_paths(base);
    if (paths.empty())
      throw InputError("--scenes", "scene '" + base + "' has no camera paths (bathroom and living-room have)");
    if (!o.paths.empty()) {
      std::vector<CameraPath> chosen;
      for (const std::string& p : o.paths)
        for (const CameraPath& c : paths)
          if (c.name == p) chosen.push_back(c);
      paths = std::move(chosen);
    }
    if (o.quick && paths.size() > 1) paths.resize(1);
    if (paths.empty()) throw InputError("--paths", "none of the named paths exists in scene '" + base + "'");
    steps += paths.size() * std::size_t(o.frames);
    work.emplace_back(name, std::move(paths));
  }
  if (o.sweeps) steps += 14;
  par::Executor ex(global.threads, global.lanes);
  ResultTable table(o.json);
  Progress progress("soff", steps, global.quiet);
  table.set_progress(&progress);
  for (const auto& [name, paths] : work) {
    const Scene scene = load_scene(name);
    for (const CameraPath& path : paths) path_row(scene, name, path, o, ex, table, progress);
  }
  if (!o.sweeps) return;
  // The trends of SOFF Tables 3, 4, 5 and 8 on the first frame of the first path.
  const std::string& name = work.front().first;
  const Scene scene = load_scene(name);
  const Camera cam = work.front().second.front().at(0);
  for (double s : {0.5, 1.0, 2.0})  // Table 3 / Fig.7: clusters and disocclusion against the bins
    sweep_row(scene, name, cam, "bin_scale", s, o.width,
              {{"theta_bins", std::max(1.0, std::round(13 * s))}, {"phi_bins", std::max(1.0, std::round(8 * s))}}, o,
              ex, table, progress);
  for (int w : {o.width / 2, o.width, o.width * 2})  // Table 4: output size
    sweep_row(scene, name, cam, "output_width", w, w, {}, o, ex, table, progress);
  for (double s : {0.5, 1.0, 2.0})  // Table 5: depth-image resolution
    sweep_row(scene, name, cam, "image_scale", s, o.width, {{"image_scale", s}}, o, ex, table, progress);
  for (int rays : {8, 49})  // Table 8: glossy rays per pixel
    sweep_row(scene, name, cam, "glossy_rays", rays, o.width, {{"glossy_rays", rays}}, o, ex, table, progress);
  // Table 6 / §4.2.1: the reflectors' triangles × 4 (same shapes) change little.
  sweep_row(scene, name, cam, "reflector_triangles", 1, o.width, {}, o, ex, table, progress);
  sweep_row(with_reflectors_split(scene), name, cam, "reflector_triangles", 4, o.width, {}, o, ex, table, progress);
}

}  // namespace

void add_experiment_soff_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<SoffExperimentOptions>();
  auto* cmd = experiment.add_subcommand(
      "soff",
      "SOFF §4: per scene and camera path the specular error against the exact specular "
      "reference, the disocclusion pixels, clusters, the stage split and the speed against "
      "tracing the same rays with a BVH rebuilt per frame and prebuilt; --sweeps adds the "
      "bins / output size / depth-image scale / glossy rays / reflector triangles trends (Tables 3, 4, 5, 8, 6).\n"
      "Example: speculum experiment soff --quick --json");
  cmd->add_option("--scenes", o->scenes,
                  "Scenes with camera paths (default: living-room:size=240000:reflectors=25, bathroom)")
      ->delimiter(',');
  cmd->add_option("--paths", o->paths, "Path names (default: every path of each scene)")->delimiter(',');
  cmd->add_option("--frames", o->frames, "Frames per path, spread evenly over it")
      ->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_option("--width", o->width, "Output side (square; SOFF: 512)")->check(CLI::Range(16, 2048))->capture_default_str();
  cmd->add_option("--supersample", o->supersample, "k×k samples per pixel (SOFF: 2)")
      ->check(CLI::Range(1, 4))->capture_default_str();
  cmd->add_option("--glossy-rays", o->glossy_rays, "soff's rays per glossy sample (SOFF: 8 to 49)")
      ->check(CLI::Range(1, 64))->capture_default_str();
  cmd->add_option("--glossy-samples", o->glossy_samples, "The specular reference's GGX samples per glossy pixel")
      ->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--reference-spp", o->reference_spp,
                  "Path-traced reference samples for mae8_frame (first frame of each path; 0: skip)")
      ->check(CLI::Range(0, 4096))->capture_default_str();
  cmd->add_option("--param", o->params, "soff parameter name=value for the path rows, repeatable (see `speculum techniques`)");
  cmd->add_option("--images", o->images,
                  "Write each frame's soff and exact-specular images and their 8-bit difference ×8 "
                  "(SOFF Fig. 8) into this existing directory")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--sweeps", o->sweeps, "Add the Table 3/4/5/8 sweeps on the first frame of the first path");
  cmd->add_flag("--quick", o->quick, "One scene (bathroom), one path, 4 frames, 256² (tests and smoke checks)");
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_soff_experiment(*o, global); });
}

}  // namespace speculum::cli
