// The reflector maps a frame reads only from the camera (raster/reflector_maps.h MapSizing):
// leaving out the faces no read comes near changes no output byte of the reads it was
// derived for (distance-map searches, envmap lookups, mirror and glossy lobes); reflectors
// the camera does not see get no map; footprint sizes are powers of two under the cap that
// grow with the reflector's size on screen.
#include "raster/reflector_maps.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/sampling.h"
#include "core/scene_loader.h"
#include "raster/distance_map_reflect.h"
#include "raster/envmap_reflect.h"
#include "tests/raster/frame_test_util.h"

namespace speculum::raster {
namespace {

struct View {
  Scene scene;
  ShadowMaps shadows;
  EnvironmentMap env;
  GBuffer g;
};

View view_of(const std::string& name, int width, int height, par::Executor& ex) {
  View v;
  v.scene = load_scene(name);
  const Camera cam = v.scene.cameras.front();
  v.shadows = render_shadow_maps(ex, v.scene, 128);
  v.env = build_environment(ex, v.scene.environment);
  v.g = resolve_gbuffer(ex, v.scene, render_visibility(ex, v.scene, cam, width, height), cam.eye);
  return v;
}

int culled_faces(const ReflectorMaps& maps) {
  int culled = 0;
  for (const unsigned f : maps.faces) culled += kCubeFaces - std::popcount(f);
  return culled;
}

// Built-in scenes with mirrors and glossy reflectors: the specular layer from maps with only
// the read faces equals the one from complete maps, byte for byte, while faces were indeed
// left out (searches reach further than lookups along R, so they keep more).
TEST(ReflectorMaps, UnreadFacesChangeNoSearchedOrLookedUpSample) {
  par::Executor ex(2);
  int culled_searched = 0, culled_looked_up = 0;
  for (const char* name : {"sphere-in-room", "glossy-plane", "living-room"}) {
    SCOPED_TRACE(name);
    const View v = view_of(name, 96, 72, ex);
    const int size = 64;
    const ReflectorMaps all = render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g);
    DistanceSearchOptions search;
    MapSizing searched;
    searched.reads = MapSizing::Reads::search;
    searched.lobe_directions = search.lobe_directions;
    const ReflectorMaps culled =
        render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g, ReflectorSelection::all, {}, nullptr, searched);
    ASSERT_EQ(all.cubes.size(), culled.cubes.size());
    culled_searched += culled_faces(culled);
    EXPECT_EQ(rendered_texels(culled) < rendered_texels(all), culled_faces(culled) > 0);
    EXPECT_TRUE(same_bytes(distance_map_reflect(ex, v.g, v.env, all, search),
                           distance_map_reflect(ex, v.g, v.env, culled, search)));
    MapSizing looked_up;
    looked_up.reads = MapSizing::Reads::direction;
    const ReflectorMaps by_direction =
        render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g, ReflectorSelection::all, {}, nullptr, looked_up);
    culled_looked_up += culled_faces(by_direction);
    EXPECT_TRUE(same_bytes(envmap_reflect(ex, v.g, v.env, &all), envmap_reflect(ex, v.g, v.env, &by_direction)));
  }
  // The mirror ball reads every face; the floors and the wall mirror do not.
  EXPECT_GT(culled_searched, 0);
  EXPECT_GT(culled_looked_up, culled_searched);
}

// Unit directions at face centres, edges, corners and `random` more spread over the sphere.
std::vector<glm::vec3> test_directions(std::uint32_t random) {
  std::vector<glm::vec3> directions = {{1, 0, 0}, {0, -1, 0}, {1, 1, 0}, {1, 1, 1}, {-1, 0.999f, 0.2f}, {0.3f, -0.2f, -1}};
  for (std::uint32_t k = 0; k < random; ++k) {
    const glm::vec2 u = hamersley(k, random);
    directions.push_back(spherical_local(1.0f - 2.0f * u.x, u.y));
  }
  for (glm::vec3& d : directions) d = glm::normalize(d);
  return directions;
}

// The texels of a map of side `size` (every face, levels [0, levels)) whose centre is within
// `angle` of one of `reads` but that `mask` does not cover; the first one described in `first`.
long long uncovered_texels(const CubeTileMask& mask, int size, int levels, const std::vector<glm::vec3>& reads, float angle,
                           std::string& first) {
  long long uncovered = 0;
  for (int level = 0; level < levels; ++level) {
    const int s = size >> level;
    for (int face = 0; face < kCubeFaces; ++face)
      for (int y = 0; y < s; ++y)
        for (int x = 0; x < s; ++x) {
          const glm::vec3 t = cube_direction(face, {x + 0.5f, y + 0.5f}, s);
          bool within = false;
          for (const glm::vec3& d : reads) within = within || std::acos(std::clamp(glm::dot(t, d), -1.0f, 1.0f)) <= angle;
          if (!within || mask.covers(face, level, x, y)) continue;
          if (uncovered++ == 0)
            first = "level " + std::to_string(level) + " face " + std::to_string(face) + " texel " + std::to_string(x) +
                    "," + std::to_string(y);
        }
  }
  return uncovered;
}

// The tile bound (mark_tiles_near): every texel centre within the margin of a direction, on
// every face and at every mip level, lies over a marked tile — brute force over all texels of
// maps of side 32 and 64, for directions at face centres, edges, corners and at random —
// while small margins mark only a small part of the map.
TEST(ReflectorMaps, MarkedTilesHoldEveryTexelWithinTheMargin) {
  const std::vector<glm::vec3> directions = test_directions(40);
  for (const auto& [size, tile] : {std::pair{32, 8}, std::pair{64, 8}, std::pair{32, 1}, std::pair{64, 2}}) {
    long long marked_small = 0, total_small = 0;
    for (const glm::vec3& d : directions) {
      for (const float margin : {0.001f, 0.02f, 0.1f, 0.3f, 0.49f, 0.6f}) {
        CubeTileMask mask;
        mask.size = size;
        mask.tile = tile;
        mark_tiles_near(mask, d, margin);
        std::string first;
        EXPECT_EQ(uncovered_texels(mask, size, static_cast<int>(std::log2(float(size))) + 1, {d}, margin, first), 0)
            << "size " << size << " tile " << tile << " margin " << margin << " d " << d.x << "," << d.y << "," << d.z
            << ": " << first;
        if (margin <= 0.02f) {
          marked_small += static_cast<long long>(mask.texel_count(0x3fu));
          total_small += 6LL * size * size;
        }
      }
    }
    EXPECT_LT(marked_small * 10, total_small) << size;  // a narrow read marks under a tenth
  }
}

// Reads whose reach is too wide for the face-plane bound (LookupTileMarker records them per
// coarse cell; settle_wide_reads turns the cells into tiles): every texel centre within the
// reach of a read direction, at every level, lies over a marked tile — brute force over maps
// of side 64 and 128, one direction a mask and all of them in one mask from two markers —
// while lone reads under a radian mark fewer tiles than the whole faces they come near.
TEST(ReflectorMaps, WideReadsMarkEveryTexelWithinTheirReach) {
  const std::vector<glm::vec3> directions = test_directions(24);
  par::Executor ex(2);
  for (const int size : {64, 128}) {
    const int levels = static_cast<int>(std::log2(float(size))) + 1;
    for (const float exponent : {40.0f, 262.0f}) {
      const float reach = lookup_reach(size, levels, exponent);
      ASSERT_GE(reach, 0.5f) << "a wide read";
      const auto check = [&](const CubeTileMask& mask, const std::vector<glm::vec3>& read) {
        std::string first;
        EXPECT_EQ(uncovered_texels(mask, size, levels, read, reach, first), 0)
            << "size " << size << " exponent " << exponent << ": " << first;
      };
      long long marked = 0, whole = 0;
      for (const glm::vec3& d : directions) {
        CubeTileMask mask = tile_mask_for_reads(size, levels);
        LookupTileMarker marker(mask, levels);
        marker.mark(d * 3.0f, exponent);  // any length
        settle_wide_reads(ex, mask);
        check(mask, {d});
        marked += static_cast<long long>(mask.texel_count(0x3fu));
        whole += static_cast<long long>(std::popcount(cube_faces_near(d, reach))) * size * size;
      }
      if (reach < 1.0f) {
        EXPECT_LT(marked * 10, whole * 9) << size << " " << exponent;
      }
      CubeTileMask all = tile_mask_for_reads(size, levels);
      LookupTileMarker first(all, levels), second(all, levels);
      for (std::size_t k = 0; k < directions.size(); ++k) (k % 2 ? first : second).mark(directions[k], exponent);
      settle_wide_reads(ex, all);
      check(all, directions);
    }
  }
}

// Lookups along R read only the tiles near their directions: maps rendered on those tiles
// alone give the same specular layer, byte for byte, as complete maps, and fewer texels; with
// refractors_read_at_surface, a refractor's map too.
TEST(ReflectorMaps, UnreadTilesChangeNoLookedUpSample) {
  par::Executor ex(2);
  for (const char* name : {"living-room", "glossy-plane", "glass-sphere"})
  for (const bool at_surface : {false, true}) {
    SCOPED_TRACE(std::string(name) + (at_surface ? ", refractors read at the surface" : ""));
    const View v = view_of(name, 128, 96, ex);
    for (const int size : {64, 128}) {
      const ReflectorMaps all = render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g);
      MapSizing looked_up;
      looked_up.reads = MapSizing::Reads::direction;
      looked_up.refractors_read_at_surface = at_surface;
      const ReflectorMaps tiled =
          render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g, ReflectorSelection::all, {}, nullptr, looked_up);
      ASSERT_EQ(tiled.tiles.size(), tiled.cubes.size());
      double whole_faces = 0.0;
      for (std::size_t m = 0; m < tiled.cubes.size(); ++m) {
        EXPECT_TRUE(tiled.tiles[m].active());
        whole_faces += double(std::popcount(tiled.faces[m])) * size * size;
      }
      if (std::string(name) == "living-room") {
        EXPECT_LT(rendered_texels(tiled), 0.9 * whole_faces);
        // Its mirrors' maps are read at level 0 alone, so at single texels: the chrome ball
        // and the bowl reflect nearly every direction, yet keep under half their texels (the
        // glass ball's map, also read at level 0, keeps all: refracted reads go anywhere).
        int sparse_texel_maps = 0;
        for (std::size_t m = 0; m < tiled.cubes.size(); ++m)
          sparse_texel_maps += tiled.tiles[m].tile == 1 &&
                               tiled.tiles[m].texel_count(tiled.faces[m]) < 0.5 * std::popcount(tiled.faces[m]) * size * size;
        EXPECT_GE(sparse_texel_maps, 2);
      }
      if (std::string(name) == "glass-sphere") {
        EXPECT_GT(rendered_texels(tiled), 0.0);
        // Its glass ball's map (read at level 0 alone) keeps all its texels unless only the
        // lookups at its surface read it.
        EXPECT_EQ(rendered_texels(tiled) < 0.5 * whole_faces, at_surface);
      }
      EXPECT_TRUE(same_bytes(envmap_reflect(ex, v.g, v.env, &all), envmap_reflect(ex, v.g, v.env, &tiled)));
    }
  }
}

// Searches read colour only where they end: the maps' distances first (visibility kept, no
// colour), then colour shaded and prefiltered on the tiles the searches read, give the same
// specular layer, byte for byte, as one pass over complete maps — with fewer texels shaded
// where mirrors read their maps at single texels. Mirrors, glossy lobes (sub-lobe searches at
// coarse levels) and refractors (searches along T) all take part.
TEST(ReflectorMaps, ColourShadedWhereSearchesReadChangesNoSample) {
  par::Executor ex(2);
  for (const char* name : {"sphere-in-room", "glossy-plane", "living-room", "glass-sphere"}) {
    SCOPED_TRACE(name);
    const View v = view_of(name, 128, 96, ex);
    for (const int size : {64, 128}) {
      DistanceSearchOptions search;
      MapSizing searched;
      searched.reads = MapSizing::Reads::search;
      searched.lobe_directions = search.lobe_directions;
      const ReflectorMaps whole =
          render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g, ReflectorSelection::all, {}, nullptr, searched);
      const ReflectorMaps distances = render_reflector_maps(ex, v.scene, v.shadows, v.env, size, &v.g,
                                                            ReflectorSelection::all, {}, nullptr,
                                                            searched_distance_maps(true, false));
      DistanceReflectStats one_pass;
      const ImageRGBA expected = distance_map_reflect(ex, v.g, v.env, whole, search, &one_pass);
      const DistanceSearches found = distance_map_search(ex, v.g, distances, search);
      const ReflectorMaps shaded = shade_reflector_maps(ex, v.scene, v.shadows, v.env, distances, found.tiles);
      EXPECT_TRUE(same_bytes(expected, distance_map_lookup(ex, v.g, v.env, shaded, found, search)));
      EXPECT_EQ(found.stats.searches, one_pass.searches);
      EXPECT_EQ(found.stats.lookups, one_pass.lookups);
      EXPECT_LE(rendered_texels(shaded), rendered_texels(whole));
      // The mirror ball's map, read at single texels (though nearly all around: the rest of
      // the room is in it), keeps under 70 % of its texels.
      if (std::string(name) == "sphere-in-room") {
        EXPECT_LT(rendered_texels(shaded), 0.7 * rendered_texels(whole));
      }
    }
  }
}

// Searches taken from an earlier search of other samples of the same G-buffer (other object
// ids, kNoId for the samples left out): what both search is reused, the rest searched, and the result is the direct search's — the
// same directions in the same order, the same tiles marked — with only the new samples counted.
TEST(ReflectorMaps, SearchesReusedFromOtherSamplesOfTheGBufferAreTheSame) {
  par::Executor ex(2);
  for (const char* name : {"glossy-plane", "living-room", "glass-sphere"}) {
    SCOPED_TRACE(name);
    const View v = view_of(name, 128, 96, ex);
    DistanceSearchOptions search;
    const ReflectorMaps distances = render_reflector_maps(ex, v.scene, v.shadows, v.env, 64, &v.g,
                                                          ReflectorSelection::all, {}, nullptr,
                                                          searched_distance_maps(true, false));
    // Two overlapping column ranges of the view: the earlier the left two thirds, the later
    // the right two thirds.
    const auto columns = [&](int x0, int x1) {
      GBuffer g = v.g;
      for (std::size_t i = 0; i < g.object.size(); ++i) {
        const int x = static_cast<int>(i % std::size_t(g.width));
        if (x < x0 || x >= x1) g.object.pixels[i] = kNoId;
      }
      return g;
    };
    const GBuffer earlier_g = columns(0, 2 * v.g.width / 3), later_g = columns(v.g.width / 3, v.g.width);
    const DistanceSearches earlier = distance_map_search(ex, earlier_g, distances, search);
    const DistanceSearches direct = distance_map_search(ex, later_g, distances, search);
    const DistanceSearches reused = distance_map_search_reusing(ex, later_g, distances, search, earlier_g.object, earlier);
    ASSERT_EQ(reused.found.size(), direct.found.size());
    for (std::size_t c = 0; c < direct.found.size(); ++c) {
      ASSERT_EQ(reused.found[c].size(), direct.found[c].size());
      if (!direct.found[c].empty()) {
        EXPECT_EQ(std::memcmp(reused.found[c].data(), direct.found[c].data(), direct.found[c].size() * sizeof(glm::vec3)), 0);
      }
    }
    ASSERT_EQ(reused.tiles.size(), direct.tiles.size());
    for (std::size_t m = 0; m < direct.tiles.size(); ++m)
      for (int f = 0; f < kCubeFaces; ++f) EXPECT_EQ(reused.tiles[m].tiles[f], direct.tiles[m].tiles[f]);
    // The middle third was searched earlier: only the right third is searched again.
    const DistanceSearches right = distance_map_search(ex, columns(2 * v.g.width / 3, v.g.width), distances, search);
    EXPECT_GT(direct.stats.searches, right.stats.searches);
    EXPECT_EQ(reused.stats.searches, right.stats.searches);
    EXPECT_EQ(reused.stats.lookups, right.stats.lookups);
  }
}

// A map's prefiltered texels taken from a map prefiltered before from other level-0 faces
// (prefilter_reuse) where no input changed: the same bytes at every level as prefiltering all
// again, with changed blobs on a face's edge and inside another face, and tiles and faces
// prefiltered in one map and not the other. Two thirds of level 1 that both prefilter are taken; taking every texel
// prefiltered before (as if nothing had changed) gives other bytes.
TEST(ReflectorMaps, PrefilteredTexelsTakenFromAnEarlierMapAreTheSame) {
  par::Executor ex(2);
  constexpr int kSize = 64;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::array<ImageRGBA, kCubeFaces> before;
  for (auto& face : before) {
    face = ImageRGBA(kSize, kSize);
    for (auto& p : face.pixels) p = glm::vec4(u(rng), u(rng), u(rng), 1.0f);
  }
  std::array<ImageRGBA, kCubeFaces> now = before;
  for (int y = 20; y < 30; ++y)
    for (int x = 0; x < 6; ++x) now[0].at(x, y) = glm::vec4(5.0f, 0.0f, 1.0f, 1.0f);  // on face 0's edge
  for (int y = 40; y < 44; ++y)
    for (int x = 30; x < 37; ++x) now[3].at(x, y) += glm::vec4(0.5f, 0.5f, 0.5f, 0.0f);
  const auto random_tiles = [&](float keep) {
    CubeTileMask mask = tile_mask_for_reads(kSize, 2);
    for (auto& t : mask.tiles)
      for (auto& tile : t) tile = u(rng) < keep;
    return mask;
  };
  const CubeTileMask tiles_before = random_tiles(0.8f), tiles_now = random_tiles(0.8f);
  const unsigned faces_before = 0x3fu & ~(1u << 5), faces_now = 0x3fu & ~(1u << 2);
  const EnvironmentMap earlier = environment_from_faces(ex, before, false, 0, faces_before, &tiles_before);
  const int levels = static_cast<int>(earlier.levels.size());
  const EnvironmentMap expected = environment_from_faces(ex, now, false, 0, faces_now, &tiles_now);
  const PrefilterReuse reuse =
      prefilter_reuse(ex, now, faces_now, &tiles_now, earlier, faces_before, &tiles_before, levels);
  const EnvironmentMap taken = environment_from_faces(ex, now, false, 0, faces_now, &tiles_now, &reuse);
  ASSERT_EQ(taken.levels.size(), expected.levels.size());
  for (std::size_t l = 0; l < expected.levels.size(); ++l)
    for (int f = 0; f < kCubeFaces; ++f) {
      SCOPED_TRACE(::testing::Message() << "level " << l << " face " << f);
      EXPECT_TRUE(same_bytes(taken.levels[l][f], expected.levels[l][f]));
    }
  // What level 1 takes: of the texels both maps prefilter, those under no changed tile.
  std::size_t both = 0, from_before = 0;
  for (int f = 0; f < kCubeFaces; ++f)
    for (int y = 0; y < kSize / 2; ++y)
      for (int x = 0; x < kSize / 2; ++x) {
        if (!((faces_now >> f) & 1u) || !tiles_now.covers(f, 1, x, y)) continue;
        if (!((faces_before >> f) & 1u) || !tiles_before.covers(f, 1, x, y)) continue;
        ++both;
        from_before += !reuse.changed[1].covers(f, 1, x, y);
      }
  EXPECT_GT(from_before, both * 2 / 3);
  PrefilterReuse blind = reuse;
  for (std::size_t l = 1; l < blind.changed.size(); ++l)
    for (auto& t : blind.changed[l].tiles) std::fill(t.begin(), t.end(), std::uint8_t(0));
  const EnvironmentMap stale = environment_from_faces(ex, now, false, 0, faces_now, &tiles_now, &blind);
  EXPECT_FALSE(same_bytes(stale.levels[1][0], expected.levels[1][0]));
}

// A reflector with no sample in the camera's view gets no map under skip_unseen (nothing
// reads it), and the specular layer is unchanged.
TEST(ReflectorMaps, ReflectorsTheCameraDoesNotSeeGetNoMap) {
  par::Executor ex(2);
  View v = view_of("living-room", 96, 72, ex);
  // Look at the floor in a corner: most reflectors leave the view.
  Camera cam = v.scene.cameras.front();
  cam.target = cam.eye + glm::vec3(0.3f, -1.0f, 0.2f);
  v.g = resolve_gbuffer(ex, v.scene, render_visibility(ex, v.scene, cam, 96, 72), cam.eye);
  MapSizing skip;
  skip.skip_unseen = true;
  const ReflectorMaps all = render_reflector_maps(ex, v.scene, v.shadows, v.env, 32, &v.g);
  const ReflectorMaps seen =
      render_reflector_maps(ex, v.scene, v.shadows, v.env, 32, &v.g, ReflectorSelection::all, {}, nullptr, skip);
  EXPECT_LT(seen.cubes.size(), all.cubes.size());
  for (std::size_t o = 0; o < v.scene.objects.size(); ++o) {
    if (seen.map_of_object[o] < 0) continue;
    bool visible = false;
    for (std::size_t i = 0; i < v.g.object.size() && !visible; ++i) visible = v.g.object.pixels[i] == o;
    EXPECT_TRUE(visible) << o;
  }
  DistanceSearchOptions search;
  EXPECT_TRUE(same_bytes(distance_map_reflect(ex, v.g, v.env, all, search),
                         distance_map_reflect(ex, v.g, v.env, seen, search)));
}

// Footprint sizes: powers of two in [kMinFootprintSize, cap], 0 for objects that read no
// map; the same mirror ball seen on more pixels never gets a smaller map.
TEST(ReflectorMaps, FootprintSizesArePowersOfTwoThatGrowWithTheView) {
  par::Executor ex(2);
  const View small = view_of("sphere-in-room", 80, 60, ex);
  const View large = view_of("sphere-in-room", 640, 480, ex);
  const std::vector<int> a = footprint_sizes(ex, small.scene, small.g, 256);
  const std::vector<int> b = footprint_sizes(ex, large.scene, large.g, 256);
  ASSERT_EQ(a.size(), small.scene.objects.size());
  int sized = 0;
  for (std::size_t o = 0; o < a.size(); ++o) {
    for (const int s : {a[o], b[o]})
      if (s != 0) {
        EXPECT_TRUE(std::has_single_bit(static_cast<unsigned>(s))) << s;
        EXPECT_GE(s, kMinFootprintSize);
        EXPECT_LE(s, 256);
      }
    if (a[o] == 0) continue;
    ++sized;
    EXPECT_LE(a[o], b[o]) << o;
  }
  EXPECT_GT(sized, 0);
}

// Lobe sizes (MapSizing::from_lobes): a map whose reflector reflects through glossy lobes
// alone is the smallest power of two (at least kMinFootprintSize) whose texel angle (π/2)/side
// is at most 0.15 of the half-power angle of its sharpest read, the sub-lobe of exponent 4n:
// living-room's vase halves, its mirrors, refractor and the floor keep the cap; the sizes do
// not depend on the view.
TEST(ReflectorMaps, LobeSizesFollowTheSharpestGlossyLobe) {
  par::Executor ex(2);
  const View v = view_of("living-room", 96, 72, ex);
  const View other = view_of("living-room", 64, 48, ex);
  const ReflectorMaps capped = render_reflector_maps(ex, v.scene, v.shadows, v.env, 256, &v.g, ReflectorSelection::all,
                                                     {}, nullptr, searched_distance_maps(false, false));
  const ReflectorMaps sized = render_reflector_maps(ex, v.scene, v.shadows, v.env, 256, &v.g, ReflectorSelection::all,
                                                    {}, nullptr, searched_distance_maps(false, true));
  const ReflectorMaps sized_other = render_reflector_maps(ex, other.scene, other.shadows, other.env, 256, &other.g,
                                                          ReflectorSelection::all, {}, nullptr,
                                                          searched_distance_maps(false, true));
  ASSERT_EQ(sized.cubes.size(), capped.cubes.size());
  int smaller = 0;
  for (std::size_t o = 0; o < v.scene.objects.size(); ++o) {
    const int m = sized.map_of_object[o];
    if (m < 0) continue;
    SCOPED_TRACE(v.scene.objects[o].name);
    const int side = sized.cubes[m].size;
    EXPECT_EQ(side, sized_other.cubes[sized_other.map_of_object[o]].size);
    EXPECT_EQ(capped.cubes[capped.map_of_object[o]].size, 256);
    const Object& obj = v.scene.objects[o];
    const SurfaceParams s = surface_params(v.scene.materials[v.scene.mesh.triangle_material[obj.first_triangle]]);
    const bool glossy = !s.is_refractor() && !s.is_mirror_lobe() && s.phong_exponent < 1e6f;
    if (!glossy) {
      EXPECT_EQ(side, 256);
      continue;
    }
    const float need = 0.15f * std::sqrt(2.0f * 0.69314718f / (4.0f * s.phong_exponent));
    const auto angle = [](int n) { return 0.5f * kPi / float(n); };
    EXPECT_TRUE(std::has_single_bit(unsigned(side)));
    if (side < 256) {
      EXPECT_LE(angle(side), need);
    }
    if (side > kMinFootprintSize) {
      EXPECT_GT(angle(side / 2), need);
    }
    smaller += side < 256;
  }
  EXPECT_EQ(smaller, 1);  // the vase
}

}  // namespace
}  // namespace speculum::raster
