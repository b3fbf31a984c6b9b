// `speculum experiment yu-fig9`: YU Fig.9 (YU §4) — glossy-plane with its object
// tessellated on res×res vertex grids, traced with LOD off and α ∈ {1, 3, 10}: per-frame glossy
// time, nodes and triangle tests per ray, and error against the reference tracer.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/techniques/render_frame.h"
#include "apps/techniques/recipes.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "core/error.h"
#include "core/image_metrics.h"
#include "core/procedural_geometry.h"
#include "core/sampling.h"
#include "parallel/executor.h"
#include "raster/composite.h"
#include "trace/reference_tracer.h"

namespace speculum::cli {

namespace {

struct YuFig9Options {
  int width = 512;
  int samples = 30;
  int min_res = 32;
  int max_res = 1024;
  std::vector<std::string> alphas = {"off", "1", "3", "10"};
  int reference_spp = 64;
  int runs = 3;
  std::string reference_cache = (std::filesystem::temp_directory_path() / "speculum_yu_fig9").string();
  std::string save_images;  // '' : none
  bool json = false;
};

// YU Fig.9's arrangement — one smooth object on a glossy plane, its reflection filling most
// of the glossy pixels — built from glossy-plane's parts: the vase profile (2.5× wider, 1.5×
// taller: a squat pot) sampled on a res×res vertex grid (a geometry-image-like tessellation,
// as YU's gargoyle: 2 (res-1)² triangles) on a checkered glossy plane of 2 triangles. The
// camera stands low and close, tilted down, so most floor pixels mirror the pot and most
// glossy rays meet it (not the sky). The plane's roughness 0.35 (Phong n ≈ 131, lobe
// half-width ≈ 6°) is a glossy lobe; glossy-plane's 0.25 (n ≈ 510, ≈ 3°) is near mirror.
Scene fig9_scene(int res) {
  using namespace procedural;
  SceneBuilder b("yu-fig9 " + std::to_string(res));
  Material plane_m = glossy("glossy floor", glm::vec3(1.0f), 0.35f);
  plane_m.base_color_texture.texture =
      b.add_texture(checker_texture(256, 16, {0.7f, 0.7f, 0.72f}, {0.25f, 0.25f, 0.28f}), "checker");
  const auto plane = b.add_material(plane_m);
  const auto vase = b.add_material(diffuse("terracotta vase", {0.7f, 0.3f, 0.15f}));
  b.add_object("plane", plane, quad({-20.0f, 0.0f, 20.0f}, {40.0f, 0, 0}, {0, 0, -40.0f}, 1, 1, 20.0f));
  b.add_object("vase", vase, parametric_grid(res - 1, res - 1, [](float u, float v) {
                 const float r = 0.25f + 0.3f * std::sin(kPi * std::min(v * 1.2f, 1.0f)) + 0.08f * v * v;
                 const float phi = -2.0f * kPi * u;  // du × dv outward
                 return glm::vec3(2.5f * r * std::cos(phi), 2.4f * v, 2.5f * r * std::sin(phi));
               }));
  Scene s = b.take();
  Camera c;
  c.name = "main";
  c.eye = {0.0f, 0.6f, 3.0f};
  c.target = {0.0f, -0.3f, 0.0f};
  c.vfov_degrees = 50.0f;
  c.znear = 0.05f;
  c.zfar = 100.0f;
  s.cameras.push_back(c);
  const glm::vec3 sun{0.4f, 0.8f, 0.3f};
  Light l;
  l.name = "sun";
  l.type = LightType::Directional;
  l.direction = -glm::normalize(sun);
  l.intensity = 3.0f;
  l.color = glm::vec3(1.0f, 0.95f, 0.85f);
  s.lights.push_back(l);
  s.environment.equirect = sky_equirect(512, 256, sun);
  s.environment.source = "procedural sky";
  return s;
}

ImageRGBA reference_display(const Scene& scene, int res, const pipeline::FrameSettings& f,
                            const YuFig9Options& o, par::Executor& ex) {
  std::string cached;
  if (!o.reference_cache.empty()) {
    std::filesystem::create_directories(o.reference_cache);
    cached = (std::filesystem::path(o.reference_cache) /
              ("v2_res" + std::to_string(res) + "_" + std::to_string(f.width) + "_spp" +
               std::to_string(o.reference_spp) + ".exr")).string();
    if (std::filesystem::exists(cached)) return raster::tonemap(ex, read_image(cached), f.exposure);
  }
  trace::ReferenceOptions r;
  r.width = f.width;
  r.height = f.height;
  r.spp = o.reference_spp;
  r.seed = 12345;
  r.pixel_jitter = false;  // pixel centres, as the rasterized primary visibility
  const ImageRGBA radiance = trace::render_reference(scene, f.camera, r, ex);
  if (!cached.empty()) write_image(cached, radiance);
  return raster::tonemap(ex, radiance, f.exposure);
}

std::uint64_t counter(const par::RunReport& r, const char* node, const char* name) {
  const par::NodeRecord* n = r.find(node);
  if (!n) return 0;
  const auto it = n->counters.find(name);
  return it == n->counters.end() ? 0 : it->second;
}

double node_ms(const par::RunReport& r, const char* node) {
  const par::NodeRecord* n = r.find(node);
  return n ? n->duration_ns * 1e-6 : 0.0;
}

void run_yu_fig9(const YuFig9Options& o, const GlobalOptions& global) {
  if (o.min_res > o.max_res) throw InputError("--min-res", "larger than --max-res");
  std::vector<float> alphas;
  for (const std::string& a : o.alphas) {
    if (a == "off" || a == "0") {
      alphas.push_back(0.0f);
      continue;
    }
    std::istringstream in(a);
    float v = 0.0f;
    if (!(in >> v) || !in.eof() || !(v > 0.0f) || !std::isfinite(v))
      throw InputError("--alpha", "expected 'off' or a positive number, got '" + a + "'");
    alphas.push_back(v);
  }
  par::Executor ex(global.threads, global.lanes);
  ResultTable table(o.json);
  std::size_t resolutions = 0;
  for (int res = o.min_res; res <= o.max_res; res *= 2) ++resolutions;
  Progress progress("yu-fig9", resolutions * alphas.size(), global.quiet);
  table.set_progress(&progress);
  for (int res = o.min_res; res <= o.max_res; res *= 2) {
    const Scene scene = fig9_scene(res);
    pipeline::FrameSettings f;
    f.width = o.width;
    f.height = o.width;
    f.spp = o.samples;
    f.camera = scene.cameras.front();
    const ImageRGBA reference = reference_display(scene, res, f, o, ex);
    // BVH, bake and LOD data are built by the first frame and shared by the others (a
    // static scene: YU precomputes them); `ms` is the per-frame glossy work.
    auto cache = std::make_shared<trace::LodStaticData>();
    pipeline::Technique technique = pipeline::find_technique("yu-lod");
    technique.recipe = [cache](par::Graph& g, const Scene* sc, const pipeline::FrameSettings& fs) {
      return pipeline::add_yu_lod_passes_cached(g, sc, fs, cache);
    };
    double static_ms = 0.0;
    for (std::size_t ai = 0; ai < alphas.size(); ++ai) {
      const float alpha = alphas[ai];
      f.alpha = alpha;
      std::vector<double> ms, trace_ms, rays_ms, shade_ms;
      pipeline::FrameResult frame;
      for (int run = 0; run < std::max(1, o.runs); ++run) {
        frame = pipeline::render_frame(scene, technique, f, ex);
        if (static_ms == 0.0)
          static_ms = node_ms(frame.report, "bvh_build") + node_ms(frame.report, "radiance_bake") +
                      node_ms(frame.report, "lod_build");
        ms.push_back(node_ms(frame.report, "glossy_rays") + node_ms(frame.report, "lod_trace") +
                     node_ms(frame.report, "hit_radiance"));
        trace_ms.push_back(node_ms(frame.report, "lod_trace"));
        rays_ms.push_back(node_ms(frame.report, "glossy_rays"));
        shade_ms.push_back(node_ms(frame.report, "hit_radiance"));
      }
      for (auto* v : {&ms, &trace_ms, &rays_ms, &shade_ms}) std::sort(v->begin(), v->end());
      const double rays = static_cast<double>(std::max<std::uint64_t>(1, counter(frame.report, "lod_trace", "rays")));
      const ImageError e = image_error(frame.display, reference, "yu-lod vs reference");
      if (!o.save_images.empty()) {
        std::filesystem::create_directories(o.save_images);
        const std::string stem = (std::filesystem::path(o.save_images) / ("res" + std::to_string(res))).string();
        if (ai == 0) write_image(stem + "_reference.png", reference);
        std::ostringstream name;
        name << stem << "_alpha_" << (alpha > 0.0f ? o.alphas[ai] : std::string("off")) << ".png";
        write_image(name.str(), frame.display);
      }
      table.cell("mesh_res", res)
          .cell("triangles", static_cast<std::int64_t>(scene.mesh.triangle_count()));
      if (alpha > 0.0f) table.cell("alpha", static_cast<double>(alpha), 0);
      else table.cell("alpha", "off");
      table.cell("ms", ms[ms.size() / 2], 1)
          .cell("rays_ms", rays_ms[rays_ms.size() / 2], 1)
          .cell("trace_ms", trace_ms[trace_ms.size() / 2], 1)
          .cell("shade_ms", shade_ms[shade_ms.size() / 2], 1)
          .cell("nodes_per_ray", double(counter(frame.report, "lod_trace", "nodes_visited")) / rays, 1)
          .cell("tris_per_ray", double(counter(frame.report, "lod_trace", "triangle_tests")) / rays, 1)
          .cell("proxy_hit_frac", double(counter(frame.report, "lod_trace", "proxy_hits")) / rays, 3)
          .cell("rmse", e.rmse, 4)
          .cell("psnr", e.psnr, 2)
          .cell("static_ms", static_ms, 0);
      table.end_row();
    }
  }
}

}  // namespace

void add_experiment_yu_fig9_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<YuFig9Options>();
  auto* cmd = experiment.add_subcommand(
      "yu-fig9",
      "YU Fig.9: one object on a glossy plane, the object at res² samples (32²..1024²), LOD off vs "
      "α=1,3,10: glossy ms/frame (rays_ms + trace_ms + shade_ms), nodes and triangle tests per "
      "ray, rmse/psnr vs the reference tracer.\n"
      "Set-up: glossy-plane's vase profile as a squat pot (2.5× wide, 2.4 tall) on a 40×40 "
      "checkered glossy plane (roughness 0.35, Phong n≈131; 2 triangles), sun + sky; camera at "
      "(0, 0.6, 3) looking at (0, -0.3, 0), 50° — low and close, so the pot's reflection fills "
      "most glossy pixels, as in YU Fig.9.\n"
      "Example: speculum experiment yu-fig9 --width 128 --samples 8 --max-res 128 --runs 1");
  cmd->add_option("--width", o->width, "Image width and height")->check(CLI::Range(8, 4096))->capture_default_str();
  cmd->add_option("--samples", o->samples, "Glossy rays per pixel N")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--min-res", o->min_res, "Smallest mesh resolution (vertices per side)")
      ->check(CLI::Range(2, 4096))->capture_default_str();
  cmd->add_option("--max-res", o->max_res, "Largest mesh resolution (doubling from --min-res)")
      ->check(CLI::Range(2, 4096))->capture_default_str();
  cmd->add_option("--alpha", o->alphas, "α values to run (repeatable; 'off' = LOD off)")->capture_default_str();
  cmd->add_option("--reference-spp", o->reference_spp, "Reference tracer samples per pixel (one reference per mesh resolution)")
      ->check(CLI::Range(1, 65536))->capture_default_str();
  cmd->add_option("--runs", o->runs, "Frames timed per row (the median is printed)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  cmd->add_option("--reference-cache", o->reference_cache,
                  "Directory caching the reference EXRs per resolution/size/spp ('' : none)")
      ->capture_default_str();
  cmd->add_option("--save-images", o->save_images,
                  "Directory for each row's display PNG and each resolution's reference PNG ('' : none)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_yu_fig9(*o, global); });
}

}  // namespace speculum::cli
