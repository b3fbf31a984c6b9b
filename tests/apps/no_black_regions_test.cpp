// Every technique renders every built-in scene without black regions the reference lacks:
// a pixel the technique leaves black (all channels below 1/255 after tone mapping, exposure
// 1) must be black in the reference too — at its full specular depth or at one bounce (a
// first-order technique is not asked to show a mirror inside a mirror). At most 0.5 % of the
// pixels may break this, per technique × scene, except the cells listed in kOpenCells.
// Each cell's frame error (mae8 against the same reference) is also held to its bound in
// tests/data/frame_error_bounds.json, set from the output with a small margin: a regression
// in any cell fails, and a bound may only be lowered.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "parallel/executor.h"
#include "raster/composite.h"
#include "trace/reference_tracer.h"

namespace speculum::pipeline {
namespace {

constexpr int kWidth = 96, kHeight = 72;

bool black(const glm::vec4& p) { return p.x < 1.0f / 255.0f && p.y < 1.0f / 255.0f && p.z < 1.0f / 255.0f; }

ImageRGBA reference_display(const Scene& s, int depth, par::Executor& ex) {
  trace::ReferenceOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.spp = 4;
  o.pixel_jitter = false;
  o.max_depth = depth;
  return raster::tonemap(ex, trace::render_reference(s, s.cameras.front(), o, ex), 1.0f);
}

// Cells that still break the rule, bounded at their current count so they cannot get worse
// (a bound may only be lowered): in living-room and bathroom, yu-lod's rays that hit a
// surface in shadow find it black (its hit shading is direct light plus the environment's
// unoccluded irradiance, with no light bounced between surfaces, which the reference has), and
// ray-hierarchy's chrome balls see a few black hits at the table's edge; in water-slab, rays that refract into the closed slab
// reach its floor-side face from inside, where ray-hierarchy's one bounce and the layered
// tracer's layers end (cone-tracing traces refraction as ray-hierarchy's rays, so the same).
struct OpenCell {
  const char* technique;
  const char* scene;
  std::size_t max_black;
};
constexpr OpenCell kOpenCells[] = {{"yu-lod", "living-room", 124},
                                   {"yu-lod", "bathroom", 63},
                                   {"ray-hierarchy", "living-room", 35},
                                   {"ray-hierarchy", "water-slab", 1273},
                                   {"cone-tracing", "water-slab", 1273},
                                   {"layered-distance-map", "water-slab", 608}};

const nlohmann::json& frame_error_bounds() {
  static const nlohmann::json bounds = [] {
    std::ifstream in(SPECULUM_TEST_DATA "/frame_error_bounds.json");
    std::stringstream text;
    text << in.rdbuf();
    return nlohmann::json::parse(text.str());
  }();
  return bounds;
}

class NoBlackRegions : public ::testing::TestWithParam<std::string> {};

TEST_P(NoBlackRegions, EveryTechniqueAgainstTheReference) {
  const Scene s = load_scene(GetParam() + ":size=4000");
  par::Executor ex(2);
  const ImageRGBA full = reference_display(s, 8, ex), first = reference_display(s, 1, ex);
  for (const Technique& t : techniques()) {
    if (t.name == "reference" || t.name == "specular-reference") continue;
    FrameSettings f;
    f.width = kWidth;
    f.height = kHeight;
    f.camera = s.cameras.front();
    f.cube_map_size = 128;
    f.shadow_map_size = 256;
    f = t.with_defaults(f);
    const ImageRGBA img = render_frame(s, t, f, ex).display;
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < img.pixels.size(); ++i)
      if (black(img.pixels[i]) && !black(full.pixels[i]) && !black(first.pixels[i])) ++wrong;
    std::size_t bound = img.pixels.size() / 200;  // 0.5 %
    for (const OpenCell& c : kOpenCells)
      if (t.name == c.technique && GetParam() == c.scene) bound = c.max_black;
    EXPECT_LE(wrong, bound) << t.name << " on " << GetParam() << ": " << wrong << " black pixels the reference lacks";

    const std::string id = t.name + "@" + GetParam();
    const double mae8 = image_error(full, img).mae8;
    const nlohmann::json& bounds = frame_error_bounds();
    if (!bounds.contains(id)) {
      ADD_FAILURE() << "no frame-error bound for " << id << " in tests/data/frame_error_bounds.json: measured "
                    << mae8 << ", suggested \"" << id << "\": " << std::ceil((mae8 * 1.02 + 0.05) * 100.0) / 100.0;
      continue;
    }
    EXPECT_LE(mae8, bounds[id].get<double>()) << id << ": frame mae8 against the reference";
  }
}

INSTANTIATE_TEST_SUITE_P(BuiltinScenes, NoBlackRegions,
                         ::testing::Values("sphere-in-room", "glossy-plane", "mirror-corridor", "living-room",
                                           "glass-sphere", "bowl", "bumpy-sphere", "caustic-ring", "water-slab",
                                           "ellipsoid", "bathroom"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n) if (c == '-') c = '_';
                           return n;
                         });

}  // namespace
}  // namespace speculum::pipeline
