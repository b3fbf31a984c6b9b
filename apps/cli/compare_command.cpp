// `speculum compare A B [--metric M] [--max X] [--diff out.png]`: image error metrics on PNG
// 8-bit values (core/image_metrics.h), a heat-map of the difference, and an exit status for
// golden-image tests: 0 within the bound, 1 outside, 2 bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <glm/vec3.hpp>

#include "apps/cli/commands.h"
#include "apps/cli/json_output.h"
#include "core/error.h"
#include "core/image.h"
#include "core/image_flip.h"
#include "core/image_metrics.h"

namespace speculum::cli {
namespace {

struct CompareOptions {
  std::string a, b;
  std::string metric = "psnr";
  double max = std::nan("");
  std::string diff;
  bool json = false;
  double ppd = 67.0;
};

// Black → red → yellow → white over t in [0, 1] (sRGB values).
glm::vec3 heat(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  return {std::clamp(3.0f * t, 0.0f, 1.0f), std::clamp(3.0f * t - 1.0f, 0.0f, 1.0f),
          std::clamp(3.0f * t - 2.0f, 0.0f, 1.0f)};
}

// Per pixel the largest 8-bit RGB difference, scaled so the image's largest shows white.
ImageRGBA heat_map(const ImageRGBA& a, const ImageRGBA& b, int max8) {
  ImageRGBA out(a.width, a.height);
  const float scale = 1.0f / float(std::max(1, max8));
  for (std::size_t i = 0; i < a.size(); ++i) {
    int d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(display_to_8bit(a.pixels[i][c]) - display_to_8bit(b.pixels[i][c])));
    const glm::vec3 h = heat(float(d) * scale);
    out.pixels[i] = {srgb_to_linear(h.x), srgb_to_linear(h.y), srgb_to_linear(h.z), 1.0f};
  }
  return out;
}

ImageRGBA flip_heat_map(const ImageF& error) {
  ImageRGBA out(error.width, error.height);
  for (std::size_t i = 0; i < error.size(); ++i) {
    const glm::vec3 h = heat(error.pixels[i]);
    out.pixels[i] = {srgb_to_linear(h.x), srgb_to_linear(h.y), srgb_to_linear(h.z), 1.0f};
  }
  return out;
}

void run_compare(const CompareOptions& o, const GlobalOptions& global) {
  if (o.diff.size() < 4 || o.diff.compare(o.diff.size() - 4, 4, ".png") != 0) {
    if (!o.diff.empty()) throw InputError(o.diff, "--diff must end in .png");
  }
  const ImageRGBA a = read_image(o.a);
  const ImageRGBA b = read_image(o.b);
  const ImageError e = image_error(a, b, o.a + " vs " + o.b);
  FlipResult flip;
  if (o.metric == "flip") {
    FlipOptions fo;
    fo.pixels_per_degree = o.ppd;
    flip = flip_error(a, b, fo, o.a + " vs " + o.b);
  }
  const double value = o.metric == "mae8"   ? e.mae8
                       : o.metric == "rmse" ? e.rmse
                       : o.metric == "flip" ? flip.mean
                                            : e.psnr;
  if (o.json) {
    OrderedJson j{{"a", o.a}, {"b", o.b}, {"width", a.width}, {"height", a.height},
                  {"mae8", rounded(e.mae8, 6)}, {"rmse", rounded(e.rmse, 8)}, {"psnr", rounded(e.psnr, 4)},
                  {"max8", static_cast<int>(e.max8)}, {"differing_pixels", e.differing_pixels}};
    if (o.metric == "flip") j["flip"] = rounded(flip.mean, 6);
    std::printf("%s\n", json_line(j).c_str());
  } else
    std::printf("mae8 %.6f\nrmse %.8f\npsnr %.4f\nmax8 %.0f\ndiffering_pixels %zu of %zu\n", e.mae8,
                e.rmse, e.psnr, e.max8, e.differing_pixels, a.size());
  if (o.metric == "flip" && !o.json) std::printf("flip %.6f\nflip_max %.6f\n", flip.mean, flip.max);
  if (!o.diff.empty()) {
    if (o.metric == "flip") {
      write_image(o.diff, flip_heat_map(flip.error));
      if (!global.quiet)
        std::fprintf(stderr, "speculum: diff %s: FLIP error, black 0 .. white 1\n", o.diff.c_str());
    } else {
      write_image(o.diff, heat_map(a, b, static_cast<int>(e.max8)));
    }
    if (!global.quiet && o.metric != "flip")
      std::fprintf(stderr, "speculum: diff %s: black 0 .. white %d (largest 8-bit difference)\n",
                   o.diff.c_str(), std::max(1, static_cast<int>(e.max8)));
  }
  if (std::isnan(o.max)) return;
  const bool within = o.metric == "psnr" ? value >= o.max : value <= o.max;
  if (!within) {
    std::fflush(stdout);
    std::fprintf(stderr, "speculum: compare: %s %.6g is %s the bound %.6g\n", o.metric.c_str(),
                 value, o.metric == "psnr" ? "below" : "above", o.max);
    throw ExitStatus{1};
  }
}

}  // namespace

void add_compare_command(CLI::App& app, GlobalOptions& global) {
  auto opts = std::make_shared<CompareOptions>();
  auto* cmd = app.add_subcommand(
      "compare",
      "Compare two images on their 8-bit PNG values: mae8, rmse, psnr (and LDR-FLIP); exit 0 when --metric is\n"
      "within --max (for psnr: at least --max), 1 when not, 2 on bad input");
  cmd->footer("Example: speculum compare out.png golden.png --metric psnr --max 40 --diff diff.png");
  cmd->add_option("a", opts->a, "First image (PNG, EXR, ...)")->required();
  cmd->add_option("b", opts->b, "Second image, same size")->required();
  cmd->add_option("--metric", opts->metric, "Metric checked against --max: mae8, rmse, psnr or flip (LDR-FLIP mean, 0..1)")
      ->check(CLI::IsMember({"mae8", "rmse", "psnr", "flip"}))
      ->capture_default_str();
  cmd->add_option("--max", opts->max,
                  "Bound on --metric (default: none, always exit 0); psnr passes when >= it");
  cmd->add_option("--diff", opts->diff, "Write a heat-map of the per-pixel difference (.png)");
  cmd->add_option("--ppd", opts->ppd, "FLIP: observer pixels per visual degree")
      ->check(CLI::Range(1.0, 1000.0))->capture_default_str();
  cmd->add_flag("--json", opts->json, "Print the metrics as one JSON object");
  cmd->callback([opts, &global] { run_compare(*opts, global); });
}

}  // namespace speculum::cli
