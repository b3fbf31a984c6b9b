// Tests of the tile rasterizer (raster/visibility.h): fill rule, watertightness, an
// all-triangles ray oracle, perspective-correct interpolation and determinism.
#include "raster/visibility.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "core/error.h"
#include "core/scene_loader.h"
#include "raster/cube_map.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

using testing::add_torus;
using testing::add_triangles;

ScreenVertex fixed_vertex(std::int32_t x, std::int32_t y) {
  ScreenVertex v;
  v.clip = glm::vec4(0, 0, 0, 1);
  v.x = x;
  v.y = y;
  v.inv_w = 1.0f;
  return v;
}
// How far (in pixels) snapping vertices to the sub-pixel grid can move an edge.
constexpr double kSnapTolerancePixels = 1.0 / kSubpixelOne;

constexpr std::int32_t centre_of(int pixel) { return pixel * kSubpixelOne + kSubpixelOne / 2; }

TEST(RasterFillRule, EdgesThroughSampleCentresFollowTopLeft) {
  par::Executor ex(1);
  // Right triangle with vertices on sample centres (2,2), (10,2), (2,10): its top edge
  // (y=2) and left edge (x=2) are included, its hypotenuse x+y=12 is excluded.
  std::vector<ScreenVertex> v = {fixed_vertex(centre_of(2), centre_of(2)),
                                 fixed_vertex(centre_of(10), centre_of(2)),
                                 fixed_vertex(centre_of(2), centre_of(10))};
  const auto vis = rasterize_screen_vertices(ex, v, {0, 1, 2}, {0}, 16, 16, {});
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const bool expected = x >= 2 && y >= 2 && x + y < 12;
      EXPECT_EQ(vis.triangle.at(x, y) == 0, expected) << x << "," << y;
    }
  // The mirrored triangle (hypotenuse on the left/top side) takes the hypotenuse and
  // drops its right and bottom edges.
  std::vector<ScreenVertex> w = {fixed_vertex(centre_of(10), centre_of(10)),
                                 fixed_vertex(centre_of(10), centre_of(2)),
                                 fixed_vertex(centre_of(2), centre_of(10))};
  const auto vis2 = rasterize_screen_vertices(ex, w, {0, 1, 2}, {0}, 16, 16, {});
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const bool expected = x < 10 && y < 10 && x + y >= 12;
      EXPECT_EQ(vis2.triangle.at(x, y) == 0, expected) << x << "," << y;
    }
}

TEST(RasterFillRule, GridOnSampleCentresCoversEverySampleOnce) {
  // A 40×30-cell grid whose vertices all sit on sample centres, each cell split along a
  // random diagonal and wound randomly: every sample strictly inside or on the top/left
  // border is covered exactly once, every other sample not at all.
  par::Executor ex(2);
  std::mt19937 rng(7);
  const int cells_x = 40, cells_y = 30, step = 3;
  std::vector<ScreenVertex> v;
  for (int j = 0; j <= cells_y; ++j)
    for (int i = 0; i <= cells_x; ++i)
      v.push_back(fixed_vertex(centre_of(1 + i * step), centre_of(1 + j * step)));
  std::vector<std::uint32_t> idx, objects;
  auto at = [&](int i, int j) { return std::uint32_t(j * (cells_x + 1) + i); };
  for (int j = 0; j < cells_y; ++j)
    for (int i = 0; i < cells_x; ++i) {
      std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      const bool flip_diagonal = rng() & 1u;
      std::uint32_t t0[3] = {a, b, flip_diagonal ? d : c};
      std::uint32_t t1[3] = {flip_diagonal ? b : a, c, d};
      if (rng() & 1u) std::swap(t0[1], t0[2]);
      if (rng() & 1u) std::swap(t1[1], t1[2]);
      idx.insert(idx.end(), t0, t0 + 3);
      idx.insert(idx.end(), t1, t1 + 3);
      objects.push_back(0), objects.push_back(0);
    }
  RasterOptions opt;
  opt.count_coverage = true;
  const int w = 1 + cells_x * step + 3, h = 1 + cells_y * step + 3;
  const auto vis = rasterize_screen_vertices(ex, v, idx, objects, w, h, opt);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool inside = x >= 1 && y >= 1 && x < 1 + cells_x * step && y < 1 + cells_y * step;
      ASSERT_EQ(vis.coverage.at(x, y), inside ? 1u : 0u) << x << "," << y;
    }
}

// Setup drops the triangles whose box holds at most 2×2 sample centres when they cover none
// of them. Against a brute-force edge test on every centre: a dropped triangle covers no
// sample, every triangle covering a sample is kept, and the per-sample coverage counts of
// the whole soup (tiny, sliver, degenerate and larger triangles at random sub-pixel
// positions, both windings) equal the brute-force counts.
TEST(RasterSetup, DropsOnlyTrianglesThatCoverNoSample) {
  std::mt19937 rng(29);
  const int width = 70, height = 50;
  std::uniform_int_distribution<std::int32_t> px(0, width * kSubpixelOne - 1),
      py(0, height * kSubpixelOne - 1), tiny(-1 * kSubpixelOne, 1 * kSubpixelOne),
      sliver(-3 * kSubpixelOne, 3 * kSubpixelOne);
  std::vector<ScreenVertex> v;
  std::vector<std::uint32_t> idx, objects;
  for (int t = 0; t < 20000; ++t) {
    const std::int32_t cx = px(rng), cy = py(rng);
    auto& d = t % 3 == 0 ? sliver : tiny;
    for (int k = 0; k < 3; ++k) {
      idx.push_back(static_cast<std::uint32_t>(v.size()));
      if (t % 11 == 0 && k == 2) {
        v.push_back(v.back());
        continue;
      }
      const std::int32_t dx = d(rng), dy = d(rng);  // drawn in this order on every compiler
      v.push_back(fixed_vertex(cx + dx, cy + dy));
    }
    objects.push_back(0);
  }
  // Brute force: a centre is covered when every edge function, with the vertices in
  // positive-area order, is positive or zero on a top or left edge.
  auto covers = [](const ScreenVertex& a, ScreenVertex b, ScreenVertex c, int x, int y) {
    const std::int64_t area = (std::int64_t(b.x) - a.x) * (std::int64_t(c.y) - a.y) -
                              (std::int64_t(b.y) - a.y) * (std::int64_t(c.x) - a.x);
    if (area == 0) return false;
    if (area < 0) std::swap(b, c);
    const ScreenVertex* p[3] = {&a, &b, &c};
    for (int i = 0; i < 3; ++i) {
      const ScreenVertex& u = *p[(i + 1) % 3];
      const ScreenVertex& w = *p[(i + 2) % 3];
      const std::int64_t ea = std::int64_t(u.y) - w.y, eb = std::int64_t(w.x) - u.x;
      const std::int64_t e = ea * (centre_of(x) - u.x) + eb * (centre_of(y) - u.y);
      if (e < ((ea > 0 || (ea == 0 && eb > 0)) ? 0 : 1)) return false;
    }
    return true;
  };
  const Viewport viewport{width, height};
  std::vector<SetupTriangle> kept;
  std::vector<ClipMap> maps;
  const std::size_t n = setup_triangles(v.data(), idx.data(), 0, objects.size(), objects.data(),
                                        {}, viewport, 0, 0, kept, maps);
  std::vector<std::uint8_t> is_kept(objects.size(), 0);
  for (std::size_t k = 0; k < n; ++k) is_kept[kept[k].triangle] = 1;
  std::vector<std::uint32_t> expected(std::size_t(width) * height, 0);
  std::size_t dropped_small = 0;
  for (std::size_t t = 0; t < objects.size(); ++t) {
    int covered = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (covers(v[idx[3 * t]], v[idx[3 * t + 1]], v[idx[3 * t + 2]], x, y)) {
          ++covered;
          ++expected[std::size_t(y) * width + x];
        }
    if (covered > 0) {
      EXPECT_TRUE(is_kept[t]) << "triangle " << t << " covers " << covered;
    }
    // Dropped although a sample centre lies inside its vertex box: only the coverage test
    // drops these (the box test alone keeps them).
    std::int32_t lo_x = INT32_MAX, hi_x = INT32_MIN, lo_y = INT32_MAX, hi_y = INT32_MIN;
    for (int k = 0; k < 3; ++k) {
      lo_x = std::min(lo_x, v[idx[3 * t + k]].x), hi_x = std::max(hi_x, v[idx[3 * t + k]].x);
      lo_y = std::min(lo_y, v[idx[3 * t + k]].y), hi_y = std::max(hi_y, v[idx[3 * t + k]].y);
    }
    const bool centre_in_box = (lo_x - kSubpixelOne / 2 + kSubpixelOne - 1) / kSubpixelOne <=
                                   (hi_x - kSubpixelOne / 2) / kSubpixelOne &&
                               (lo_y - kSubpixelOne / 2 + kSubpixelOne - 1) / kSubpixelOne <=
                                   (hi_y - kSubpixelOne / 2) / kSubpixelOne;
    dropped_small += !is_kept[t] && centre_in_box;
  }
  EXPECT_GT(dropped_small, 2000u);  // the coverage test is exercised
  par::Executor ex(2);
  RasterOptions opt;
  opt.count_coverage = true;
  const auto vis = rasterize_screen_vertices(ex, v, idx, objects, width, height, opt);
  EXPECT_EQ(expected, vis.coverage.pixels);
}

Camera look_at(const glm::vec3& eye, const glm::vec3& target, float fov = 45.0f) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.vfov_degrees = fov;
  c.znear = 0.05f;
  c.zfar = 100.0f;
  return c;
}

TEST(RasterWatertight, ClosedTorusFrontCoverageEqualsBackCoverage) {
  // A ray from outside a closed surface enters it as often as it leaves: per sample, the
  // number of front faces covering it equals the number of back faces. A crack or a
  // double hit on a shared edge breaks the equality.
  Scene scene;
  scene.name = "torus";
  add_torus(scene, glm::vec3(0.0f), 1.0f, 0.45f, 96, 48);
  par::Executor ex(2);
  const Camera cam = look_at({0.2f, -3.4f, 0.7f}, {0.05f, 0.02f, 0.0f});
  RasterOptions front, back;
  front.count_coverage = back.count_coverage = true;
  front.cull = CullMode::Back;   // keeps front faces
  back.cull = CullMode::Front;   // keeps back faces
  const auto f = render_visibility(ex, scene, cam, 257, 191, front);
  const auto b = render_visibility(ex, scene, cam, 257, 191, back);
  std::size_t covered = 0, twice = 0;
  for (std::size_t i = 0; i < f.coverage.size(); ++i) {
    ASSERT_EQ(f.coverage.pixels[i], b.coverage.pixels[i]) << "sample " << i;
    covered += f.coverage.pixels[i] > 0;
    twice += f.coverage.pixels[i] == 2;
  }
  EXPECT_GT(covered, f.coverage.size() / 5);
  EXPECT_GT(twice, 100u);  // the view sees through the hole: some rays cross it twice
}

// Signed distance in pixels from the centre of sample (x, y) to the image of triangle `t`
// under `cam`: the smallest over its three edges, positive inside, negative outside. Each
// edge is the plane through the eye and the edge, cut with the image plane (a line), so a
// triangle crossing the near plane needs no clipping here. In double, from the camera basis.
double signed_pixel_distance(const Scene& scene, std::uint32_t t, const Camera& cam, int w, int h,
                             int x, int y) {
  const glm::dvec3 e(cam.eye), f = glm::normalize(glm::dvec3(cam.target) - e);
  const glm::dvec3 r = glm::normalize(glm::cross(f, glm::dvec3(cam.up))), u = glm::cross(r, f);
  const double tan_half = std::tan(glm::radians(double(cam.vfov_degrees)) * 0.5);
  const double aspect = double(w) / h;
  // The sample centre on the image plane at unit depth, and pixels per image-plane unit.
  const glm::dvec3 p = f + r * ((2.0 * (x + 0.5) / w - 1.0) * tan_half * aspect) +
                       u * ((1.0 - 2.0 * (y + 0.5) / h) * tan_half);
  const double pixels_per_unit = h / (2.0 * tan_half);
  const TriangleMesh& m = scene.mesh;
  glm::dvec3 v[3];
  for (int k = 0; k < 3; ++k) v[k] = glm::dvec3(m.positions[m.indices[3 * t + k]]) - e;
  double inside = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const glm::dvec3 &a = v[k], &b = v[(k + 1) % 3], &c = v[(k + 2) % 3];
    const glm::dvec3 n = glm::cross(a, b);
    const glm::dvec3 n_image = n - glm::dot(n, f) * f;  // the line's normal within the image plane
    const double side = glm::dot(n, c);                  // the third vertex is on the inside
    if (glm::length(n_image) == 0.0 || side == 0.0) continue;
    inside = std::min(inside, std::copysign(1.0, side) * glm::dot(n, p) / glm::length(n_image) *
                                  pixels_per_unit);
  }
  return inside;
}

TEST(RasterOracle, VisibilityMatchesBruteForceRays) {
  // Overlapping random triangles in depth layers (no interpenetration) plus a floor that
  // crosses the near plane (exercises clipping).
  Scene scene;
  scene.name = "random layers";
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  // One draw per statement: a call's arguments are evaluated in an unspecified order (GCC and
  // Clang differ), and the scene must be the same with every compiler.
  const auto draw = [&](float scale) { return u(rng) * scale; };
  for (int k = 0; k < 40; ++k) {
    glm::vec3 c;
    c.x = draw(1.2f);
    c.y = draw(0.9f);
    c.z = -0.1f * k;
    std::vector<glm::vec3> p;
    for (int i = 0; i < 3; ++i) {
      glm::vec3 o;
      o.x = draw(0.6f);
      o.y = draw(0.6f);
      o.z = draw(0.04f);
      p.push_back(c + o);
    }
    add_triangles(scene, p, {0, 1, 2});
  }
  add_triangles(scene, {{-20, -1.2f, 10}, {20, -1.2f, 10}, {0, -1.2f, -30}}, {0, 1, 2});
  const Camera cam = look_at({0.1f, 0.2f, 3.0f}, {0.0f, -0.1f, -1.0f});
  const int w = 320, h = 240;
  for (int threads : {1, 2}) {
    par::Executor ex(threads);
    const auto vis = render_visibility(ex, scene, cam, w, h);
    const glm::dvec3 forward(glm::normalize(cam.target - cam.eye));
    // The oracle hit's depth along the view axis, as the visibility buffer stores depth.
    const auto oracle_depth = [&](const auto& hit, const Ray& ray) {
      return hit.t * glm::dot(glm::dvec3(ray.direction), forward);
    };
    std::size_t edge_samples = 0, mismatches_off_edge = 0, hits = 0;
    double max_depth_rel = 0, max_bary = 0, worst_outside = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const Ray ray = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
        const auto hit = testing::oracle_closest_hit(scene, ray, forward, cam.znear);
        const std::uint32_t got = vis.triangle.at(x, y);
        if (got != hit.triangle) {
          // The oracle's triangle within 2e-3 (barycentric) of an edge: an edge sample.
          if (hit.triangle != kNoId && hit.min_edge_distance < 2e-3) {
            ++edge_samples;
          } else if (hit.triangle == kNoId) {
            // A hit where the oracle sees nothing: the sample centre must lie just outside
            // (or on) an edge of the reported triangle. Vertex snapping to 1/256 pixel moves
            // each coordinate by <= 1/512 pixel, hence edges by < 1/256 pixel.
            const double d = signed_pixel_distance(scene, got, cam, w, h, x, y);
            worst_outside = std::max(worst_outside, -d);
            if (std::abs(d) <= kSnapTolerancePixels) {
              ++edge_samples;
            } else {
              ++mismatches_off_edge;
              ADD_FAILURE() << "sample " << x << "," << y << " reports triangle " << got
                            << " at " << d << " px from its edges (inside > 0); the oracle misses";
            }
          } else if (got == kNoId) {
            ++mismatches_off_edge;
            ADD_FAILURE() << "sample " << x << "," << y << " reports nothing; the oracle sees triangle "
                          << hit.triangle;
          } else {
            // Both see a triangle: the reported one may be nearer with its snapped edge just
            // over the sample centre (the same tolerance as above); otherwise it is wrong.
            const double d = signed_pixel_distance(scene, got, cam, w, h, x, y);
            if (std::abs(d) <= kSnapTolerancePixels && vis.depth.at(x, y) < oracle_depth(hit, ray)) {
              ++edge_samples;
            } else {
              ++mismatches_off_edge;
              ADD_FAILURE() << "sample " << x << "," << y << " reports triangle " << got << " at " << d
                            << " px from its edges (inside > 0); the oracle sees triangle " << hit.triangle;
            }
          }
          continue;
        }
        if (got == kNoId) continue;
        ++hits;
        // The distance helper agrees with the oracle where both see the same triangle.
        EXPECT_GE(signed_pixel_distance(scene, got, cam, w, h, x, y), -kSnapTolerancePixels)
            << x << "," << y;
        const double depth = oracle_depth(hit, ray);
        max_depth_rel = std::max(max_depth_rel, std::abs(vis.depth.at(x, y) - depth) / depth);
        max_bary = std::max({max_bary, std::abs(vis.bary.at(x, y).x - hit.b1),
                             std::abs(vis.bary.at(x, y).y - hit.b2)});
      }
    EXPECT_EQ(mismatches_off_edge, 0u);
    EXPECT_LE(edge_samples, static_cast<std::size_t>(0.001 * w * h)) << edge_samples;
    EXPECT_GT(hits, static_cast<std::size_t>(w * h / 2));
    EXPECT_LT(max_depth_rel, 1e-4);
    EXPECT_LT(max_bary, 2e-3);  // includes the sub-pixel snapping of vertices
    EXPECT_LE(worst_outside, kSnapTolerancePixels);  // 3.9e-4 px at the time of writing
    const std::string suffix = "_threads" + std::to_string(threads);
    RecordProperty("worst_outside_px" + suffix, std::to_string(worst_outside));
    RecordProperty("edge_samples" + suffix, std::to_string(edge_samples));
  }
}

TEST(RasterInterpolation, PerspectiveCorrectUvOnGrazingPlane) {
  // A 200×200 floor seen at a few degrees: uv = (x, z) scaled; the analytic uv comes from
  // intersecting each sample's ray with the plane y = 0.
  Scene scene;
  scene.name = "grazing plane";
  const float s = 100.0f;
  add_triangles(scene, {{-s, 0, -s}, {s, 0, -s}, {s, 0, s}, {-s, 0, s}}, {0, 2, 1, 0, 3, 2},
                {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  const Camera cam = look_at({0.0f, 0.4f, 0.0f}, {0.3f, 0.35f, -10.0f}, 50.0f);
  const int w = 200, h = 150;
  par::Executor ex(2);
  const auto vis = render_visibility(ex, scene, cam, w, h);
  double max_err = 0;
  std::size_t samples = 0;
  const auto& m = scene.mesh;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint32_t t = vis.triangle.at(x, y);
      if (t == kNoId) continue;
      const Ray ray = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
      if (ray.direction.y >= -1e-3f) continue;
      const double dist = -double(ray.origin.y) / double(ray.direction.y);
      const glm::dvec3 p = glm::dvec3(ray.origin) + dist * glm::dvec3(ray.direction);
      if (std::abs(p.x) > s || std::abs(p.z) > s) continue;
      const glm::dvec2 analytic((p.x + s) / (2 * s), (p.z + s) / (2 * s));
      const glm::vec2 b = vis.bary.at(x, y);
      const glm::vec2 uv = (1.0f - b.x - b.y) * m.uvs[m.indices[3 * t]] +
                           b.x * m.uvs[m.indices[3 * t + 1]] + b.y * m.uvs[m.indices[3 * t + 2]];
      // Sub-pixel vertex snapping moves uv by well under 1e-4 of the plane here.
      max_err = std::max({max_err, std::abs(uv.x - analytic.x), std::abs(uv.y - analytic.y)});
      ++samples;
    }
  EXPECT_GT(samples, std::size_t(w * h / 3));
  EXPECT_LT(max_err, 1e-3);
}

bool same_bits(const VisibilityBuffer& a, const VisibilityBuffer& b) {
  auto eq = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           std::memcmp(x.pixels.data(), y.pixels.data(), x.size() * sizeof(x.pixels[0])) == 0;
  };
  return eq(a.triangle, b.triangle) && eq(a.object, b.object) && eq(a.depth, b.depth) &&
         eq(a.bary, b.bary);
}

// Heavy overdraw with depth ties and near-plane clipping: the case where scheduling or
// early rejection could change which triangle wins.
Scene overdraw_scene() {
  Scene scene;
  scene.name = "many triangles";
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> p;
  std::vector<std::uint32_t> idx;
  for (int k = 0; k < 60000; ++k) {
    // Interpenetrating, sometimes coplanar-duplicate triangles make depth ties likely.
    const glm::vec3 c{u(rng) * 2, u(rng) * 1.5f, u(rng) * 2};
    const auto base = static_cast<std::uint32_t>(p.size());
    for (int i = 0; i < 3; ++i) p.push_back(c + 0.08f * glm::vec3{u(rng), u(rng), u(rng)});
    idx.insert(idx.end(), {base, base + 1, base + 2});
    if (k % 100 == 0) idx.insert(idx.end(), {base, base + 1, base + 2});  // exact duplicate
  }
  add_triangles(scene, p, idx);
  add_torus(scene, glm::vec3(0, 0, 1.5f), 1.0f, 0.3f, 64, 32);  // clipped by the near plane
  return scene;
}
Camera overdraw_camera() { return look_at({0.0f, 0.1f, 2.6f}, {0.0f, 0.0f, 0.0f}, 60.0f); }

TEST(RasterDeterminism, BitIdenticalAcrossThreadsAndLanes) {
  const Scene scene = overdraw_scene();
  const Camera cam = overdraw_camera();
  par::Executor ex1(1);
  const auto ref = render_visibility(ex1, scene, cam, 333, 250, {});
  for (int threads : {2, 8}) {
    par::Executor ex(threads);
    EXPECT_TRUE(same_bits(ref, render_visibility(ex, scene, cam, 333, 250, {}))) << threads;
  }
  for (int lanes : {1, 4, 8, 16}) {
    RasterOptions opt;
    opt.lanes = lanes;
    par::Executor ex(2);
    EXPECT_TRUE(same_bits(ref, render_visibility(ex, scene, cam, 333, 250, opt))) << lanes;
    // RasterOptions::lanes = 0 takes the executor's width.
    par::Executor ex_at_width(2, lanes);
    EXPECT_TRUE(same_bits(ref, render_visibility(ex_at_width, scene, cam, 333, 250, {}))) << lanes;
  }
}

// A frame large enough for the tile pass's streaming row writes, with a floor reaching far
// into the guard band (edge values beyond int32, the 8-lane path's exact doubles against the
// scalar int64 loop), a torus cut by the near plane and small triangles: the same bits at
// every lane width and thread count.
TEST(RasterDeterminism, LargeFrameWithGuardBandFloorSameBitsAtEveryWidth) {
  Scene scene;
  scene.name = "floor";
  add_triangles(scene, {{-90.0f, -1.0f, -90.0f}, {90.0f, -1.0f, -90.0f},
                        {90.0f, -1.0f, 90.0f}, {-90.0f, -1.0f, 90.0f}},
                {0, 1, 2, 0, 2, 3});
  add_torus(scene, glm::vec3(0, 0, 1.5f), 1.0f, 0.3f, 64, 32);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec3> p;
  std::vector<std::uint32_t> idx;
  for (std::uint32_t k = 0; k < 3000; ++k) {
    const glm::vec3 c{u(rng) * 2, u(rng) * 0.8f, u(rng) * 2 - 1.0f};
    for (int i = 0; i < 3; ++i) p.push_back(c + 0.05f * glm::vec3{u(rng), u(rng), u(rng)});
    idx.insert(idx.end(), {3 * k, 3 * k + 1, 3 * k + 2});
  }
  add_triangles(scene, p, idx);
  const Camera cam = look_at({0.0f, 0.4f, 2.6f}, {0.0f, -0.6f, 0.0f}, 60.0f);
  const int width = 720, height = 480;  // 345 600 samples: above the streaming threshold
  RasterOptions scalar;
  scalar.lanes = 1;
  par::Executor ex1(1);
  const auto ref = render_visibility(ex1, scene, cam, width, height, scalar);
  std::size_t floor_samples = 0;
  for (const std::uint32_t t : ref.triangle.pixels)
    floor_samples += t < 2;
  EXPECT_GT(floor_samples, std::size_t(width) * height / 10);  // the floor is drawn
  for (int lanes : {4, 8, 16})
    for (int threads : {1, 2}) {
      RasterOptions opt;
      opt.lanes = lanes;
      par::Executor ex(threads);
      EXPECT_TRUE(same_bits(ref, render_visibility(ex, scene, cam, width, height, opt)))
          << lanes << " lanes, " << threads << " threads";
    }
}

// Counting coverage rasterizes every covering triangle; without it, triangles and blocks
// behind a tile's hierarchical depth are skipped. Skipping must never change a winner.
TEST(RasterHierarchicalDepth, RejectionNeverChangesTheResult) {
  const Scene scene = overdraw_scene();
  const Camera cam = overdraw_camera();
  par::Executor ex(2);
  RasterOptions all;
  all.count_coverage = true;
  const auto full = render_visibility(ex, scene, cam, 333, 250, all);
  // The scene must give rejection something to do: many hidden layers per covered sample.
  std::size_t covered = 0, layers = 0;
  for (std::size_t i = 0; i < full.coverage.size(); ++i) {
    covered += full.coverage.pixels[i] > 0;
    layers += full.coverage.pixels[i];
  }
  ASSERT_GT(covered, std::size_t(333 * 250 / 2));
  EXPECT_GT(double(layers) / double(covered), 4.0);
  for (int lanes : {1, 8}) {
    RasterOptions opt;
    opt.lanes = lanes;
    EXPECT_TRUE(same_bits(full, render_visibility(ex, scene, cam, 333, 250, opt))) << lanes;
  }
}

// Triangle groups wholly outside a view are not set up: the visibility buffer of every cube
// face around points inside and outside three scenes, and of cameras looking along and
// across the room, is the same bytes as with every triangle set up, while groups were
// indeed left out; groups of another mesh are refused.
TEST(RasterTriangleGroups, LeavingOutGroupsOutsideTheViewChangesNoByte) {
  par::Executor ex(2);
  std::size_t views = 0, left_out = 0, groups_total = 0;
  for (const char* name : {"living-room", "sphere-in-room", "bathroom"}) {
    SCOPED_TRACE(name);
    const Scene scene = load_scene(name);
    const TriangleGroups groups = triangle_groups(ex, scene.mesh);
    const Bounds b = scene.bounds();
    std::vector<Camera> cams;
    for (const glm::vec3 at : {b.center(), b.lo + 0.2f * b.extent(), b.hi + 0.3f * b.extent()})
      for (int face = 0; face < kCubeFaces; ++face) cams.push_back(cube_face_camera(face, at, 0.01f, 100.0f));
    cams.push_back(scene.cameras.front());
    for (const Camera& cam : cams) {
      RasterOptions all, grouped;
      grouped.groups = &groups;
      RasterWorkspace w;
      VisibilityBuffer a, g;
      render_visibility(ex, scene, cam, 96, 96, all, w, a);
      render_visibility(ex, scene, cam, 96, 96, grouped, w, g);
      for (const std::uint8_t o : w.outside_groups) left_out += o;
      groups_total += w.outside_groups.size();
      ++views;
      ASSERT_EQ(a.triangle.pixels, g.triangle.pixels) << views;
      ASSERT_EQ(a.object.pixels, g.object.pixels) << views;
      ASSERT_EQ(0, std::memcmp(a.depth.pixels.data(), g.depth.pixels.data(), a.depth.size() * sizeof(float)));
      ASSERT_EQ(0, std::memcmp(a.bary.pixels.data(), g.bary.pixels.data(), a.bary.size() * sizeof(glm::vec2)));
    }
  }
  EXPECT_GT(left_out, groups_total / 2) << "a cube face sees a small part of the scene";
  const Scene other = load_scene("glossy-plane");
  const TriangleGroups groups = triangle_groups(ex, load_scene("living-room").mesh);
  RasterOptions wrong;
  wrong.groups = &groups;
  EXPECT_THROW(render_visibility(ex, other, other.cameras.front(), 32, 32, wrong), InputError);
}

TEST(RasterInput, AbsurdSizesAndCamerasThrowInputError) {
  Scene scene;
  scene.name = "tiny";
  add_triangles(scene, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  par::Executor ex(1);
  EXPECT_THROW(render_visibility(ex, scene, look_at({0, 0, 3}, {0, 0, 0}), 0, 10), InputError);
  EXPECT_THROW(render_visibility(ex, scene, look_at({0, 0, 3}, {0, 0, 0}), 100000, 10), InputError);
  EXPECT_THROW(render_visibility(ex, scene, look_at({0, 0, 3}, {0, 0, 3}), 10, 10), InputError);
}


TEST(RasterInput, OverflowingCoordinatesAreDroppedNotUndefined) {
  // Finite but huge vertices overflow clip space to inf/NaN: such triangles are dropped
  // and the rest of the image is unaffected.
  Scene scene;
  scene.name = "huge";
  testing::add_triangles(scene, {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}}, {0, 1, 2});
  Scene with_huge = scene;
  testing::add_triangles(with_huge, {{3e38f, 0, 0}, {0, -3e38f, 1}, {0, 0, -3e38f}}, {0, 1, 2});
  Camera cam;
  cam.eye = {0, 0, 3};
  par::Executor ex(2);
  const auto a = render_visibility(ex, scene, cam, 64, 64);
  const auto b = render_visibility(ex, with_huge, cam, 64, 64);
  for (std::size_t i = 0; i < a.triangle.size(); ++i)
    if (b.triangle.pixels[i] != 1u) {
      EXPECT_EQ(a.triangle.pixels[i], b.triangle.pixels[i]);
    }
}


// The batched vertex stage (8 vertices per AVX2 step plus a scalar tail) must give every
// vertex the bytes of the one-vertex function, including vertices behind the eye, outside
// the guard band, exactly on clip planes and overflowing to inf/NaN.
TEST(RasterVertexStage, BatchedEqualsOneVertexFunctionBitForBit) {
  Camera cam;
  cam.eye = {0.3f, 0.2f, 3.0f};
  cam.znear = 0.1f;
  cam.zfar = 50.0f;
  const int width = 333, height = 250;
  const glm::mat4 vp = projection_matrix(cam, width, height) * view_matrix(cam);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> near_box(-4.0f, 4.0f), far_box(-3000.0f, 3000.0f);
  std::vector<glm::vec3> positions;
  for (int i = 0; i < 997; ++i)  // not a multiple of 8: exercises the tail
    positions.push_back(i % 3 ? glm::vec3{near_box(rng), near_box(rng), near_box(rng)}
                              : glm::vec3{far_box(rng), far_box(rng), far_box(rng)});
  positions.push_back(cam.eye);                        // w = 0
  positions.push_back({0.3f, 0.2f, 3.0f - cam.znear}); // on the near plane
  positions.push_back({3e38f, 0.0f, 0.0f});            // overflows to inf
  positions.push_back({-3e38f, 3e38f, -3e38f});
  positions.push_back({std::nanf(""), 0.0f, 0.0f});
  const Viewport viewport{width, height};
  std::vector<ScreenVertex> batched(positions.size());
  make_screen_vertices(vp, positions.data(), positions.size(), viewport, batched.data());
  std::size_t needs_clip = 0, snapped = 0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const ScreenVertex one = make_screen_vertex(vp * glm::vec4(positions[i], 1.0f), viewport);
    EXPECT_EQ(0, std::memcmp(&one, &batched[i], sizeof(ScreenVertex))) << i;
    (one.outcode & kNeedsClip ? needs_clip : snapped) += 1;
  }
  EXPECT_GT(needs_clip, 50u);  // both outcomes are exercised
  EXPECT_GT(snapped, 300u);
}


// The chunked, branch-free setup equals setup_triangle called per triangle: same records
// (bytes), same clip maps, for every cull mode and with excluded objects; the vertices
// include ones needing clipping, tiny triangles covering no sample and degenerate ones.
TEST(RasterSetup, ChunkedSetupEqualsPerTriangleSetup) {
  Camera cam;
  cam.eye = {0.0f, 0.0f, 2.0f};
  cam.znear = 0.5f;
  const int width = 200, height = 150;
  const glm::mat4 vp = projection_matrix(cam, width, height) * view_matrix(cam);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> box(-2.5f, 2.5f), small(-0.01f, 0.01f);
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices, objects;
  for (std::uint32_t t = 0; t < 3000; ++t) {
    const glm::vec3 c{box(rng), box(rng), box(rng)};
    const float s = t % 4 == 0 ? 150.0f : 1.0f;  // some large triangles cross the near plane
    for (int k = 0; k < 3; ++k) {
      indices.push_back(static_cast<std::uint32_t>(positions.size()));
      positions.push_back(t % 7 == 0 && k == 2 ? positions[positions.size() - 1]  // degenerate
                                               : c + s * glm::vec3{small(rng), small(rng), small(rng)});
    }
    objects.push_back(t % 5);
  }
  const Viewport viewport{width, height};
  std::vector<ScreenVertex> vertices(positions.size());
  make_screen_vertices(vp, positions.data(), positions.size(), viewport, vertices.data());
  const std::vector<std::uint8_t> excluded{0, 0, 1};  // object 2 left out; 3, 4 beyond the flags
  for (int cull : {-1, 0, 1}) {
    for (const auto& skip : {std::vector<std::uint8_t>{}, excluded}) {
      std::vector<SetupTriangle> one, chunked(5);  // chunked writes after 5 existing records
      std::vector<ClipMap> one_maps, chunked_maps;
      for (std::size_t t = 0; t < objects.size(); ++t) {
        if (!skip.empty() && objects[t] < skip.size() && skip[objects[t]]) continue;
        const std::uint32_t* idx = &indices[3 * t];
        setup_triangle(vertices[idx[0]], vertices[idx[1]], vertices[idx[2]],
                       static_cast<std::uint32_t>(t), objects[t], viewport, cull, one, one_maps);
      }
      const std::size_t end = setup_triangles(vertices.data(), indices.data(), 0,
                                              objects.size(), objects.data(), skip, viewport,
                                              cull, 5, chunked, chunked_maps);
      ASSERT_EQ(one.size() + 5, end) << cull;
      ASSERT_GE(chunked.size(), end);
      ASSERT_EQ(one_maps.size(), chunked_maps.size()) << cull;
      EXPECT_GE(one_maps.size(), 5u);  // clipping is exercised
      EXPECT_EQ(0, std::memcmp(one.data(), chunked.data() + 5, one.size() * sizeof(SetupTriangle)))
          << cull;
      EXPECT_EQ(0, std::memcmp(one_maps.data(), chunked_maps.data(),
                               one_maps.size() * sizeof(ClipMap)))
          << cull;
    }
  }
}


// setup_triangles sets up 8 triangles at a time in AVX2 lanes when none of them needs
// clipping or is excluded. Its records must equal the scalar setup_triangle's byte for byte:
// here on snapped vertices built directly in fixed point — slivers around sample centres
// (vertices and edges exactly on centres: the top-left rule's ties), zero-area and collinear
// triangles, triangles reaching the guard band (64-bit edge values), huge ones whose box is
// clamped to a corner of the viewport, outcodes that reject trivially, and a few vertices that
// need clipping (their groups take the scalar path) — for every cull mode, with excluded
// objects, and from starts and ends that are not multiples of 8.
TEST(RasterSetup, LaneSetupEqualsScalarSetupRecordForRecord) {
  const int width = 96, height = 80;
  const Viewport viewport{width, height};
  std::mt19937 rng(29);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  const std::int32_t guard = static_cast<std::int32_t>(kGuardBandPixels) * kSubpixelOne;
  auto snapped = [&](std::int32_t x, std::int32_t y) {
    ScreenVertex v = fixed_vertex(x, y);
    v.inv_w = std::uniform_real_distribution<float>(0.01f, 2.0f)(rng);
    v.outcode = (x < 0 ? 1u : 0u) | (x > width * kSubpixelOne ? 2u : 0u) | (y < 0 ? 4u : 0u) |
                (y > height * kSubpixelOne ? 8u : 0u);
    return v;
  };
  // Offsets that land on sample centres and half-way between them as often as elsewhere.
  auto jitter = [&](int range) {
    return uniform(0, 1) ? uniform(-range, range) : uniform(-range / 128, range / 128) * 128;
  };
  std::vector<ScreenVertex> vertices;
  std::vector<std::uint32_t> indices, objects;
  const int count = 20000;
  for (int t = 0; t < count; ++t) {
    ScreenVertex v[3];
    const int kind = (t / 8 + t % 3) % 10;  // runs of one kind: all-small groups too
    if (kind <= 5) {  // slivers and small triangles around sample centres
      const std::int32_t x = centre_of(uniform(-2, width + 1)) + jitter(256);
      const std::int32_t y = centre_of(uniform(-2, height + 1)) + jitter(256);
      const int reach = kind < 3 ? 300 : 1200;
      for (int k = 0; k < 3; ++k) v[k] = snapped(x + (k ? jitter(reach) : 0), y + (k ? jitter(reach) : 0));
    } else if (kind == 6) {  // zero area: a repeated vertex or three collinear ones
      const std::int32_t x = centre_of(uniform(0, width - 1)), y = centre_of(uniform(0, height - 1));
      const std::int32_t dx = jitter(2000), dy = jitter(2000);
      v[0] = snapped(x, y), v[1] = snapped(x + dx, y + dy);
      v[2] = uniform(0, 1) ? v[1] : snapped(x + 2 * dx, y + 2 * dy);
    } else if (kind == 7) {  // reaching the guard band
      for (auto& u : v)
        u = snapped(uniform(-guard, width * kSubpixelOne + guard),
                    uniform(-guard, height * kSubpixelOne + guard));
    } else if (kind == 8) {  // huge, boxed into a corner of the viewport
      const std::int32_t cx = uniform(0, 1) ? -guard + 5 : width * kSubpixelOne + guard - 5;
      const std::int32_t cy = uniform(0, 1) ? -guard + 7 : height * kSubpixelOne + guard - 7;
      v[0] = snapped(uniform(0, 1) ? centre_of(0) + jitter(200) : centre_of(width - 1) + jitter(200),
                     uniform(0, 1) ? centre_of(0) + jitter(200) : centre_of(height - 1) + jitter(200));
      v[1] = snapped(cx, v[0].y + jitter(300));
      v[2] = snapped(v[0].x + jitter(300), cy);
    } else {  // mostly small; one group in five has a vertex that needs clipping
      const std::int32_t x = centre_of(uniform(0, width - 1)), y = centre_of(uniform(0, height - 1));
      for (int k = 0; k < 3; ++k) v[k] = snapped(x + jitter(600), y + jitter(600));
      if (t % 50 == 9) {  // a triangle through the near plane, in clip space
        std::uniform_real_distribution<float> d(-0.5f, 0.5f);
        v[0] = make_screen_vertex(glm::vec4{d(rng), d(rng), 0.5f, 1.0f}, viewport);
        v[1] = make_screen_vertex(glm::vec4{d(rng), d(rng), 0.5f, 1.0f}, viewport);
        v[2] = make_screen_vertex(glm::vec4{d(rng), d(rng), 0.2f, -0.5f}, viewport);
      }
    }
    for (const ScreenVertex& u : v) {
      indices.push_back(static_cast<std::uint32_t>(vertices.size()));
      vertices.push_back(u);
    }
    objects.push_back(static_cast<std::uint32_t>(t / 24 % 3));
  }
  const std::vector<std::uint8_t> excluded{0, 1};  // object 1 left out, 2 beyond the flags
  std::size_t kept_total = 0, clipped_total = 0;
  for (int cull : {-1, 0, 1}) {
    for (const auto& skip : {std::vector<std::uint8_t>{}, excluded}) {
      for (const auto& [begin, end] : {std::pair{0, count}, {3, count - 5}, {13, 13 + 8 * 37}}) {
        std::vector<SetupTriangle> scalar, lanes(3);  // lanes writes after 3 existing records
        std::vector<ClipMap> scalar_maps, lane_maps;
        for (int t = begin; t < end; ++t) {
          if (!skip.empty() && objects[t] < skip.size() && skip[objects[t]]) continue;
          const std::uint32_t* idx = &indices[3 * std::size_t(t)];
          setup_triangle(vertices[idx[0]], vertices[idx[1]], vertices[idx[2]],
                         static_cast<std::uint32_t>(t), objects[t], viewport, cull, scalar,
                         scalar_maps);
        }
        const std::size_t n = setup_triangles(vertices.data(), indices.data(), begin, end,
                                              objects.data(), skip, viewport, cull, 3, lanes,
                                              lane_maps);
        ASSERT_EQ(scalar.size() + 3, n) << cull << " " << begin;
        ASSERT_EQ(scalar_maps.size(), lane_maps.size());
        EXPECT_EQ(0, std::memcmp(scalar.data(), lanes.data() + 3, scalar.size() * sizeof(SetupTriangle)))
            << cull << " " << begin;
        EXPECT_EQ(0, std::memcmp(scalar_maps.data(), lane_maps.data(),
                                 scalar_maps.size() * sizeof(ClipMap)));
        kept_total += scalar.size();
        clipped_total += scalar_maps.size();
      }
    }
  }
  // Both outcomes and the clipping fallback are exercised.
  EXPECT_GT(kept_total, 30000u);
  EXPECT_LT(kept_total, 3u * 2u * 2u * count);
  EXPECT_GT(clipped_total, 20u);
}


// Triangles whose box spans at most 4 × 2 pixels of a tile take a one-register 8-lane path
// (two rows of four samples). It must give the bits of the scalar reference (lanes 1): here
// thousands of such triangles over the last rows and columns of the tiles (the one-row case
// on a tile's last row, lanes past the row end), vertices and edges on sample centres (the
// top-left rule's ties) and equal depths (ties broken by the triangle index), with slivers
// that cover no sample between them.
TEST(RasterDeterminism, TinyTrianglesAtTileEdgesSameBitsAsScalar) {
  const int width = 200, height = 140;  // partial tiles on the right and at the bottom
  std::mt19937 rng(17);
  auto uniform = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  auto near_tile_edge = [&](int size) {
    const int tile = uniform(0, (size - 1) / kTileSize) * kTileSize;
    return std::clamp(tile + uniform(-3, 3) + (uniform(0, 1) ? kTileSize - 1 : 0), 0, size - 1);
  };
  std::vector<ScreenVertex> vertices;
  std::vector<std::uint32_t> indices, objects;
  for (std::uint32_t t = 0; t < 30000; ++t) {
    const int px = uniform(0, 3) ? near_tile_edge(width) : uniform(0, width - 1);
    const int py = uniform(0, 3) ? near_tile_edge(height) : uniform(0, height - 1);
    const bool flat_depth = t % 3 == 0;  // equal 1/w everywhere: depth ties across triangles
    for (int k = 0; k < 3; ++k) {
      const int reach = t % 2 ? 384 : 900;
      const int jx = uniform(0, 1) ? uniform(-reach, reach) : uniform(-reach / 128, reach / 128) * 128;
      const int jy = uniform(0, 1) ? uniform(-reach, reach) : uniform(-reach / 128, reach / 128) * 128;
      ScreenVertex v = fixed_vertex(centre_of(px) + jx, centre_of(py) + jy);
      v.inv_w = flat_depth ? 0.5f : std::uniform_real_distribution<float>(0.2f, 1.0f)(rng);
      indices.push_back(static_cast<std::uint32_t>(vertices.size()));
      vertices.push_back(v);
    }
    objects.push_back(t % 7);
  }
  par::Executor ex(2);
  RasterOptions scalar;
  scalar.lanes = 1;
  const auto ref = rasterize_screen_vertices(ex, vertices, indices, objects, width, height, scalar);
  std::size_t covered = 0;
  for (const std::uint32_t id : ref.triangle.pixels) covered += id != kNoId;
  EXPECT_GT(covered, std::size_t(width) * height / 3);
  for (int lanes : {4, 8, 16}) {
    RasterOptions opt;
    opt.lanes = lanes;
    EXPECT_TRUE(same_bits(ref, rasterize_screen_vertices(ex, vertices, indices, objects, width,
                                                         height, opt)))
        << lanes;
  }
}

}  // namespace
}  // namespace speculum::raster
