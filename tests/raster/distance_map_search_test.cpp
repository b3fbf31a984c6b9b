// Tests of the distance-map search (SURVEY §4.1): checks against exact geometry — direct
// lookup at the reference point, one exact parallax step for a wall perpendicular to R, one
// exact secant step on a plane — and the error growing with |x − o| in sphere-in-room
// against a brute-force ray oracle.
#include "raster/distance_map_search.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/sampling.h"
#include "core/scene_loader.h"
#include "raster/distance_map_reflect.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Exact distance map of the plane n·y = c around the origin (nothing behind it).
struct PlaneMap {
  glm::vec3 n;
  float c;
  float operator()(const glm::vec3& d) const {
    const glm::vec3 u = glm::normalize(d);
    const float un = glm::dot(u, n);
    return un > 0.0f ? c / un : kInf;
  }
  float hit(const glm::vec3& x, const glm::vec3& r) const {
    return (c - glm::dot(n, x)) / glm::dot(n, r);
  }
};

// One SURVEY eq.5 step between guesses d_l and d_p, from the search's own ratio and
// secant_from_ratios (the search takes its ratios from the linear march instead).
template <class DistanceFn>
float secant_step(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r, float d_l,
                  float d_p) {
  int lookups = 0;
  return secant_from_ratios(d_l, distance_search_detail::ratio(distance_towards, x, r, d_l, lookups),
                            d_p, distance_search_detail::ratio(distance_towards, x, r, d_p, lookups));
}

std::vector<glm::vec3> sphere_directions(int n) {  // Fibonacci sphere
  std::vector<glm::vec3> out;
  for (int i = 0; i < n; ++i) {
    const float y = 1.0f - 2.0f * (i + 0.5f) / n, rr = std::sqrt(1.0f - y * y);
    const float phi = 2.39996323f * i;
    out.push_back({rr * std::cos(phi), y, rr * std::sin(phi)});
  }
  return out;
}

TEST(DistanceMapSearch, ParallaxStepIsExactForAWallPerpendicularToR) {
  const glm::vec3 r = glm::normalize(glm::vec3(0.2f, -0.1f, 1.0f));
  const PlaneMap wall{r, 5.0f};
  DistanceSearchOptions o;
  o.linear = false;
  o.secant = false;
  o.parallax_steps = 1;
  for (const glm::vec3 x : {glm::vec3(1, 2, 0.5f), glm::vec3(-2, 0.3f, -1), glm::vec3(0.1f, 0, 3)}) {
    const DistanceSearchResult res = search_distance(wall, x, r, o);
    EXPECT_NEAR(res.d, wall.hit(x, r), 1e-4f * wall.hit(x, r));
    EXPECT_EQ(res.lookups, 1);
  }
  // The same single step on a tilted wall is not exact (so the check above can fail).
  const PlaneMap tilted{glm::normalize(glm::vec3(0.6f, 0.0f, 1.0f)), 5.0f};
  const glm::vec3 x(1, 2, 0.5f);
  EXPECT_GT(std::abs(search_distance(tilted, x, r, o).d - tilted.hit(x, r)), 0.05f);
}

TEST(DistanceMapSearch, OneSecantStepIsExactWhenBothStoredPointsLieOnOnePlane) {
  const PlaneMap wall{glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f)), 4.0f};
  for (const glm::vec3 r : sphere_directions(64)) {
    const glm::vec3 x(0.7f, -0.4f, 0.9f);
    const float exact = wall.hit(x, r);
    if (!(exact > 0.0f) || exact > 100.0f) continue;
    for (const float a : {0.3f, 0.9f})
      for (const float b : {1.1f, 2.5f}) {
        const float d = secant_step(wall, x, r, a * exact, b * exact);
        EXPECT_NEAR(d, exact, 2e-4f * exact) << "a " << a << " b " << b;
      }
  }
  // Guesses whose stored points lie on two different planes (a corner) give an inexact step.
  const PlaneMap left{glm::vec3(1, 0, 0), 2.0f}, back{glm::vec3(0, 0, 1), 2.0f};
  const auto corner = [&](const glm::vec3& d) { return std::min(left(d), back(d)); };
  const glm::vec3 x(1.5f, 0.0f, -1.5f), r = glm::normalize(glm::vec3(0.8f, 0.0f, 1.0f));
  const float exact = left.hit(x, r);
  ASSERT_LT(x.z + r.z * exact, 2.0f);  // the true hit is on the left plane
  const glm::vec3 far = x + r * (40.0f * exact);
  ASSERT_LT(back(far), left(far));     // the far guess's stored point is on the back plane
  EXPECT_GT(std::abs(secant_step(corner, x, r, 0.5f * exact, 40.0f * exact) - exact), 0.01f);
}

TEST(DistanceMapSearch, LinearPlusSecantConvergesOnATiltedWall) {
  const PlaneMap wall{glm::normalize(glm::vec3(-0.4f, 0.3f, 1.0f)), 6.0f};
  const glm::vec3 x(0.5f, 1.0f, -0.8f);
  DistanceSearchOptions o;  // defaults: linear 16, secant 4
  int checked = 0;
  for (const glm::vec3 r : sphere_directions(200)) {
    const float exact = wall.hit(x, r);
    if (!(exact > 0.0f) || exact > 8.0f * glm::length(x)) continue;  // inside the march
    const DistanceSearchResult res = search_distance(wall, x, r, o);
    EXPECT_TRUE(res.bracketed);
    EXPECT_NEAR(res.d, exact, 1e-3f * exact);
    ++checked;
  }
  EXPECT_GT(checked, 30);
}

// A scene and its cube map from the mirror sphere's centre, the sphere collapsed to a point
// (the reflector is not in its own map).
struct RoomFixture {
  Scene scene;
  CubeMap map;
  RoomFixture() {
    scene = load_scene("sphere-in-room:size=3000");
    for (std::size_t o = 0; o < scene.objects.size(); ++o)
      if (scene.objects[o].name == "mirror sphere") {
        const Object& ob = scene.objects[o];
        for (std::uint32_t t = ob.first_triangle; t < ob.first_triangle + ob.triangle_count; ++t)
          for (int k = 0; k < 3; ++k) scene.mesh.positions[scene.mesh.indices[3 * t + k]] = {0, -50, 0};
      }
    par::Executor ex(2);
    CubeMapOptions opt;
    opt.size = 128;
    map = render_cube_map(ex, scene, {0.0f, 1.5f, 0.0f}, opt);
  }
  // Mean distance between the searched hit (o + u·stored) and the true hit over directions.
  double mean_error(const glm::vec3& x, const DistanceSearchOptions& o) const {
    double sum = 0;
    int n = 0;
    for (const glm::vec3 r : sphere_directions(300)) {
      const testing::OracleHit truth =
          testing::oracle_closest_hit(scene, Ray{x, r}, glm::dvec3(r), 1e-4);
      if (truth.triangle == 0xffffffffu) continue;
      const glm::vec3 exact = x + r * float(truth.t);
      const DistanceSearchResult res = search_distance_map(map, x, r, o);
      const glm::vec3 u = glm::normalize(res.direction);
      const glm::vec3 found = map.centre + u * map.distance_towards(u);
      sum += glm::length(found - exact);
      ++n;
    }
    return sum / n;
  }
};

TEST(DistanceMapSearch, AtTheReferencePointEqualsADirectCubeLookup) {
  const RoomFixture f;
  for (const DistanceSearchOptions o :
       {DistanceSearchOptions{}, DistanceSearchOptions{true, 3, false, 16, true, 2}}) {
    for (const glm::vec3 r : sphere_directions(100)) {
      const DistanceSearchResult res = search_distance_map(f.map, f.map.centre, r, o);
      EXPECT_EQ(res.direction, r);
      EXPECT_EQ(res.d, f.map.distance_towards(r));
    }
  }
}

TEST(DistanceMapSearch, MarchInLanesGivesTheBitsOfTheScalarMarch) {
  // search_distance_map marches eight samples at a time; the generic search marches one at a
  // time with ratio(). Same d, direction, bracket and lookup count, bit for bit: origins
  // inside and outside the room's map, at its centre too, every direction, march lengths
  // that end inside and across batches, a map with empty texels (the environment behind a
  // hole), and rays that leave from exactly the centre's direction.
  RoomFixture f;
  for (int k = 0; k < 40; ++k) f.map.distance[k % kCubeFaces].pixels[(k * 997) % f.map.distance[0].pixels.size()] = kInf;
  const auto scalar = [&](const glm::vec3& x, const glm::vec3& r, const DistanceSearchOptions& o) {
    return search_distance([&](const glm::vec3& d) { return f.map.distance_towards(d); }, x - f.map.centre, r, o);
  };
  int bracketed = 0, compared = 0;
  const std::vector<glm::vec3> dirs = sphere_directions(300);
  for (const int steps : {2, 5, 8, 9, 16, 23}) {
    DistanceSearchOptions o;
    o.linear_steps = steps;
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      const glm::vec3 r = dirs[i];
      const float reach = 0.1f + 3.0f * float(i % 7) / 6.0f;
      const glm::vec3 x = f.map.centre + reach * dirs[(i * 31 + 7) % dirs.size()];
      for (const glm::vec3 origin : {x, f.map.centre, f.map.centre + 0.5f * r}) {
        const DistanceSearchResult a = search_distance_map(f.map, origin, r, o), b = scalar(origin, r, o);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a.d), std::bit_cast<std::uint32_t>(b.d)) << steps << " " << i;
        ASSERT_EQ(a.direction, b.direction) << steps << " " << i;
        ASSERT_EQ(a.bracketed, b.bracketed) << steps << " " << i;
        ASSERT_EQ(a.lookups, b.lookups) << steps << " " << i;
        bracketed += a.bracketed;
        ++compared;
      }
    }
    // A ray that passes exactly through the centre, at d = 0.5 (the middle sample of an even
    // march): ratio() reads nothing there (l = 0), and counts no lookup.
    for (const glm::vec3 axis : {glm::vec3(0, 0, 1), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0)}) {
      const glm::vec3 origin = f.map.centre - 0.5f * axis;
      const DistanceSearchResult a = search_distance_map(f.map, origin, axis, o), b = scalar(origin, axis, o);
      ASSERT_EQ(std::bit_cast<std::uint32_t>(a.d), std::bit_cast<std::uint32_t>(b.d)) << steps;
      ASSERT_EQ(a.lookups, b.lookups) << steps;
    }
  }
  EXPECT_GT(bracketed, compared / 3);
}

// Eight searches with their secant steps side by side in lanes: each result (d, direction,
// bracket, lookups) has the bits of the search alone, for every count of directions, with
// secant steps on and off, with and without the linear march and the parallax steps, from one
// point (the map's centre, or elsewhere) and from a point of its own per search (some at the
// centre), on a map with empty texels.
TEST(DistanceMapSearch, EightSearchesInLanesGiveTheBitsOfEachAlone) {
  RoomFixture f;
  for (int k = 0; k < 40; ++k) f.map.distance[k % kCubeFaces].pixels[(k * 997) % f.map.distance[0].pixels.size()] = kInf;
  const std::vector<glm::vec3> dirs = sphere_directions(240);
  std::vector<DistanceSearchOptions> options(6);
  options[1].secant_steps = 1;
  options[2].secant = false;
  options[3].linear = false;
  options[4].parallax = false, options[4].linear_steps = 5;
  options[5].secant_steps = 9, options[5].linear_steps = 23;
  int bracketed = 0, refined = 0, compared = 0;
  for (std::size_t oi = 0; oi < options.size(); ++oi) {
    const DistanceSearchOptions& o = options[oi];
    for (std::size_t i = 0; i + 8 <= dirs.size(); i += 8) {
      const float reach = 0.1f + 3.0f * float(i % 7) / 6.0f;
      const glm::vec3 x = f.map.centre + reach * dirs[(i * 31 + 7) % dirs.size()];
      const int count = 1 + int(i / 8) % 8;
      for (int from = 0; from < 3; ++from) {
        DistanceSearchResult lanes[8];
        glm::vec3 origins[8];
        for (int j = 0; j < 8; ++j)
          origins[j] = from == 0 ? x
                       : from == 1 ? f.map.centre
                       : j % 3 == 1 ? f.map.centre
                                    : f.map.centre + (0.2f + 0.4f * float(j)) * dirs[(i * 17 + 5 * j + 3) % dirs.size()];
        search_distance_map8(f.map, origins, &dirs[i], count, o, lanes);
        for (int j = 0; j < count; ++j) {
          const DistanceSearchResult alone = search_distance_map(f.map, origins[j], dirs[i + j], o);
          ASSERT_EQ(std::bit_cast<std::uint32_t>(lanes[j].d), std::bit_cast<std::uint32_t>(alone.d)) << oi << " " << i << " " << j;
          ASSERT_EQ(lanes[j].direction, alone.direction) << oi << " " << i << " " << j;
          ASSERT_EQ(lanes[j].bracketed, alone.bracketed) << oi << " " << i << " " << j;
          ASSERT_EQ(lanes[j].lookups, alone.lookups) << oi << " " << i << " " << j;
          bracketed += alone.bracketed;
          refined += alone.bracketed && o.secant && alone.lookups > 2;
          ++compared;
        }
      }
    }
  }
  EXPECT_GT(bracketed, compared / 5);  // from the centre and without the march: no bracket
  EXPECT_GT(refined, compared / 6);
}

// The sub-lobe axes a glossy search keeps for the last exponent: whatever exponents came
// before, the axes of each are those computed afresh.
TEST(DistanceMapSearch, SubLobeAxesAreThoseOfTheExponentAsked) {
  for (const int directions : {1, 5, 8}) {
    SubLobeAxes axes(directions);
    EXPECT_EQ(axes.count(), directions);
    for (const float exponent : {131.0f, 131.0f, 20.0f, 131.0f, 4000.0f, 4000.0f, 20.0f}) {
      const glm::vec3* got = axes(exponent);
      for (int k = 0; k < directions; ++k) {
        const glm::vec3 expected = sample_phong_lobe(
            hamersley(std::uint32_t(k), std::uint32_t(directions)), exponent * (4.0f / 3.0f));
        EXPECT_EQ(std::bit_cast<std::uint32_t>(got[k].x), std::bit_cast<std::uint32_t>(expected.x));
        EXPECT_EQ(std::bit_cast<std::uint32_t>(got[k].y), std::bit_cast<std::uint32_t>(expected.y));
        EXPECT_EQ(std::bit_cast<std::uint32_t>(got[k].z), std::bit_cast<std::uint32_t>(expected.z));
      }
    }
  }
}

TEST(DistanceMapSearch, ErrorGrowsWithDistanceFromTheReferencePoint) {
  const RoomFixture f;
  const glm::vec3 away = glm::normalize(glm::vec3(-1.0f, 0.2f, 1.0f));
  for (const DistanceSearchOptions o :
       {DistanceSearchOptions{}, DistanceSearchOptions{true, 1, false, 16, false, 0}}) {
    double previous = -1.0;
    for (const float dist : {0.0f, 1.5f, 3.0f}) {
      const double e = f.mean_error(f.map.centre + away * dist, o);
      if (dist == 0.0f) {
        EXPECT_LT(e, 0.06) << "texel-sized error only at o";
      }
      EXPECT_GT(e, previous) << "|x - o| = " << dist;
      previous = e;
    }
  }
}

}  // namespace
}  // namespace speculum::raster
