// How inspect draws the trace-side outputs (apps/inspect/inspect_trace_images.h): rays on their
// pixels with d*0.5+0.5 colours and an active mask, hits on the grid of the rays drawn before
// them (none: not drawable), hierarchy levels' α and r, YU's Ω_s and hit/proxy fractions.
#include <map>
#include <gtest/gtest.h>

#include "apps/inspect/inspect_trace_images.h"
#include "captured_output.h"
#include "core/shading.h"
#include "trace/glossy_rays.h"
#include "trace/lod_trace.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"

namespace speculum::inspect {
namespace {

std::map<std::string, View> by_label(const Drawing& d) {
  std::map<std::string, View> m;
  for (const View& v : d.views) m[v.label] = v;
  return m;
}

float srgb(float linear) { return linear_to_srgb(linear); }

// 3 x 2 grid, rays at pixels 1 (direction +x) and 4 (direction -z, not unit).
trace::SecondaryRays two_rays() {
  trace::SecondaryRays r;
  r.width = 3, r.height = 2;
  r.rays.resize(6);
  r.active.assign(6, 0);
  r.weight.assign(6, glm::vec3(0.0f));
  r.rays.set(1, Ray{glm::vec3(0.0f), glm::vec3(1, 0, 0)});
  r.rays.set(4, Ray{glm::vec3(0.0f), glm::vec3(0, 0, -2)});
  r.active[1] = r.active[4] = 1;
  r.weight[1] = glm::vec3(0.5f), r.weight[4] = glm::vec3(1.0f);
  r.count = 2;
  return r;
}

TEST(InspectTraceImages, SecondaryRaysDrawDirectionsOnTheirPixels) {
  forget_ray_grids();
  const trace::SecondaryRays r = two_rays();
  par::Executor ex(1);
  const Drawing d = draw_output(capture(r, "rays_1"), ex);
  ASSERT_TRUE(d.drawable);
  EXPECT_EQ(d.size, "3x2, 2 active");
  auto v = by_label(d);
  ASSERT_TRUE(v.count("direction") && v.count("active") && v.count("weight"));
  const ImageRGBA& dir = v["direction"].picture;
  EXPECT_NEAR(srgb(dir.at(1, 0).x), 1.0f, 1e-3f);  // +x → (1, 0.5, 0.5)
  EXPECT_NEAR(srgb(dir.at(1, 0).y), 0.5f, 1e-3f);
  EXPECT_NEAR(srgb(dir.at(1, 1).z), 0.0f, 1e-3f);  // -z normalised → (0.5, 0.5, 0)
  EXPECT_NEAR(srgb(dir.at(1, 1).x), 0.5f, 1e-3f);
  EXPECT_EQ(dir.at(0, 0), glm::vec4(0, 0, 0, 1));  // no ray: black
  EXPECT_EQ(v["direction"].raw_rgba.at(1, 1).z, -2.0f);  // EXR keeps the raw vector
  EXPECT_EQ(v["active"].raw_scalar.pixels, (std::vector<float>{0, 1, 0, 0, 1, 0}));
}

TEST(InspectTraceImages, HitsUseTheGridOfTheirRaysAndAreNotDrawableWithout) {
  forget_ray_grids();
  trace::HitStream hits;
  hits.resize(6);
  for (std::size_t i = 0; i < 6; ++i) hits.triangle[i] = trace::kNoHit, hits.t[i] = 0.0f;
  hits.triangle[4] = 7, hits.t[4] = 2.5f;
  hits.triangle[1] = 3, hits.t[1] = 1.0f;
  par::Executor ex(1);
  EXPECT_FALSE(draw_output(capture(hits, "hits_1"), ex).drawable);  // no grid known yet

  const trace::SecondaryRays r = two_rays();
  draw_output(capture(r, "rays_1"), ex);
  const Drawing d = draw_output(capture(hits, "hits_1"), ex);
  ASSERT_TRUE(d.drawable);
  EXPECT_EQ(d.size, "3x2, 2 hits");
  auto v = by_label(d);
  ASSERT_TRUE(v.count("t") && v.count("triangle"));
  EXPECT_EQ(v["t"].raw_scalar.at(1, 1), 2.5f);
  EXPECT_EQ(v["t"].raw_scalar.at(1, 0), 1.0f);
  EXPECT_NEAR(v["t"].picture.at(1, 1).x, 1.0f, 1e-6f);  // farthest hit → white
  EXPECT_EQ(v["t"].picture.at(1, 0).x, 0.0f);           // nearest → black
  const glm::vec3 c = id_colour(7);
  EXPECT_NEAR(srgb(v["triangle"].picture.at(1, 1).y), c.y, 1e-3f);
  EXPECT_EQ(v["triangle"].raw_scalar.at(0, 0), -1.0f);  // no hit

  // Shadow hits: one stream per light on the same grid; a hit is an occluded pixel.
  std::vector<trace::HitStream> shadow{hits};
  const Drawing s = draw_output(capture(shadow, "shadow_hits_1"), ex);
  ASSERT_TRUE(s.drawable);
  ASSERT_EQ(s.views.size(), 1u);
  EXPECT_EQ(s.views[0].label, "light0");
  EXPECT_EQ(s.views[0].raw_scalar.pixels, (std::vector<float>{0, 1, 0, 0, 1, 0}));
}

TEST(InspectTraceImages, HierarchyLevelsShowConeAngleAndRadius) {
  par::Executor ex(1);
  trace::RayStream rays;
  rays.resize(16);
  std::vector<std::uint8_t> active(16, 1);
  for (std::size_t i = 0; i < 16; ++i)
    rays.set(i, Ray{glm::vec3(float(i % 4), float(i / 4), 0.0f), glm::vec3(float(i % 4) * 0.1f, 0.0f, -1.0f)});
  const trace::RayHierarchy h = trace::build_ray_hierarchy(ex, rays, active, 4, 4);
  ASSERT_EQ(h.levels, 2);
  const Drawing d = draw_output(capture(h, "hierarchy_1"), ex);
  ASSERT_TRUE(d.drawable);
  auto v = by_label(d);
  for (const char* l : {"level1.alpha", "level1.radius", "level0.alpha", "level0.radius"})
    ASSERT_TRUE(v.count(l)) << l;
  EXPECT_EQ(v["level1.alpha"].raw_scalar.width, 2);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(v["level1.alpha"].raw_scalar.pixels[i], h.nodes[1][i].alpha);
    EXPECT_EQ(v["level1.radius"].raw_scalar.pixels[i], h.nodes[1][i].r);
  }
  EXPECT_EQ(v["level0.alpha"].raw_scalar.pixels[0], h.nodes[0][0].alpha);
}

TEST(InspectTraceImages, GlossyRaysAndLodHitsPerPixel) {
  forget_ray_grids();
  trace::GlossyRays g;
  g.width = 2, g.height = 1, g.rays_per_pixel = 2;
  g.pixel = {1};
  g.weight = {glm::vec3(0.04f), glm::vec3(0.0f)};
  g.rays.resize(2);
  g.rays.set(0, Ray{glm::vec3(0.0f), glm::vec3(0, 1, 0), 0.0f, 10.0f});
  g.rays.set(1, Ray{glm::vec3(0.0f), glm::vec3(1, 0, 0), 1.0f, 0.0f});  // below the horizon
  g.solid_angle = {0.5f, 0.0f};
  par::Executor ex(1);
  const Drawing d = draw_output(capture(g, "glossy_rays"), ex);
  ASSERT_TRUE(d.drawable);
  auto v = by_label(d);
  ASSERT_TRUE(v.count("solid_angle") && v.count("direction") && v.count("active_fraction"));
  EXPECT_EQ(v["solid_angle"].raw_scalar.at(1, 0), 0.5f);  // the inactive ray is left out
  EXPECT_EQ(v["active_fraction"].raw_scalar.at(1, 0), 0.5f);
  EXPECT_NEAR(srgb(v["direction"].picture.at(1, 0).y), 1.0f, 1e-3f);
  EXPECT_EQ(v["solid_angle"].picture.at(0, 0), glm::vec4(0, 0, 0, 1));  // not glossy

  std::vector<trace::LodHit> hits(2);
  hits[0].t = 3.0f, hits[0].proxy = 5;  // a proxy hit; ray 1 misses
  const Drawing l = draw_output(capture(hits, "glossy_hits"), ex);
  ASSERT_TRUE(l.drawable);
  auto lv = by_label(l);
  ASSERT_TRUE(lv.count("hit_fraction") && lv.count("proxy_fraction") && lv.count("t"));
  EXPECT_EQ(lv["hit_fraction"].raw_scalar.at(1, 0), 0.5f);
  EXPECT_EQ(lv["proxy_fraction"].raw_scalar.at(1, 0), 0.5f);
  EXPECT_EQ(lv["hit_fraction"].raw_scalar.at(0, 0), 0.0f);
  EXPECT_EQ(lv["t"].raw_scalar.at(1, 0), 3.0f);
}

}  // namespace
}  // namespace speculum::inspect
