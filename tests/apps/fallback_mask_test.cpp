// The fallback mask a pass publishes while `inspect` captures the frame marks exactly the
// samples its fallback_* counters count (where a sample takes one ray), marks only samples
// that fell back, and capturing it leaves the image unchanged.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/fallback_mask.h"
#include "core/scene_loader.h"
#include "parallel/executor.h"
#include "tests/apps/node_counter.h"

namespace speculum::pipeline {
namespace {

struct Captured {
  FrameResult frame;
  std::map<std::string, FallbackMask> masks;  // by node
};

Captured render(const Scene& s, const std::string& technique, int bounces, bool capture) {
  const Technique& t = find_technique(technique);
  FrameSettings f;
  f.width = 80;
  f.height = 60;
  f.camera = s.cameras.front();
  f.cube_map_size = 64;
  f.shadow_map_size = 128;
  f.bounces = bounces;
  f = t.with_defaults(f);
  par::Executor ex(2);
  Captured c;
  par::CaptureHook hook;
  if (capture)
    hook = [&](const par::CapturedOutput& o) {
      if (const auto* m = o.as<FallbackMask>()) {
        EXPECT_EQ(o.port, "fallback");
        EXPECT_TRUE(o.resource.empty());  // published, not a graph resource
        c.masks[o.node] = *m;
      }
    };
  c.frame = render_frame(s, t, f, ex, hook);
  return c;
}

const FallbackMask& mask(const Captured& c, const std::string& node) {
  static const FallbackMask none;
  const auto it = c.masks.find(node);
  if (it == c.masks.end()) ADD_FAILURE() << "node " << node << " published no fallback mask";
  return it == c.masks.end() ? none : it->second;
}

void expect_same_image(const Captured& a, const Captured& b) {
  ASSERT_EQ(a.frame.display.pixels.size(), b.frame.display.pixels.size());
  for (std::size_t i = 0; i < a.frame.display.pixels.size(); ++i)
    ASSERT_EQ(a.frame.display.pixels[i], b.frame.display.pixels[i]) << "pixel " << i;
}

// One ray per pixel: the last generation's exhausted samples are the marked pixels.
TEST(FallbackMask, RayHierarchyMarksEveryExhaustedSample) {
  const Scene s = load_scene("water-slab:size=3000");
  const Captured c = render(s, "ray-hierarchy", 1, true);
  const FallbackMask& m = mask(c, "shade_hits");
  const double exhausted = node_counter(c.frame, "shade_hits", "fallback_depth_exhausted");
  EXPECT_GT(exhausted, 0.0);  // glass at one bounce always continues
  EXPECT_EQ(double(m.count(Fallback::depth_exhausted)), exhausted);
  EXPECT_EQ(m.count(Fallback::depth_exhausted), m.reason.size() - m.count(Fallback::none));
  expect_same_image(c, render(s, "ray-hierarchy", 1, false));
}

// yu-lod does not trace refractors: every refractor sample is marked.
TEST(FallbackMask, YuLodMarksEveryRefractorSample) {
  const Scene s = load_scene("glass-sphere:size=3000");
  const Captured c = render(s, "yu-lod", 0, true);
  const FallbackMask& m = mask(c, "refractor_environment");
  const double refractors = node_counter(c.frame, "refractor_environment", "fallback_refractor_environment");
  EXPECT_GT(refractors, 0.0);
  EXPECT_EQ(double(m.count(Fallback::refractor_environment)), refractors);
  expect_same_image(c, render(s, "yu-lod", 0, false));
}

// A layered sample may spend several continuations: its pixel is marked once, so the marked
// pixels are at least one and at most the counted continuations.
TEST(FallbackMask, LayeredMarksTheSamplesWhosePathsFellBack) {
  const Scene s = load_scene("water-slab:size=3000");
  const Captured c = render(s, "layered-distance-map", 0, true);
  const FallbackMask& m = mask(c, "layered_reflect");
  const double exhausted = node_counter(c.frame, "layered_reflect", "fallback_depth_exhausted");
  const double missed = node_counter(c.frame, "layered_reflect", "fallback_search_missed");
  const std::size_t marked = m.reason.size() - m.count(Fallback::none);
  EXPECT_GT(marked, 0u);
  EXPECT_LE(double(marked), exhausted + missed);
  EXPECT_EQ(m.count(Fallback::search_missed) > 0, missed > 0.0);
  expect_same_image(c, render(s, "layered-distance-map", 0, false));
}

}  // namespace
}  // namespace speculum::pipeline
