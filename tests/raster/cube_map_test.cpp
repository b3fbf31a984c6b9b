// Tests of cube maps and the environment node: face conventions round-trip, the faces near a
// direction, cube-map distance against a brute-force ray oracle (SURVEY §4 distance maps),
// prefiltered environment and SH irradiance against analytic constants.
#include "raster/cube_map.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "raster/cube_coord_lanes.h"
#include "raster/environment.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

// cube_coord8 against cube_coord, bit for bit (and its face table against the cameras'):
// directions on every face, along the axes, on the edges and corners between faces (the ties
// of the largest component), with signed zeros, and random ones, eight at a time in every
// arrangement of lanes.
TEST(CubeCoordLanes, EightCoordinatesHaveTheBitsOfOneAtATime) {
  // The faces' axes and signs cube_coord8 is written with are those of the face cameras.
  for (int f = 0; f < kCubeFaces; ++f) {
    const CubeFaceAxes& a = kCubeFaceAxes[f];
    EXPECT_EQ(a.forward, f / 2) << f;
    EXPECT_EQ(a.right, detail::kRightAxis[f / 2]) << f;
    EXPECT_EQ(a.up, detail::kUpAxis[f / 2]) << f;
    EXPECT_EQ(a.forward_sign, detail::kForwardSign[f]) << f;
    EXPECT_EQ(a.right_sign, detail::kRightSign[f]) << f;
    EXPECT_EQ(a.up_sign, detail::kUpSign[f]) << f;
  }
  std::vector<glm::vec3> dirs;
  const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 0.3f, -0.7f};
  for (const float x : values)
    for (const float y : values)
      for (const float z : values)
        if (x != 0.0f || y != 0.0f || z != 0.0f) dirs.emplace_back(x, y, z);
  std::mt19937 rng(5);
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (int k = 0; k < 4000; ++k) dirs.emplace_back(n(rng), n(rng), n(rng));
  for (const int size : {1, 7, 256}) {
    for (std::size_t i = 0; i + 8 <= dirs.size(); i += 3) {
      using L = par::Lanes<8>;
      alignas(32) float in[3][8];
      for (int j = 0; j < 8; ++j)
        for (int c = 0; c < 3; ++c) in[c][j] = dirs[i + j][c];
      const L::f32 d[3] = {L::load_aligned(in[0]), L::load_aligned(in[1]), L::load_aligned(in[2])};
      const CubeCoordLanes lanes = cube_coord8(d, size);
      alignas(32) std::int32_t face[8];
      alignas(32) float x[8], y[8];
      L::store_aligned(lanes.face, face), L::store_aligned(lanes.x, x), L::store_aligned(lanes.y, y);
      for (int j = 0; j < 8; ++j) {
        const CubeCoord one = cube_coord(dirs[i + j], size);
        ASSERT_EQ(face[j], one.face) << i + j;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(x[j]), std::bit_cast<std::uint32_t>(one.pixel.x)) << i + j;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(y[j]), std::bit_cast<std::uint32_t>(one.pixel.y)) << i + j;
      }
    }
  }
}

TEST(CubeMapFaces, DirectionAndCoordinateRoundTrip) {
  const int size = 32;
  for (int face = 0; face < kCubeFaces; ++face)
    for (float y : {0.5f, 7.25f, 31.5f})
      for (float x : {0.5f, 16.0f, 30.75f}) {
        const glm::vec3 d = cube_direction(face, {x, y}, size);
        const CubeCoord c = cube_coord(d * 3.0f, size);
        EXPECT_EQ(c.face, face);
        EXPECT_NEAR(c.pixel.x, x, 1e-3f);
        EXPECT_NEAR(c.pixel.y, y, 1e-3f);
        // The face camera's primary ray through the same point is the same direction.
        const Ray r = primary_ray(cube_face_camera(face, {}, 0.1f, 10.0f), size, size, x, y);
        EXPECT_LT(glm::length(r.direction - d), 1e-5f);
      }
}

// cube_faces_near holds the face of every direction within its margin of p (directions on
// the cap's rim, where the bound is tight, and inside it), at margins up to past π/2; and it
// is no looser than the cap: straight down, 0.7 rad stays on −Y, whose sides start at 45°.
TEST(CubeMapFaces, FacesNearHoldEveryDirectionWithinTheMargin) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int trial = 0; trial < 400; ++trial) {
    const float cos_theta = 1.0f - 2.0f * unit(rng);
    const glm::vec3 p = spherical_local(cos_theta, unit(rng));
    const float margin = 1.8f * unit(rng) * unit(rng);
    const unsigned faces = cube_faces_near(p, margin);
    const Onb frame(p);
    for (int k = 0; k < 400; ++k) {
      const float angle = margin * (k % 2 == 0 ? 1.0f : unit(rng));
      const glm::vec3 q = frame.to_world(spherical_local(std::cos(angle), unit(rng)));
      ASSERT_TRUE((faces >> cube_coord(q, 64).face) & 1u) << "trial " << trial << " margin " << margin;
    }
  }
  EXPECT_EQ(cube_faces_near({0.0f, -1.0f, 0.0f}, 0.7f), 1u << 3);
  EXPECT_EQ(cube_faces_near({0.0f, -1.0f, 0.0f}, 0.8f) & 0x3bu, 0x3bu);  // −Y and its four sides
  EXPECT_EQ(cube_faces_near({0.0f, -1.0f, 0.0f}, 1.6f), 0x3fu);
}

// A tile mask's texel count is the number of level-0 texels its read tiles hold, on sides that
// are and are not whole numbers of tiles (the last row and column of tiles are then partial).
TEST(CubeTileMask, TexelCountEqualsTheTexelsOfItsReadTiles) {
  std::mt19937 rng(7);
  for (const int size : {8, 20, 37, 64}) {
    CubeTileMask mask;
    mask.size = size;
    const int n = mask.tiles_per_side();
    for (int face = 1; face < kCubeFaces; ++face) {  // face 0 keeps no tile array: nothing read
      mask.tiles[face].resize(static_cast<std::size_t>(n) * n);
      for (std::uint8_t& t : mask.tiles[face]) t = rng() % 3 == 0;
    }
    for (const unsigned faces : {0x3fu, 0x15u, 0x01u}) {
      double expected = 0.0;
      for (int face = 0; face < kCubeFaces; ++face)
        if ((faces >> face) & 1u)
          for (const std::uint8_t v : mask.texels(face)) expected += v;
      EXPECT_EQ(mask.texel_count(faces), expected) << "size " << size << " faces " << faces;
    }
  }
}

// Each texel's byte is its tile's, for one-texel tiles and wider ones, on sides that are and
// are not whole numbers of tiles.
TEST(CubeTileMask, TexelsTakeTheirTilesBytes) {
  std::mt19937 rng(11);
  for (const int tile : {1, 2, 3, 8})
    for (const int size : {8, 20, 37}) {
      CubeTileMask mask;
      mask.size = size;
      mask.tile = tile;
      const int n = mask.tiles_per_side();
      mask.tiles[2].resize(static_cast<std::size_t>(n) * n);
      for (std::uint8_t& t : mask.tiles[2]) t = rng() % 2;
      const std::vector<std::uint8_t> texels = mask.texels(2);
      ASSERT_EQ(texels.size(), static_cast<std::size_t>(size) * size);
      for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
          ASSERT_EQ(texels[static_cast<std::size_t>(y) * size + x],
                    mask.tiles[2][static_cast<std::size_t>(y / tile) * n + x / tile])
              << "tile " << tile << " size " << size << " texel " << x << "," << y;
      EXPECT_EQ(mask.texels(0), std::vector<std::uint8_t>(static_cast<std::size_t>(size) * size, 0));
    }
}

TEST(CubeMapDistance, EqualsOracleHitDistanceInEveryFace) {
  // A closed room around o with a torus and loose triangles in it: every texel hits.
  Scene scene;
  scene.name = "room";
  using testing::add_triangles;
  const float r = 3.0f;
  add_triangles(scene,
                {{-r, -r, -r}, {r, -r, -r}, {r, r, -r}, {-r, r, -r},
                 {-r, -r, r}, {r, -r, r}, {r, r, r}, {-r, r, r}},
                {0, 1, 2, 0, 2, 3, 4, 6, 5, 4, 7, 6, 0, 4, 5, 0, 5, 1,
                 3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2});
  testing::add_torus(scene, {0.4f, 0.2f, -0.3f}, 1.2f, 0.3f, 48, 24);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-2.5f, 2.5f);
  for (int k = 0; k < 30; ++k) {
    const glm::vec3 c{u(rng), u(rng), u(rng)};
    add_triangles(scene, {c, c + glm::vec3(0.5f, 0.1f, 0), c + glm::vec3(0, 0.4f, 0.3f)}, {0, 1, 2});
  }
  const glm::vec3 o(0.1f, -0.2f, 0.3f);
  CubeMapOptions opt;
  opt.size = 48;
  opt.znear = 0.01f;
  opt.zfar = 50.0f;
  par::Executor ex(2);
  const CubeMap cube = render_cube_map(ex, scene, o, opt);
  std::size_t samples = 0, edge = 0;
  double max_rel = 0;
  for (int face = 0; face < kCubeFaces; ++face) {
    const Camera cam = cube_face_camera(face, o, opt.znear, opt.zfar);
    const glm::dvec3 forward(glm::normalize(cam.target - cam.eye));
    for (int y = 0; y < opt.size; ++y)
      for (int x = 0; x < opt.size; ++x) {
        const Ray ray = primary_ray(cam, opt.size, opt.size, x + 0.5f, y + 0.5f);
        const auto hit = testing::oracle_closest_hit(scene, ray, forward, opt.znear);
        ASSERT_NE(hit.triangle, kNoId) << "the room is closed";
        ++samples;
        const double expected = hit.t;  // unit direction: t is |y − o|
        const double got = cube.distance[face].at(x, y);
        const double rel = std::abs(got - expected) / expected;
        if (rel > 1e-3 && hit.min_edge_distance < 2e-3) { ++edge; continue; }
        max_rel = std::max(max_rel, rel);
      }
  }
  EXPECT_EQ(samples, std::size_t(6 * opt.size * opt.size));
  EXPECT_LT(max_rel, 1e-3);
  EXPECT_LE(edge, samples / 500) << edge;
}

TEST(Environment, ConstantEnvironmentPrefiltersAndIrradiatesExactly) {
  Environment env;
  env.constant = glm::vec3(0.2f, 0.5f, 1.5f);
  par::Executor ex(2);
  const EnvironmentMap map = build_environment(ex, env, 16);
  std::mt19937 rng(9);
  std::normal_distribution<float> g;
  for (int k = 0; k < 50; ++k) {
    const glm::vec3 d = glm::normalize(glm::vec3{g(rng), g(rng), g(rng)});
    for (float n : {1e6f, 500.0f, 20.0f, 1.0f}) {
      const glm::vec3 L = map.radiance(d, n);
      EXPECT_NEAR(L.x, 0.2f, 1e-4f);
      EXPECT_NEAR(L.z, 1.5f, 1e-4f);
    }
    // E = π L for a constant environment (cosine-weighted hemisphere integral).
    const glm::vec3 e = map.irradiance(d);
    EXPECT_NEAR(e.y, kPi * 0.5f, 2e-3f * kPi * 0.5f);
  }
}

TEST(Environment, SkyIrradianceMatchesDirectIntegration) {
  // Low-frequency sky: SH9 irradiance is accurate to a few percent for such content.
  Environment env;
  env.equirect = ImageRGBA(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) {
      const float up = 1.0f - (y + 0.5f) / 16.0f;  // +1 at the top, -1 at the bottom
      env.equirect.at(x, y) = glm::vec4(glm::vec3(1.0f + 0.8f * up), 1.0f);
    }
  par::Executor ex(1);
  const EnvironmentMap map = build_environment(ex, env, 32);
  for (const glm::vec3 n : {glm::vec3(0, 1, 0), glm::vec3(0, -1, 0), glm::vec3(1, 0, 0)}) {
    // Brute-force E(n) = ∫ L(ω) max(0, n·ω) dω over a fine cosine-sampled hemisphere.
    double e = 0;
    const int m = 20000;
    const Onb onb(n);
    for (int i = 0; i < m; ++i) {
      const glm::vec3 w = onb.to_world(sample_cosine_hemisphere(hamersley(i, m)));
      e += environment_radiance(env, w).x;
    }
    e *= kPi / m;  // pdf cosθ/π: estimator π·mean(L)
    EXPECT_NEAR(map.irradiance(n).x, e, 0.03 * e) << n.x << n.y << n.z;
  }
}

TEST(Environment, EightIrradiancesAtOnceHaveTheBitsOfOne) {
  // A sky with colour in every SH band (darker than zero on part of the sphere after
  // projection: the clamp at zero is exercised), normals in every direction.
  Environment env;
  env.equirect = ImageRGBA(64, 32);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x)
      env.equirect.at(x, y) = glm::vec4((x + y) % 7 == 0 ? 30.0f : 0.0f, 0.5f * float(y) / 32.0f, x < 8 ? 4.0f : 0.0f, 1.0f);
  par::Executor ex(1);
  const EnvironmentMap map = build_environment(ex, env, 16);
  int clamped = 0;
  for (std::uint32_t i = 0; i < 2000; ++i) {
    glm::vec3 n[8], got[8];
    for (int j = 0; j < 8; ++j)
      n[j] = spherical_local(1.0f - 2.0f * random_float(i * 8 + j, 0, 0, 3), random_float(i * 8 + j, 0, 1, 3));
    map.irradiance8(Vec3Lanes<8>::load(n, 8)).store(got, 8);
    for (int j = 0; j < 8; ++j) {
      const glm::vec3 e = map.irradiance(n[j]);
      ASSERT_EQ(got[j], e) << i << " lane " << j;
      clamped += e.x == 0.0f || e.y == 0.0f || e.z == 0.0f;
    }
  }
  EXPECT_GT(clamped, 0);
}

// Six size² faces of uniform random radiance in [0, 4) drawn from `rng` (every level of their
// prefiltered cascade differs).
std::array<ImageRGBA, kCubeFaces> random_cube_faces(int size, std::mt19937& rng) {
  std::array<ImageRGBA, kCubeFaces> faces;
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  for (ImageRGBA& f : faces) {
    f = ImageRGBA(size, size);
    for (glm::vec4& p : f.pixels) p = glm::vec4{u(rng), u(rng), u(rng), 1.0f};
  }
  return faces;
}

// The prefiltering cascade, computed eight texels at a time, against its definition looked up
// one direction at a time: level l's texel is the mean of 48 Hamersley directions of the
// Phong lobe whose variance is the difference of levels l and l−1's (half-power angle one
// texel each), about the texel's axis, each read bilinearly from level l−1 (a one-level map
// read as a mirror) — bit for bit, on every face, with a random texture and tile masks off.
TEST(Environment, PrefilteredTexelsAreTheMeanOfTheirLobesLookups) {
  for (const int size : {16, 64}) {
    std::mt19937 rng(11);
    const std::array<ImageRGBA, kCubeFaces> faces = random_cube_faces(size, rng);
    par::Executor ex(2);
    const EnvironmentMap map = environment_from_faces(ex, faces, false, 4);
    const auto texel_angle = [](int s) { return 0.5f * kPi / static_cast<float>(s); };
    for (int l = 1; l < 4; ++l) {
      EnvironmentMap previous;
      previous.size = size >> (l - 1);
      previous.levels = {map.levels[l - 1]};
      const int s = size >> l;
      const float target = texel_angle(s), before = l == 1 ? 0.0f : texel_angle(size >> (l - 1));
      const float step = std::sqrt(target * target - before * before);
      const float exponent = 2.0f * 0.69314718f / (step * step);
      for (int face = 0; face < kCubeFaces; ++face)
        for (int y = 0; y < s; ++y)
          for (int x = 0; x < s; ++x) {
            const Onb onb(cube_direction(face, {x + 0.5f, y + 0.5f}, s));
            glm::vec3 sum(0.0f);
            for (std::uint32_t k = 0; k < 48; ++k)
              sum += previous.radiance(onb.to_world(sample_phong_lobe(hamersley(k, 48), exponent)), 1e6f);
            const glm::vec4 want(sum / 48.0f, 1.0f);
            const glm::vec4 got = map.levels[l][face].at(x, y);
            ASSERT_EQ(0, std::memcmp(&want, &got, sizeof want))
                << "size " << size << " level " << l << " face " << face << " texel " << x << "," << y;
          }
    }
  }
}

// radiance8 against radiance, bit for bit: batches of 1..8 directions (axis-aligned ones and
// face edges among them) with one exponent, with a run of equal exponents, and with mixed
// exponents (mirror, between levels, coarsest level, past the last level).
TEST(Environment, EightLookupsHaveTheBitsOfOneAtATime) {
  const int size = 32;
  std::mt19937 rng(9);
  par::Executor ex(2);
  const EnvironmentMap map = environment_from_faces(ex, random_cube_faces(size, rng), false);
  std::normal_distribution<float> g;
  std::uniform_int_distribution<int> pick(0, 6);
  const float exponents[7] = {1e6f, 5000.0f, 800.0f, 245.0f, 40.0f, 3.0f, 1.0f};
  int mixed_batches = 0;
  for (int batch = 0; batch < 3000; ++batch) {
    const int count = 1 + batch % 8, mode = (batch / 8) % 3;
    glm::vec3 d[8], got[8];
    float n[8];
    for (int j = 0; j < count; ++j) {
      d[j] = batch % 50 == 0 && j < 3 ? glm::vec3(j == 0, j == 1, j == 2) * (j % 2 ? -1.0f : 1.0f)
                                      : glm::normalize(glm::vec3{g(rng), g(rng), g(rng)});
      if (batch % 37 == 0) d[j] = glm::normalize(glm::vec3(1.0f, 1.0f, g(rng)));  // face edges
      n[j] = mode == 0 ? exponents[batch % 7] : mode == 1 ? exponents[std::min(j / 3 + batch % 5, 6)]
                                                          : exponents[pick(rng)];
    }
    bool mixed = false;
    for (int j = 1; j < count; ++j) mixed |= n[j] != n[0];
    mixed_batches += mixed;
    map.radiance8(d, n, count, got);
    for (int j = 0; j < count; ++j) {
      const glm::vec3 want = map.radiance(d[j], n[j]);
      ASSERT_EQ(0, std::memcmp(&want, &got[j], sizeof want)) << "batch " << batch << " lane " << j << " n " << n[j];
    }
  }
  EXPECT_GT(mixed_batches, 500);
}

TEST(Environment, TruncatedLevelsGiveTheSameRadianceForTheLobesTheyServe) {
  // A random-texture cube (every level differs), prefiltered fully and only to the levels
  // levels_for_lobes says exponents ≥ n need: radiance() must agree bit for bit for every
  // exponent ≥ n, and a mirror-only map keeps level 0 alone.
  const int size = 64;
  std::mt19937 rng(5);
  const std::array<ImageRGBA, kCubeFaces> faces = random_cube_faces(size, rng);
  par::Executor ex(2);
  const EnvironmentMap full = environment_from_faces(ex, faces, false);
  EXPECT_EQ(levels_for_lobes(size, 1e6f), 1);
  EXPECT_EQ(levels_for_lobes(size, 0.0f), int(full.levels.size()));
  std::normal_distribution<float> g;
  for (float n : {1e6f, 3000.0f, 245.0f, 40.0f, 3.0f}) {
    const int kept = levels_for_lobes(size, n);
    const EnvironmentMap part = environment_from_faces(ex, faces, false, kept);
    ASSERT_EQ(int(part.levels.size()), kept);
    for (int k = 0; k < 200; ++k) {
      const glm::vec3 d = glm::normalize(glm::vec3{g(rng), g(rng), g(rng)});
      for (float m : {n, n * 1.7f, n * 40.0f, 1e6f}) {
        const glm::vec3 a = full.radiance(d, m), b = part.radiance(d, m);
        ASSERT_EQ(a.x, b.x) << "n " << n << " m " << m;
        ASSERT_EQ(a.z, b.z) << "n " << n << " m " << m;
      }
    }
    // Fewer levels than needed would differ: the test can tell (n well inside the range).
    if (kept >= 3 && kept < int(full.levels.size())) {
      const EnvironmentMap short_map = environment_from_faces(ex, faces, false, kept - 2);
      bool differs = false;
      for (int k = 0; k < 50 && !differs; ++k) {
        const glm::vec3 d = glm::normalize(glm::vec3{g(rng), g(rng), g(rng)});
        differs = full.radiance(d, n) != short_map.radiance(d, n);
      }
      EXPECT_TRUE(differs) << "n " << n;
    }
  }
}

}  // namespace
}  // namespace speculum::raster
