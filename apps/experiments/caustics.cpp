// `speculum experiment caustics`: the caustics technique (SURVEY §6) on the three caustic
// scenes, photon_res 32² … 512² × {splat, triangles} × {cube, light} storage: the time of the
// caustic passes (caustic_photons + caustic_map + caustic_gather) and the error of the caustic
// term alone against the light-traced reference's (trace/light_tracer.h, caustics seen
// directly), and the light leak: the share of the technique's caustic energy that lands where
// the reference has none. Storage "cube" is the survey's cube map centred at the generator;
// "light" is the same map centred at the light (shadow-map space, the technique's
// `storage=light`), the variant SURVEY §6.2 argues against: its distance check compares
// distances from the light, which cannot tell the photons' receiver from a point behind it
// along the light's ray.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "apps/cli/commands.h"
#include "apps/cli/progress.h"
#include "apps/cli/result_table.h"
#include "apps/techniques/technique_table.h"
#include "core/error.h"
#include "core/image.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "raster/caustics.h"
#include "raster/composite.h"
#include "raster/environment.h"
#include "raster/shadow_map.h"
#include "trace/bvh.h"
#include "trace/light_tracer.h"

namespace speculum::cli {
namespace {

struct CausticsOptions {
  std::vector<std::string> scenes;
  std::vector<int> photon_res;
  std::vector<std::string> filters;   // the technique's filter modes, by name or number
  std::vector<std::string> storages;  // cube, light
  int width = 160;
  int height = 120;
  int cube_size = 256;
  int caustic_size = 128;
  int reference_photons = 64;  // per pixel, per light and generator
  int chain = 4;               // steps per photon past its first generator (the technique's `chain`)
  std::string images;  // write each row's caustic term, the reference's and their difference here
  bool quick = false;
  bool json = false;
};

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// The caustic term as an image of its own, exposure 1 (as every experiment judges).
ImageRGBA display(par::Executor& ex, const ImageRGBA& radiance) { return raster::tonemap(ex, radiance, 1.0f); }

// Pixels the reference's caustics reach, grown by one pixel (its photons are sparse at the
// edges of a caustic).
std::vector<std::uint8_t> lit_mask(const ImageRGBA& reference) {
  const int w = reference.width, h = reference.height;
  std::vector<std::uint8_t> lit(reference.pixels.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4& p = reference.pixels[static_cast<std::size_t>(y) * w + x];
      if (p.x + p.y + p.z <= 0.0f) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (x + dx >= 0 && x + dx < w && y + dy >= 0 && y + dy < h)
            lit[static_cast<std::size_t>(y + dy) * w + (x + dx)] = 1;
    }
  return lit;
}

void run_caustics(const CausticsOptions& o, const GlobalOptions& global) {
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty()) scenes = {"glass-sphere", "caustic-ring", "water-slab"};
  std::vector<int> resolutions = o.photon_res;
  if (resolutions.empty()) resolutions = o.quick ? std::vector<int>{32, 64} : std::vector<int>{32, 64, 128, 256, 512};
  for (int r : resolutions)
    if (r < 16 || r > 512) throw InputError("--photon-res", std::to_string(r) + " is outside [16, 512]");
  // The filters and storages as the technique names them (`--param filter=...`,
  // `--param storage=...`): the same names in and out.
  const pipeline::Technique& technique = pipeline::find_technique("caustics");
  const auto modes = [&](const std::string& option, const std::string& name, const std::vector<std::string>& given) {
    const pipeline::TechniqueParam* param = nullptr;
    for (const pipeline::TechniqueParam& p : technique.params)
      if (p.name == name) param = &p;
    std::vector<int> out;
    for (const std::string& text : given) try {
        out.push_back(static_cast<int>(pipeline::parse_technique_param(technique, name + "=" + text).second));
      } catch (const InputError& e) {
        throw InputError(option, e.problem());
      }
    if (out.empty())
      for (std::size_t k = 0; k < param->choices.size(); ++k) out.push_back(static_cast<int>(k));
    return std::make_pair(param, out);
  };
  const auto [filter_param, filters] = modes("--filter", "filter", o.filters);
  const auto [storage_param, storages] = modes("--storage", "storage", o.storages);
  const int width = o.quick ? 64 : o.width, height = o.quick ? 48 : o.height;
  const int reference_photons = o.quick ? 4 : o.reference_photons;
  par::Executor ex(global.threads, global.lanes);
  ResultTable table(o.json);
  Progress progress("caustics", scenes.size() * resolutions.size() * storages.size() * filters.size(), global.quiet);
  table.set_progress(&progress);
  for (const std::string& scene_name : scenes) {
    const Scene scene = load_scene(o.quick ? scene_name + ":size=4000" : scene_name);
    if (scene.cameras.empty()) throw InputError(scene_name, "the scene has no camera");
    const Camera& cam = scene.cameras.front();
    // The reference's caustic term: light tracing, seen directly.
    const trace::Bvh bvh = trace::Bvh::build(scene.mesh, ex);
    trace::PhotonOptions po;
    po.photons = static_cast<std::uint64_t>(reference_photons) * width * height;
    const ImageRGBA reference = trace::render_caustics(scene, bvh, cam, width, height, po, ex);
    const ImageRGBA reference_display = display(ex, reference);
    const std::vector<std::uint8_t> lit = lit_mask(reference);
    // The passes the caustic passes read, as the technique's recipe makes them.
    const raster::EnvironmentMap env = raster::build_environment(ex, scene.environment);
    const std::vector<raster::ShadowMap> shadows = raster::render_shadow_maps(ex, scene, 512);
    const raster::GBuffer gbuffer =
        raster::resolve_gbuffer(ex, scene, raster::render_visibility(ex, scene, cam, width, height), cam.eye);
    const raster::ReflectorMaps maps = raster::render_reflector_maps(ex, scene, shadows, env, o.cube_size, &gbuffer);
    const raster::RefractorImpostors impostors = raster::render_refractor_impostors(ex, scene, 128, true);
    const ImageRGBA black(width, height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    for (int res : resolutions) {
      raster::CausticPhotonOptions pho;
      pho.photon_res = res;
      pho.chain = o.chain;
      const auto t0 = std::chrono::steady_clock::now();
      const raster::CausticPhotons photons = raster::trace_photon_images(ex, scene, maps, &impostors, pho);
      const double photons_ms = ms_since(t0);
      for (int storage : storages)
        for (int filter : filters) {
          raster::CausticMapOptions mo;
          mo.size = o.caustic_size;
          mo.filter = static_cast<raster::CausticFilter>(filter);
          mo.storage = static_cast<raster::CausticStorage>(storage);
          const auto t1 = std::chrono::steady_clock::now();
          const raster::CausticMaps cm = raster::build_caustic_maps(ex, scene, photons, mo);
          const ImageRGBA term = raster::gather_caustics(ex, gbuffer, cm, black, 0.05f);
          const double ms = photons_ms + ms_since(t1);
          double total = 0.0, leaked = 0.0;
          for (std::size_t i = 0; i < term.pixels.size(); ++i) {
            const double e = term.pixels[i].x + term.pixels[i].y + term.pixels[i].z;
            total += e;
            if (!lit[i]) leaked += e;
          }
          const ImageRGBA term_display = display(ex, term);
          const ImageError err = image_error(term_display, reference_display, "caustic term vs reference");
          if (!o.images.empty()) {
            // The two caustic terms and their absolute 8-bit difference, scaled by 8.
            const std::string stem = o.images + "/" + scene_name.substr(0, scene_name.find(':')) + "_" +
                                     std::to_string(res) + "_" + filter_param->value_text(filter) + "_" +
                                     storage_param->value_text(storage);
            ImageRGBA diff(width, height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
            for (std::size_t i = 0; i < diff.pixels.size(); ++i)
              for (int ch = 0; ch < 3; ++ch) {
                const int d = std::abs(display_to_8bit(term_display.pixels[i][ch]) -
                                       display_to_8bit(reference_display.pixels[i][ch]));
                diff.pixels[i][ch] = srgb_to_linear(std::min(1.0f, 8.0f * float(d) / 255.0f));
              }
            write_image(stem + ".png", term_display);
            write_image(stem + "_diff8.png", diff);
            write_image(o.images + "/" + scene_name.substr(0, scene_name.find(':')) + "_reference.png",
                        reference_display);
          }
          table.cell("scene", scene_name)
              .cell("filter", filter_param->value_text(filter))
              .cell("storage", storage_param->value_text(storage))
              .cell("photon_res", res)
              .cell("photons", static_cast<std::int64_t>(photons.photons))
              .cell("ms", ms, 1)
              .cell("mae8_caustic", err.mae8, 3)
              .cell("leak_fraction", total > 0.0 ? leaked / total : 0.0, 4);
          table.end_row();
        }
    }
  }
}

}  // namespace

void add_experiment_caustics_subcommand(CLI::App& experiment, GlobalOptions& global) {
  auto o = std::make_shared<CausticsOptions>();
  auto* cmd = experiment.add_subcommand(
      "caustics",
      "SURVEY §6 caustics: photon_res × {splat, triangles} × {cube, light} storage — ms of the caustic\n"
      "passes, mae8 of the caustic term against the light-traced reference, light leaks.\n"
      "Example: speculum experiment caustics --photon-res 64 --photon-res 256 --json");
  cmd->add_option("--scene", o->scenes, "Scene(s) (repeatable; default: glass-sphere, caustic-ring, water-slab)");
  cmd->add_option("--photon-res", o->photon_res, "Photon image side(s), 16..512 (repeatable; default: 32 64 128 256 512)");
  cmd->add_option("--filter", o->filters,
                  "Caustic-map filter(s) by name as in `--param filter=`: splat, triangles (repeatable; default: both)");
  cmd->add_option("--storage", o->storages,
                  "Caustic-map storage(s) by name as in `--param storage=`: cube, light (repeatable; default: both)");
  cmd->add_option("--width", o->width, "Image width")->check(CLI::Range(8, 2048))->capture_default_str();
  cmd->add_option("--height", o->height, "Image height")->check(CLI::Range(8, 2048))->capture_default_str();
  cmd->add_option("--cube-size", o->cube_size, "Face size of the generators' distance maps")
      ->check(CLI::Range(8, 2048))->capture_default_str();
  cmd->add_option("--caustic-size", o->caustic_size, "Face size of the caustic maps")
      ->check(CLI::Range(16, 1024))->capture_default_str();
  cmd->add_option("--chain", o->chain, "Steps a photon follows past its first generator: internal reflections, other generators (the technique's `chain`)")
      ->check(CLI::Range(0, 16))->capture_default_str();
  cmd->add_option("--reference-photons", o->reference_photons,
                  "Light-traced reference photons per pixel, per light and generator")
      ->check(CLI::Range(1, 1024))->capture_default_str();
  cmd->add_option("--images", o->images,
                  "Write each row's caustic term, the reference's and their 8-bit difference ×8 into this existing directory")
      ->check(CLI::ExistingDirectory);
  cmd->add_flag("--quick", o->quick, "Smoke check: 64x48, photon_res 32 and 64, small scenes, 4 reference photons per pixel");
  cmd->add_flag("--json", o->json, "One JSON object per row instead of the text table");
  cmd->callback([o, &global] { run_caustics(*o, global); });
}

}  // namespace speculum::cli
