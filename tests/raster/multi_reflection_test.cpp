// Tests of the distance-map and multi-reflection techniques as whole frames (SURVEY §4.2–4.3):
// against the reference tracer (error thresholds stated), bounce depth per round, the
// frame-lagged edge equal to in-frame rounds, and thread-count independence.
#include <cstring>
#include <string>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "raster/gbuffer.h"
#include "raster/multi_reflection.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"
#include "tests/raster/frame_test_util.h"

namespace speculum::raster {
namespace {

// sphere-in-room with the gold sphere turned into a second mirror, so each sphere shows the
// other: its reflection in the big sphere needs two bounces.
Scene two_mirror_room() {
  Scene s = load_scene("sphere-in-room:size=4000");
  for (Material& m : s.materials)
    if (m.name == "glossy gold") m.roughness = 0.0f, m.metallic = 1.0f;
  return s;
}

pipeline::FrameSettings small_cube_frame(const Scene& s) {
  pipeline::FrameSettings f;
  f.width = 96;
  f.height = 72;
  f.cube_map_size = 64;
  f.shadow_map_size = 256;
  f.camera = s.cameras.front();
  return f;
}

TEST(MultiReflection, EachRoundAddsABounceAndMovesTowardsTheReference) {
  const Scene s = two_mirror_room();
  pipeline::FrameSettings f = small_cube_frame(s);
  pipeline::FrameSettings ref = f;
  ref.spp = 4;
  const ImageRGBA reference = render_display(s, "reference", ref);
  // The frame around the specular layer (shadow maps, no anti-aliasing at 96×72 against a
  // 4-spp reference) dominates the error; envmap's error on the same frame is the yardstick.
  const double envmap = image_error(render_display(s, "envmap", f), reference).mae8;
  EXPECT_LT(envmap, 30.0);
  double previous = 1e9;
  for (const int rounds : {1, 2, 3}) {
    f.params["rounds"] = rounds;
    const double e = image_error(render_display(s, "multi-reflection", f), reference).mae8;
    // Round 2 adds the sphere-in-sphere reflections (was black); round 3 changes little.
    if (rounds <= 2) {
      EXPECT_LT(e, previous) << "rounds " << rounds;
    } else {
      EXPECT_LE(e, previous + 0.05) << "rounds " << rounds;
    }
    EXPECT_LT(e, envmap) << "mae8 against the reference tracer, rounds " << rounds;
    previous = e;
  }
}

TEST(MultiReflection, OneRoundIsTheDistanceMapTechnique) {
  const Scene s = two_mirror_room();
  const pipeline::FrameSettings f = small_cube_frame(s);
  pipeline::FrameSettings one_round = f;
  one_round.params["rounds"] = 1;
  EXPECT_TRUE(same_bytes(render_display(s, "multi-reflection", one_round), render_display(s, "distance-map", f)));
}

TEST(MultiReflection, LaggedSecondFrameEqualsTwoRounds) {
  const Scene s = two_mirror_room();
  pipeline::FrameSettings f = small_cube_frame(s);
  f.params["lagged"] = 1;
  par::Executor ex(2);
  par::Graph g;
  const pipeline::FrameOutputs out = pipeline::find_technique("multi-reflection").add_passes(g, &s, f);
  g.request(out.display);
  g.run(ex);
  const ImageRGBA first = g.get(out.display);
  g.run(ex);
  const ImageRGBA second = g.get(out.display);
  pipeline::FrameSettings in_frame = small_cube_frame(s);
  in_frame.params["rounds"] = 1;
  EXPECT_TRUE(same_bytes(first, render_display(s, "multi-reflection", in_frame)));
  in_frame.params["rounds"] = 2;
  EXPECT_TRUE(same_bytes(second, render_display(s, "multi-reflection", in_frame)));
  EXPECT_FALSE(same_bytes(first, second));
}

// Rounds after the first start from the faces' direct light and specular texels kept by the
// first (MapFaceLayers) instead of rendering the faces again, and search, composite and
// prefilter only the faces the next round's (or the camera's) searches reach: every such
// face's colour and every distance are the bytes the full re-rendering gives, and so is the
// camera's specular layer, while faces were left out.
TEST(MultiReflection, KeptFaceLayersGiveTheBytesOfReRenderedFaces) {
  const Scene s = load_scene("living-room");  // flat and curved reflectors: some faces unread
  par::Executor ex(2);
  const Camera cam = s.cameras.front();
  const ShadowMaps shadows = render_shadow_maps(ex, s, 128);
  const EnvironmentMap env = build_environment(ex, s.environment);
  const GBuffer g = resolve_gbuffer(ex, s, render_visibility(ex, s, cam, 96, 72), cam.eye);
  const DistanceSearchOptions search;
  DistanceReflectStats kept_stats, fresh_stats;
  const ReflectorMaps kept = render_multi_reflection_maps(ex, s, shadows, env, 32, &g, 3, search, &kept_stats);
  ReflectorMaps fresh = render_reflector_maps(ex, s, shadows, env, 32, &g);
  for (int round = 1; round < 3; ++round)
    fresh = rerender_reflector_maps(ex, s, shadows, env, fresh, search, &fresh_stats);
  ASSERT_EQ(kept.cubes.size(), fresh.cubes.size());
  ASSERT_GE(kept.cubes.size(), 2u);
  int left_out = 0;
  for (std::size_t m = 0; m < kept.cubes.size(); ++m)
    for (int f = 0; f < kCubeFaces; ++f) {
      if ((kept.faces[m] >> f) & 1u) EXPECT_TRUE(same_bytes(kept.cubes[m].colour[f], fresh.cubes[m].colour[f])) << m << " " << f;
      else ++left_out;
      EXPECT_EQ(0, std::memcmp(kept.cubes[m].distance[f].pixels.data(), fresh.cubes[m].distance[f].pixels.data(),
                               fresh.cubes[m].distance[f].pixels.size() * sizeof(float)));
    }
  EXPECT_GT(left_out, 0);
  EXPECT_TRUE(same_bytes(distance_map_reflect(ex, g, env, kept, search), distance_map_reflect(ex, g, env, fresh, search)));
  EXPECT_LT(kept_stats.searches, fresh_stats.searches);
  EXPECT_GT(kept_stats.searches, 0u);
}

TEST(MultiReflection, SameBytesForOneAndTwoThreads) {
  const Scene s = two_mirror_room();
  const pipeline::FrameSettings f = small_cube_frame(s);
  pipeline::FrameSettings two_rounds = f;
  two_rounds.params["rounds"] = 2;
  EXPECT_TRUE(same_bytes(render_display(s, "distance-map", f, 1), render_display(s, "distance-map", f, 2)));
  EXPECT_TRUE(same_bytes(render_display(s, "multi-reflection", two_rounds, 1), render_display(s, "multi-reflection", two_rounds, 2)));
}

// living-room with its base-colour-textured materials given a metallic-roughness texture
// that makes every other texel a mirror: reflectors that only a texture makes specular.
Scene textured_mirror_room() {
  Scene s = load_scene("living-room");
  ImageRGBA mr(2, 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x) mr.at(x, y) = glm::vec4(0.0f, (x + y) % 2 ? 1.0f : 0.01f, 1.0f, 1.0f);
  const int texture = static_cast<int>(s.textures.size());
  s.textures.push_back(mr);
  int textured = 0;
  for (Material& m : s.materials)
    if (m.base_color_texture.valid()) {
      m.metallic_roughness_texture = m.base_color_texture;
      m.metallic_roughness_texture.texture = texture;
      m.metallic = 1.0f;
      ++textured;
    }
  EXPECT_GT(textured, 0);
  return s;
}

// The rounds shaded only where the next round (or the camera) reads them give the camera's
// specular layer the bytes of rounds shaded whole, for one to three rounds, with fewer
// texels shaded and fewer searches made; reflectors made specular by a texture alone too.
TEST(MultiReflection, RoundsShadedWhereReadGiveTheBytesOfWholeRounds) {
  par::Executor ex(2);
  for (const std::string name : {"living-room", "sphere-in-room", "textured mirrors"}) {
    const Scene s = name == "sphere-in-room" ? two_mirror_room() : name == "textured mirrors" ? textured_mirror_room() : load_scene(name);
    const Camera cam = s.cameras.front();
    const ShadowMaps shadows = render_shadow_maps(ex, s, 128);
    const EnvironmentMap env = build_environment(ex, s.environment);
    const GBuffer g = resolve_gbuffer(ex, s, render_visibility(ex, s, cam, 96, 72), cam.eye);
    const DistanceSearchOptions search;
    const ReflectorMaps distances =
        render_reflector_maps(ex, s, shadows, env, 32, &g, ReflectorSelection::all, {}, nullptr, searched_distance_maps(false, false));
    const DistanceSearches camera = distance_map_search(ex, g, distances, search);
    for (int rounds = 1; rounds <= 3; ++rounds) {
      SCOPED_TRACE(name + ", rounds " + std::to_string(rounds));
      DistanceReflectStats whole_stats, read_stats;
      const ReflectorMaps whole = render_multi_reflection_maps(ex, s, shadows, env, 32, &g, rounds, search, &whole_stats);
      const ReflectorMaps where_read =
          render_multi_reflection_maps_where_read(ex, s, shadows, env, distances, camera, rounds, search, &read_stats);
      EXPECT_TRUE(same_bytes(distance_map_reflect(ex, g, env, whole, search),
                             distance_map_lookup(ex, g, env, where_read, camera, search)));
      EXPECT_LT(rendered_texels(where_read), 6.0 * 32 * 32 * double(where_read.cubes.size()));
      if (rounds > 1) {
        EXPECT_LE(read_stats.searches, whole_stats.searches);
      }
    }
  }
}

}  // namespace
}  // namespace speculum::raster
