// How inspect draws captured outputs (apps/inspect/inspect_images.h): id colours, the cube cross,
// one view per G-buffer field with the buffer's size, and unknown types not drawable.
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "apps/inspect/inspect_images.h"
#include "captured_output.h"
#include "apps/techniques/frame_settings.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"

namespace speculum::inspect {
namespace {

TEST(InspectImages, IdColoursAreStableDistinctAndNeverBlack) {
  EXPECT_EQ(id_colour(kNoId), glm::vec3(0.0f));
  std::set<std::tuple<float, float, float>> seen;
  for (std::uint32_t id = 0; id < 256; ++id) {
    const glm::vec3 c = id_colour(id);
    EXPECT_EQ(c, id_colour(id));
    EXPECT_GE(std::min({c.x, c.y, c.z}), 0.25f);
    seen.insert({c.x, c.y, c.z});
  }
  EXPECT_GE(seen.size(), 250u);  // a hash, so a rare collision is allowed
}

TEST(InspectImages, CubeCrossPutsEachFaceInItsCell) {
  std::array<ImageRGBA, 6> faces;
  for (int f = 0; f < 6; ++f) faces[f] = ImageRGBA(3, 2, glm::vec4(float(f + 1), 0, 0, 1));
  const ImageRGBA cross = cube_cross(faces);
  ASSERT_EQ(cross.width, 12);
  ASSERT_EQ(cross.height, 6);
  // (column, row) of +X −X +Y −Y +Z −Z.
  const int cell[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
  int covered = 0;
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 12; ++x) {
      const float v = cross.at(x, y).x;
      int expected = 0;
      for (int f = 0; f < 6; ++f)
        if (x / 3 == cell[f][0] && y / 2 == cell[f][1]) expected = f + 1;
      EXPECT_EQ(v, float(expected)) << x << "," << y;
      covered += v > 0;
    }
  EXPECT_EQ(covered, 6 * 6);
}

TEST(InspectImages, GBufferGivesOneViewPerFieldAtItsSize) {
  raster::GBuffer g;
  g.width = 5, g.height = 4;
  g.object = IdBuffer(5, 4, kNoId);
  g.object.at(1, 1) = 3;
  g.position = Buffer2D<glm::vec3>(5, 4, glm::vec3(1, 2, 3));
  g.normal = Buffer2D<glm::vec3>(5, 4, glm::vec3(0, 0, 1));
  g.uv = Buffer2D<glm::vec2>(5, 4);
  g.surface = SurfacePlane::uniform(5, 4, SurfaceParams{});
  g.reflector = IdBuffer(5, 4, kNoId);
  par::Executor ex(1);
  const Drawing d = draw_output(capture(g), ex);
  ASSERT_TRUE(d.drawable);
  EXPECT_EQ(d.size, "5x4");
  std::set<std::string> labels;
  for (const View& v : d.views) {
    labels.insert(v.label);
    EXPECT_EQ(v.picture.width, 5);
    EXPECT_EQ(v.picture.height, 4);
    EXPECT_TRUE(!v.raw_rgba.empty() || !v.raw_scalar.empty()) << v.label;
  }
  for (const char* field : {"object", "position", "normal", "uv", "base_color", "roughness",
                            "specular_level", "glossiness", "reflector"})
    EXPECT_TRUE(labels.count(field)) << field;
  // The normal (0,0,1) of the one covered sample is drawn as (0.5, 0.5, 1) in sRGB; the
  // background stays black.
  for (const View& v : d.views)
    if (v.label == "normal") {
      EXPECT_NEAR(linear_to_srgb(v.picture.at(1, 1).x), 0.5f, 1e-3f);
      EXPECT_NEAR(linear_to_srgb(v.picture.at(1, 1).z), 1.0f, 1e-3f);
      EXPECT_EQ(v.picture.at(0, 0).z, 0.0f);
    }
}

// A cube that leaves faces unrendered (a spot light's shadow cube, a reflector map read on
// some faces only) names them in its caption; a whole cube says nothing of the kind.
TEST(InspectImages, CubeCaptionsNameTheFacesNotRendered) {
  std::vector<raster::ShadowMap> shadows(2);
  for (raster::ShadowMap& m : shadows)
    for (ImageF& f : m.cube.distance) f = ImageF(2, 2, 1.0f);
  shadows[0].type = LightType::Spot;
  shadows[0].faces = 0b010101u;  // +X, +Y, +Z
  par::Executor ex(1);
  const Drawing d = draw_output(capture(shadows), ex);
  ASSERT_EQ(d.views.size(), 2u);
  EXPECT_NE(d.views[0].encoding.find("faces -X, -Y, -Z not rendered"), std::string::npos) << d.views[0].encoding;
  EXPECT_EQ(d.views[1].encoding.find("not rendered"), std::string::npos) << d.views[1].encoding;

  raster::ReflectorMaps maps;
  maps.cubes.resize(1);
  for (ImageF& f : maps.cubes[0].distance) f = ImageF(2, 2, 1.0f);
  maps.faces = {0b111110u};
  const Drawing m = draw_output(capture(maps), ex);
  ASSERT_EQ(m.views.size(), 1u);
  EXPECT_NE(m.views[0].encoding.find("faces +X not rendered"), std::string::npos) << m.views[0].encoding;
}

TEST(InspectImages, ScalarRampSpansTheFiniteValues) {
  ImageF f(3, 1);
  f.pixels = {2.0f, 6.0f, std::numeric_limits<float>::infinity()};
  par::Executor ex(1);
  const Drawing d = draw_output(capture(f), ex);
  ASSERT_EQ(d.views.size(), 1u);
  const ImageRGBA& p = d.views[0].picture;
  EXPECT_EQ(p.at(0, 0).x, 0.0f);            // min → black
  EXPECT_NEAR(p.at(1, 0).x, 1.0f, 1e-6f);   // max → white
  EXPECT_LT(p.at(2, 0).x, p.at(2, 0).z);    // inf → the "no value" blue
  EXPECT_EQ(d.views[0].raw_scalar.pixels, f.pixels);
}

TEST(InspectImages, UnknownTypesAreNotDrawable) {
  struct Opaque {
    int x = 1;
  } value;
  par::Executor ex(1);
  const Drawing d = draw_output(capture(value), ex);
  EXPECT_FALSE(d.drawable);
  EXPECT_TRUE(d.views.empty());
}

TEST(InspectImages, DisplayImageIsShownUnchangedAndRadianceToneMapped) {
  ImageRGBA img(2, 1, glm::vec4(4.0f, 0.5f, 0.0f, 1.0f));
  par::Executor ex(1);
  const Drawing shown = draw_output(capture(img, pipeline::kDisplay), ex);
  ASSERT_EQ(shown.views.size(), 1u);
  EXPECT_EQ(shown.views[0].picture.pixels, img.pixels);
  const Drawing mapped = draw_output(capture(img, "direct"), ex);
  ASSERT_EQ(mapped.views.size(), 1u);
  EXPECT_LE(mapped.views[0].picture.at(0, 0).x, 1.0f);  // tone-mapped into [0, 1]
  EXPECT_EQ(mapped.views[0].raw_rgba.pixels, img.pixels);  // EXR keeps the radiance
}

}  // namespace
}  // namespace speculum::inspect
