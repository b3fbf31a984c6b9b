// The fallback counters count exactly the samples that fell back: a sample whose specular
// path a technique stops at depth k is the sample that depth k + 1 follows. Each test checks
// the counter of one depth against the work of the next.
#include <gtest/gtest.h>

#include <string>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/scene_loader.h"
#include "parallel/executor.h"
#include "tests/apps/node_counter.h"

namespace speculum::pipeline {
namespace {

FrameResult render(const Scene& s, const std::string& technique, const std::string& param, int value,
                   int bounces = 0) {
  const Technique& t = find_technique(technique);
  FrameSettings f;
  f.width = 80;
  f.height = 60;
  f.camera = s.cameras.front();
  f.cube_map_size = 64;
  f.shadow_map_size = 128;
  f.bounces = bounces;
  if (!param.empty()) f.params[param] = value;
  f = t.with_defaults(f);
  par::Executor ex(2);
  return render_frame(s, t, f, ex);
}

// Planar mirrors: the mirror samples of the depth-k views (environment lookups) are those
// that depth k + 1 composites a mirrored view into, beyond the ones depth k already did.
TEST(FallbackCounters, PlanarMirrorDepthExhaustedIsWhatTheNextDepthRenders) {
  const Scene s = load_scene("mirror-corridor:size=3000");
  for (int k = 0; k <= 2; ++k) {
    SCOPED_TRACE(k);
    const FrameResult at = render(s, "planar-mirror", "depth", k), next = render(s, "planar-mirror", "depth", k + 1);
    const double exhausted = node_counter(at, "planar_mirror_views", "fallback_depth_exhausted");
    EXPECT_GT(exhausted, 0.0);  // the corridor's mirrors face each other: every depth stops somewhere
    EXPECT_EQ(exhausted, node_counter(next, "planar_mirror_views", "mirror_samples") -
                             node_counter(at, "planar_mirror_views", "mirror_samples"));
  }
}

// Ray hierarchy: the specular hits of the last generation are the rays of the next one.
TEST(FallbackCounters, RayHierarchyDepthExhaustedIsTheNextGeneration) {
  const Scene s = load_scene("mirror-corridor:size=3000");
  for (int b = 1; b <= 2; ++b) {
    SCOPED_TRACE(b);
    const FrameResult at = render(s, "ray-hierarchy", "", 0, b), next = render(s, "ray-hierarchy", "", 0, b + 1);
    const std::string last = b == 1 ? "shade_hits" : "shade_hits_" + std::to_string(b);
    const double exhausted = node_counter(at, last, "fallback_depth_exhausted");
    EXPECT_GT(exhausted, 0.0);  // mirrors facing each other: every generation meets a mirror
    EXPECT_EQ(exhausted, node_counter(next, "bounce_rays_" + std::to_string(b + 1), "rays"));
  }
}

// Cone tracing: a concave mirror bowl seen from beyond its focus reflects converging cones
// (double cones), traced as rays and counted; a convex mirror never does. At footprint 1 every
// specular pixel is a cone, a double-cone fallback or a refracted ray; hits beyond `kept` are
// counted.
TEST(FallbackCounters, ConeTracingDoubleConesOnTheBowlOnly) {
  const Scene bowl = load_scene("bowl:size=3000"), room = load_scene("sphere-in-room:size=3000");
  const FrameResult b = render(bowl, "cone-tracing", "", 0), r = render(room, "cone-tracing", "", 0);
  EXPECT_GT(node_counter(b, "pixel_cones", "fallback_double_cone"), 100.0);
  EXPECT_EQ(node_counter(r, "pixel_cones", "fallback_double_cone"), 0.0);
  for (const FrameResult* f : {&b, &r})
    EXPECT_EQ(node_counter(*f, "pixel_cones", "rays"),
              node_counter(*f, "pixel_cones", "cones") + node_counter(*f, "pixel_cones", "fallback_double_cone") +
                  node_counter(*f, "pixel_cones", "refraction_rays"));
  const FrameResult few = render(room, "cone-tracing", "kept", 1);
  EXPECT_GT(node_counter(few, "cone_triangle_coverage", "kept_overflow"), 0.0);
  EXPECT_EQ(node_counter(few, "cone_triangle_coverage", "max_kept"), 1.0);
}

// Layered distance map: each specular hit past the last bounce is one more search at the
// next bounce count.
TEST(FallbackCounters, LayeredDepthExhaustedIsTheNextBouncesSearches) {
  const Scene s = load_scene("mirror-corridor:size=3000");
  for (int b = 1; b <= 2; ++b) {
    SCOPED_TRACE(b);
    const FrameResult at = render(s, "layered-distance-map", "bounces", b),
                      next = render(s, "layered-distance-map", "bounces", b + 1);
    const double exhausted = node_counter(at, "layered_reflect", "fallback_depth_exhausted");
    EXPECT_GT(exhausted, 0.0);
    EXPECT_EQ(exhausted, node_counter(next, "layered_reflect", "searches") - node_counter(at, "layered_reflect", "searches"));
  }
}

}  // namespace
}  // namespace speculum::pipeline
