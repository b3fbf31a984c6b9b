// Tests of second-order feed-forward reflections (SOFF): clustering bounds and partition
// (§3.2), the corrected eq.1 of the cluster camera (§3.3), the depth images whichever way
// each is rendered (§3.1), the depth-image walk on an analytic ramp (§3.4), a planar cluster
// against the planar-mirror technique, and the specular error against the exact specular
// reference.
#include "raster/soff.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <set>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/camera_rays.h"
#include "core/image_metrics.h"
#include "core/optics.h"
#include "core/procedural_geometry.h"
#include "core/scene_loader.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::raster {
namespace {

using namespace speculum::procedural;

Camera look(glm::vec3 eye, glm::vec3 target, float vfov, glm::vec3 up = {0, 1, 0}) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.vfov_degrees = vfov;
  c.znear = 0.05f;
  c.zfar = 100.0f;
  return c;
}

Scene mirror_sphere() {
  SceneBuilder b("mirror sphere");
  const auto m = b.add_material(mirror("chrome"));
  b.add_object("sphere", m, sphere({0, 0, 0}, 1.0f, 96));
  Scene s = b.take();
  s.environment.constant = glm::vec3(0.2f);
  return s;
}

GBuffer gbuffer_of(par::Executor& ex, const Scene& s, const Camera& c, int w, int h) {
  return resolve_gbuffer(ex, s, render_visibility(ex, s, c, w, h), c.eye);
}

// SOFF §3.2: "a single large sphere that covers the entire screen" gives at most
// 13 × 8 / 2 = 52 clusters, seen from the side or down the pole.
TEST(SoffClusters, FullScreenMirrorSphereGivesAtMost52) {
  par::Executor ex(2);
  const Scene s = mirror_sphere();
  // The sphere's angular radius from distance 3 is 19.5°; a 25° field of view keeps even
  // the image corners (17.4° off axis) on it.
  for (const Camera& c : {look({0, 0, 3}, {0, 0, 0}, 25.0f), look({0, 3, 0}, {0, 0, 0}, 25.0f, {0, 0, -1}),
                          look({1.8f, 1.5f, 1.8f}, {0, 0, 0}, 25.0f)}) {
    const GBuffer g = gbuffer_of(ex, s, c, 128, 128);
    for (std::size_t i = 0; i < g.object.size(); ++i) ASSERT_TRUE(g.covered(i)) << "the sphere must fill the screen";
    const SoffClusters cl = soff_cluster(ex, g, {});
    EXPECT_LE(cl.count(), 52u) << "eye " << c.eye.x << "," << c.eye.y << "," << c.eye.z;
    EXPECT_GE(cl.count(), 4u);
    EXPECT_EQ(cl.visible_reflectors, 1);
  }
}

// Every non-diffuse sample belongs to exactly one cluster: the per-cluster lists partition
// the reflecting samples, agree with the per-sample ids, and the sums are theirs.
TEST(SoffClusters, EveryReflectingSampleInExactlyOneCluster) {
  par::Executor ex(2);
  const Scene s = load_scene("living-room:size=20000");
  const GBuffer g = gbuffer_of(ex, s, s.cameras.front(), 160, 120);
  const SoffClusters cl = soff_cluster(ex, g, {});
  ASSERT_GT(cl.count(), 10u);
  std::vector<int> seen(g.object.size(), 0);
  for (std::size_t c = 0; c < cl.count(); ++c) {
    ASSERT_GT(cl.size_of(c), 0u);
    glm::dvec3 sum(0.0);
    for (std::uint32_t k = cl.offsets[c]; k < cl.offsets[c + 1]; ++k) {
      const std::uint32_t i = cl.samples[k];
      ++seen[i];
      EXPECT_EQ(cl.cluster[i], c);
      EXPECT_EQ(g.object.pixels[i], cl.reflector[c]) << "a cluster spans one reflector";
      sum += glm::dvec3(g.position.pixels[i]);
    }
    EXPECT_EQ(sum, cl.sum_position[c]);
  }
  std::size_t reflecting = 0;
  for (std::size_t i = 0; i < g.object.size(); ++i) {
    const bool r = g.covered(i) && soff_reflects(g.surface[i]);
    reflecting += r;
    EXPECT_EQ(seen[i], r ? 1 : 0) << "sample " << i;
    EXPECT_EQ(cl.cluster[i] != kNoId, r);
  }
  EXPECT_EQ(cl.samples.size(), reflecting);
}

TEST(SoffClusters, SameBytesForAnyThreadCount) {
  const Scene s = load_scene("living-room:size=20000");
  par::Executor one(1), two(2), eight(8);
  const GBuffer g = gbuffer_of(two, s, s.cameras.front(), 160, 120);
  const SoffClusters a = soff_cluster(one, g, {}), b = soff_cluster(two, g, {}), c = soff_cluster(eight, g, {});
  for (const SoffClusters* x : {&b, &c}) {
    EXPECT_EQ(a.cluster, x->cluster);
    EXPECT_EQ(a.offsets, x->offsets);
    EXPECT_EQ(a.samples, x->samples);
    ASSERT_EQ(a.sum_position.size(), x->sum_position.size());
    EXPECT_EQ(0, std::memcmp(a.sum_position.data(), x->sum_position.data(), a.sum_position.size() * sizeof(glm::dvec3)));
    EXPECT_EQ(0, std::memcmp(a.sum_normal.data(), x->sum_normal.data(), a.sum_normal.size() * sizeof(glm::dvec3)));
  }
  // Cameras too (they read the clusters in a fixed order).
  SoffCameraSettings cs;
  cs.scene_diameter = 10.0f;
  const SoffCameras ca = soff_cameras(one, g, a, cs), cb = soff_cameras(eight, g, a, cs);
  ASSERT_EQ(ca.size(), cb.size());
  for (std::size_t k = 0; k < ca.size(); ++k) {
    EXPECT_EQ(ca[k].eye, cb[k].eye);
    EXPECT_EQ(ca[k].width, cb[k].width);
    EXPECT_EQ(ca[k].l, cb[k].l);
  }
}

// The depth images are rendered by two paths (large ones one at a time across the threads,
// small ones several at once on per-thread scratch kept across images and frames): every
// image has the bytes of rendering it alone, whatever ran on its thread before.
TEST(SoffDepthImages, EveryImageHasTheBytesOfRenderingItAlone) {
  const Scene s = load_scene("living-room:size=20000");
  par::Executor two(2), three(3);
  const GBuffer g = gbuffer_of(two, s, s.cameras.front(), 640, 480);
  const SoffClusters clusters = soff_cluster(two, g, {});
  SoffCameraSettings cs;
  cs.scene_diameter = glm::length(s.bounds().extent());
  const SoffCameras cameras = soff_cameras(two, g, clusters, cs);
  const EnvironmentMap env = build_environment(two, s.environment, 8);
  const std::vector<ShadowMap> shadows = render_shadow_maps(two, s, 256);
  const SoffDepthImages all = soff_depth_images(two, s, clusters, cameras, shadows, env);
  std::size_t large = 0, small = 0;
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    if (!cameras[k].valid) continue;
    const std::size_t pixels = all.offsets[k + 1] - all.offsets[k];
    (pixels >= 16384 ? large : small) += 1;
    SoffCameras one_camera = cameras;
    for (std::size_t j = 0; j < one_camera.size(); ++j) one_camera[j].valid = j == k;
    const SoffDepthImages alone = soff_depth_images(k % 2 ? two : three, s, clusters, one_camera, shadows, env);
    ASSERT_EQ(alone.pixels, pixels);
    const std::size_t at = all.offsets[k];
    EXPECT_EQ(0, std::memcmp(&all.inv_z[at], alone.inv_z.data(), pixels * sizeof(float))) << "image " << k;
    EXPECT_EQ(0, std::memcmp(&all.colour[at], alone.colour.data(), pixels * sizeof(glm::vec3))) << "image " << k;
    EXPECT_EQ(0, std::memcmp(&all.normal[at], alone.normal.data(), pixels * sizeof(glm::vec3))) << "image " << k;
    for (std::size_t i = 0; i < pixels; ++i)
      ASSERT_EQ(0, std::memcmp(&all.surface[at + i], &alone.surface[i], sizeof(SurfaceParams)))
          << "image " << k << " pixel " << i;
  }
  EXPECT_GE(large, 1u) << "no image took the shared path";
  EXPECT_GE(small, 20u) << "too few images took the per-thread path";
}

// The bin scale is the calibrated gain × a_R[%] / n_v, clamped to 1.
TEST(SoffClusters, BinScaleCalibration) {
  EXPECT_EQ(soff_bin_scale(100.0, 1), 1.0f);
  EXPECT_FLOAT_EQ(soff_bin_scale(2.0, 4), 0.5f);
  EXPECT_FLOAT_EQ(soff_bin_scale(2.0, 64, 16.0), 0.5f);
  EXPECT_EQ(soff_bin_scale(100.0, 1, 16.0), 1.0f) << "a full-screen reflector keeps the paper's ≤ 52 bins";
  int i = -1, j = -1;
  soff_bin(glm::vec3(0, 1, 0), 1.0f, {}, i, j);
  EXPECT_EQ(j, 0);
  soff_bin(glm::vec3(0, -1, 0), 1.0f, {}, i, j);
  EXPECT_EQ(j, 7) << "the polar bin of a downward normal is clamped to MAXPHIBINS − 1";
  soff_bin(glm::normalize(glm::vec3(0, 0, -1)), 1.0f, {}, i, j);
  EXPECT_EQ(i, 9);  // θ = 270°: floor(13 · 0.75)
}

// A cluster's samples on a grid with their normals, reflected directions for `eye`, and
// row neighbours.
struct SyntheticCluster {
  std::vector<glm::vec3> p, n, r;
  std::vector<SoffPair> pairs;
};
SyntheticCluster synthetic(const glm::vec3& eye, int side, float half, float curvature) {
  SyntheticCluster c;
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x) {
      const float a = -half + 2.0f * half * float(x) / float(side - 1);
      const float b = -half + 2.0f * half * float(y) / float(side - 1);
      // On a sphere of radius 1/curvature around (0, 0, −1/curvature), or the plane z = 0.
      glm::vec3 p(a, b, 0.0f), n(0, 0, 1);
      if (curvature > 0.0f) {
        const float R = 1.0f / curvature;
        n = glm::normalize(glm::vec3(a, b, R));
        p = glm::vec3(0, 0, -R) + R * n;
      }
      c.p.push_back(p);
      c.n.push_back(n);
      c.r.push_back(reflect(glm::normalize(p - eye), n));
      const auto k = std::uint32_t(c.p.size() - 1);
      if (x > 0) c.pairs.push_back({k - 1, k, false});
      if (y > 0) c.pairs.push_back({k - std::uint32_t(side), k, true});
    }
  return c;
}

// SOFF §3.3: for a planar cluster the near and far endpoints project from e0 to the same
// points, so d_n = d_f, eq.1 gives f = 1 and the corrected form keeps the eye at e0
// (the printed form would put it on the cluster).
TEST(SoffCameras, PlanarClusterEyeIsTheMirroredEye) {
  EXPECT_EQ(soff_eq1(2.0f, 2.0f, 9.0f), 1.0f);
  const glm::vec3 eye(0.3f, 0.2f, 2.0f);
  const SyntheticCluster c = synthetic(eye, 9, 0.4f, 0.0f);
  SoffCameraSettings s;
  const SoffCamera cam = soff_camera(eye, c.p, c.n, c.r, c.pairs, 0.0f, 20.0f, s);
  ASSERT_TRUE(cam.valid);
  EXPECT_NEAR(cam.f, 1.0f, 1e-4f);
  EXPECT_NEAR(glm::length(cam.eye - glm::vec3(0.3f, 0.2f, -2.0f)), 0.0f, 1e-4f);
  EXPECT_NEAR(cam.d_n, cam.d_f, 1e-4f * cam.d_n);
  // The near endpoints lie on the image plane, so their frame from e0 is the cluster's own
  // box: diagonal 2·0.4·√2.
  EXPECT_NEAR(cam.d_n, 0.8f * std::sqrt(2.0f), 1e-4f);
  EXPECT_FALSE(cam.concave);
  // The camera rays are the reflected rays: every far endpoint projects onto its sample.
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    const glm::vec3 a = cam.project(c.p[i]), b = cam.project(c.p[i] + 7.0f * c.r[i]);
    EXPECT_NEAR(a.x, b.x, 1e-2f);
    EXPECT_NEAR(a.y, b.y, 1e-2f);
  }
}

// The corrected eq.1 moves the eye so that the far endpoints' frame diagonal seen from e_c
// equals d_n (exact for a cluster viewed head-on, where e0 − P_c is along n_c).
TEST(SoffCameras, Eq1MakesTheFarFrameDiagonalEqualDn) {
  const glm::vec3 eye(0.0f, 0.0f, 3.0f);
  const SyntheticCluster c = synthetic(eye, 11, 0.2f, 1.0f);  // a unit-sphere cap
  SoffCameraSettings s;
  const float D = 30.0f;
  const SoffCamera cam = soff_camera(eye, c.p, c.n, c.r, c.pairs, 0.0f, D, s);
  ASSERT_TRUE(cam.valid);
  EXPECT_GT(cam.f, 0.0f);
  EXPECT_LT(cam.f, 1.0f) << "a convex cluster's eye moves from e0 towards P_c";
  EXPECT_FALSE(cam.concave);
  float lo_x = 1e30f, hi_x = -1e30f, lo_y = 1e30f, hi_y = -1e30f;
  for (std::size_t i = 0; i < c.p.size(); ++i) {
    const float d = glm::dot(c.p[i] - cam.centre, cam.normal);
    const glm::vec3 far = c.p[i] + c.r[i] * ((D - d) / glm::dot(c.r[i], cam.normal));
    const glm::vec3 q = far - cam.eye;
    const float z = glm::dot(q, cam.w);
    const float x = glm::dot(q, cam.u) * cam.near_dist / z, y = glm::dot(q, cam.v) * cam.near_dist / z;
    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x), lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
  }
  const float diagonal = std::hypot(hi_x - lo_x, hi_y - lo_y);
  EXPECT_NEAR(diagonal, cam.d_n, 0.03f * cam.d_n);
  // A concave cap (the same cap seen from inside the sphere) is detected as SOFF §4.4 says.
  SyntheticCluster concave = c;
  for (std::size_t i = 0; i < concave.p.size(); ++i) {
    concave.p[i].z = -concave.p[i].z;
    concave.n[i] = glm::vec3(-c.n[i].x, -c.n[i].y, c.n[i].z);
    concave.r[i] = reflect(glm::normalize(concave.p[i] - eye), concave.n[i]);
  }
  const SoffCamera cc = soff_camera(eye, concave.p, concave.n, concave.r, concave.pairs, 0.0f, D, s);
  ASSERT_TRUE(cc.valid);
  EXPECT_TRUE(cc.concave);
}

// A depth-image camera at the origin looking down +z, a 90° frame on its near plane at 1,
// far plane at 20, width × height pixels.
SoffCamera camera_down_z(int width, int height) {
  SoffCamera cam;
  cam.valid = true;
  cam.eye = glm::vec3(0.0f);
  cam.u = {1, 0, 0}, cam.v = {0, 1, 0}, cam.w = {0, 0, 1};
  cam.near_dist = 1.0f, cam.far_dist = 20.0f;
  cam.l = -1, cam.r = 1, cam.b = -1, cam.t = 1;
  cam.width = width, cam.height = height;
  return cam;
}

// SOFF §3.4 on an analytic depth image: the plane z = 3 + x seen by a camera at the origin
// looking down +z; a ray's walk finds the analytic crossing within a pixel.
TEST(SoffIntersect, DepthRampWalkFindsTheAnalyticCrossing) {
  const SoffCamera cam = camera_down_z(128, 128);
  std::vector<float> inv_z(128 * 128);
  // The plane z = 3 + 0.5 x, i.e. along the camera ray (X, Y, 1)·z: z = 3 / (1 − 0.5 X).
  for (int y = 0; y < 128; ++y)
    for (int x = 0; x < 128; ++x) {
      const glm::vec3 d = cam.pixel_direction(float(x) + 0.5f, float(y) + 0.5f);
      const float X = d.x / d.z;
      inv_z[std::size_t(y) * 128 + std::size_t(x)] = (1.0f - 0.5f * X) / 3.0f;
    }
  const glm::vec3 origins[] = {{-0.5f, 0.2f, 1.2f}, {0.4f, -0.3f, 1.0f}, {0.0f, 0.0f, 1.5f}};
  const glm::vec3 dirs[] = {glm::normalize(glm::vec3(0.3f, -0.1f, 1.0f)), glm::normalize(glm::vec3(-0.4f, 0.2f, 1.0f)),
                            glm::normalize(glm::vec3(0.05f, 0.6f, 1.0f))};
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 o = origins[k], d = dirs[k];
    // o + t d on z = 3 + 0.5 x: o.z + t d.z = 3 + 0.5 (o.x + t d.x).
    const float t = (3.0f + 0.5f * o.x - o.z) / (d.z - 0.5f * d.x);
    const glm::vec3 expect = cam.project(o + t * d);
    const SoffWalkResult r = soff_walk(cam, inv_z.data(), o, d);
    ASSERT_EQ(r.kind, SoffWalkResult::Hit) << "ray " << k;
    EXPECT_NEAR(r.sx, expect.x, 1.0f) << "ray " << k;
    EXPECT_NEAR(r.sy, expect.y, 1.0f) << "ray " << k;
    EXPECT_GT(r.steps, 3u);
  }
  // A ray that climbs slower than the plane leaves the image without a hit.
  const SoffWalkResult miss = soff_walk(cam, inv_z.data(), {0.0f, 0.0f, 1.0f}, glm::normalize(glm::vec3(1.0f, 0.0f, 0.4f)));
  EXPECT_EQ(miss.kind, SoffWalkResult::Miss);
  // An occluder in front of the plane over a band of columns: a ray that passes behind it is
  // disoccluded, not hit on the occluder's silhouette.
  std::vector<float> occluded = inv_z;
  for (int y = 0; y < 128; ++y)
    for (int x = 70; x < 80; ++x) occluded[std::size_t(y) * 128 + std::size_t(x)] = 1.0f / 1.1f;
  const SoffWalkResult hidden =
      soff_walk(cam, occluded.data(), {0.0f, 0.0f, 1.0f}, glm::normalize(glm::vec3(0.3f, 0.0f, 1.0f)));
  EXPECT_EQ(hidden.kind, SoffWalkResult::Disoccluded);
}

// The walk's definition, one step at a time (SOFF §3.4): the oracle of the walk below.
SoffWalkResult walk_one_step_at_a_time(const SoffCamera& cam, const float* inv_z, const glm::vec3& p,
                                       const glm::vec3& d) {
  SoffWalkResult res;
  const float dz = glm::dot(d, cam.w);
  if (!(dz > 1e-4f)) {
    res.kind = SoffWalkResult::Unrepresentable;
    return res;
  }
  const float zp = glm::dot(p - cam.eye, cam.w);
  const glm::vec3 start = zp < cam.near_dist ? p + d * ((cam.near_dist - zp) / dz) : p;
  const glm::vec3 end = p + d * ((cam.far_dist - zp) / dz);
  const glm::vec3 a = cam.project(start), b = cam.project(end);
  const float dx = b.x - a.x, dy = b.y - a.y;
  const int w = cam.width, h = cam.height;
  const int steps = std::max(1, int(std::ceil(std::max(std::abs(dx), std::abs(dy)))));
  auto stored = [&](float sx, float sy, bool& inside) {
    const int ix = int(std::floor(sx)), iy = int(std::floor(sy));
    inside = ix >= 0 && iy >= 0 && ix < w && iy < h;
    return inside ? inv_z[std::size_t(iy) * std::size_t(w) + std::size_t(ix)] : 0.0f;
  };
  bool inside = true;
  float ray_a = a.z, di_a = stored(a.x, a.y, inside);
  if (!inside) return res;
  float prev_jump = 0.0f;
  bool hidden = false;
  for (int k = 1; k <= steps; ++k) {
    const float s = float(k) / float(steps);
    const float sx = a.x + dx * s, sy = a.y + dy * s;
    const float ray_b = a.z + (b.z - a.z) * s;
    const float di_b = stored(sx, sy, inside);
    ++res.steps;
    if (!inside) break;
    const float da = ray_a - di_a, db = ray_b - di_b;
    const float jump = di_b - di_a;
    if (da > 0.0f && db <= 0.0f) {
      const bool silhouette = di_b > ray_a && jump > 2.0f * std::max(std::abs(prev_jump), ray_a - ray_b);
      if (!silhouette) {
        const float frac = da / (da - db);
        const float s_hit = (float(k - 1) + frac) / float(steps);
        res.kind = SoffWalkResult::Hit;
        res.sx = a.x + dx * s_hit;
        res.sy = a.y + dy * s_hit;
        res.inv_z = a.z + (b.z - a.z) * s_hit;
        return res;
      }
      if (!hidden) res.sx = a.x + dx * (float(k - 1) / float(steps)), res.sy = a.y + dy * (float(k - 1) / float(steps));
      hidden = true;
    }
    prev_jump = jump;
    ray_a = ray_b;
    di_a = di_b;
  }
  res.kind = hidden ? SoffWalkResult::Disoccluded : SoffWalkResult::Miss;
  return res;
}

// soff_walk takes eight steps at a time in lanes while none can end the walk: the same
// result, bit for bit, as the walk one step at a time, on random depth images (a tilted
// plane with occluding boxes, holes and speckle) and rays of every kind and length.
TEST(SoffIntersect, WalkInLanesGivesTheBitsOfTheWalkOneStepAtATime) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  int kinds[4] = {}, long_walks = 0;
  for (int image = 0; image < 40; ++image) {
    const SoffCamera cam = camera_down_z(16 + image * 5, 16 + image * 3);
    const int w = cam.width, h = cam.height;
    std::vector<float> inv_z(std::size_t(w) * std::size_t(h));
    const float tilt = 0.6f * u(rng), depth = 4.0f + 2.0f * u(rng);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const glm::vec3 d = cam.pixel_direction(float(x) + 0.5f, float(y) + 0.5f);
        inv_z[std::size_t(y) * std::size_t(w) + std::size_t(x)] = (1.0f - tilt * d.x / d.z) / depth;
      }
    for (int box = 0; box < 4; ++box) {  // occluders nearer than the plane, and holes (0)
      const int x0 = int((u(rng) + 1.0f) * 0.5f * float(w)), y0 = int((u(rng) + 1.0f) * 0.5f * float(h));
      const float value = box == 3 ? 0.0f : 1.0f / (1.5f + u(rng));
      for (int y = y0; y < std::min(h, y0 + h / 4); ++y)
        for (int x = x0; x < std::min(w, x0 + w / 5); ++x) inv_z[std::size_t(y) * std::size_t(w) + std::size_t(x)] = value;
    }
    for (int k = 0; k < w; ++k) inv_z[std::size_t(rng() % inv_z.size())] *= 1.0f + 0.2f * u(rng);
    for (int ray = 0; ray < 300; ++ray) {
      const glm::vec3 o(0.8f * u(rng), 0.8f * u(rng), 1.0f + 2.0f * (u(rng) + 1.0f));
      const glm::vec3 d = glm::normalize(glm::vec3(u(rng), u(rng), ray % 10 == 0 ? u(rng) : 1.0f + u(rng)));
      const SoffWalkResult want = walk_one_step_at_a_time(cam, inv_z.data(), o, d);
      const SoffWalkResult got = soff_walk(cam, inv_z.data(), o, d);
      ASSERT_EQ(int(want.kind), int(got.kind)) << "image " << image << " ray " << ray;
      ASSERT_EQ(want.steps, got.steps) << "image " << image << " ray " << ray;
      for (const auto& [a, b] : {std::pair{want.sx, got.sx}, {want.sy, got.sy}, {want.inv_z, got.inv_z}})
        ASSERT_EQ(0, std::memcmp(&a, &b, sizeof a)) << "image " << image << " ray " << ray;
      ++kinds[want.kind];
      long_walks += want.steps > 16;
    }
  }
  for (int kind = 0; kind < 4; ++kind) EXPECT_GT(kinds[kind], 50) << "kind " << kind;
  EXPECT_GT(long_walks, 1000);
}

// Renders `technique` on `scene` at w × h (every parameter at its default but `params`).
ImageRGBA render_display(const Scene& scene, const std::string& technique, int w, int h,
                         std::map<std::string, double> params = {}) {
  par::Executor ex(2);
  const pipeline::Technique& t = pipeline::find_technique(technique);
  pipeline::FrameSettings f;
  f.width = w;
  f.height = h;
  f.camera = scene.cameras.front();
  f.params = std::move(params);
  f = t.with_defaults(f);
  return pipeline::render_frame(scene, t, f, ex).display;
}

// A planar mirror floor is one cluster whose camera is the mirrored camera: the reflection
// equals the planar-mirror technique's (one bounce) except at edges, where the depth image
// is resampled.
TEST(SoffIntersect, PlanarClusterMatchesPlanarMirror) {
  SceneBuilder b("mirror floor");
  const auto floor = b.add_material(mirror("floor mirror", glm::vec3(0.9f)));
  const auto red = b.add_material(diffuse("red", {0.8f, 0.2f, 0.1f}));
  const auto blue = b.add_material(diffuse("blue", {0.1f, 0.3f, 0.8f}));
  b.add_object("floor", floor, quad({-6, 0, 6}, {12, 0, 0}, {0, 0, -12}, 8, 8));
  b.add_object("ball", red, sphere({-0.8f, 0.7f, 0.0f}, 0.7f, 48));
  b.add_object("box", blue, box({0.6f, 0.0f, -0.9f}, {1.6f, 1.2f, 0.1f}, 2, false));
  Scene s = b.take();
  Light l;
  l.type = LightType::Point;
  l.position = {1.0f, 4.0f, 2.0f};
  l.intensity = 40.0f;
  s.lights.push_back(l);
  s.environment.constant = glm::vec3(0.3f, 0.35f, 0.4f);
  s.cameras.push_back(look({0.0f, 2.2f, 4.5f}, {0.0f, 0.3f, 0.0f}, 50.0f));
  const ImageRGBA soff = render_display(s, "soff", 160, 120);
  const ImageRGBA planar = render_display(s, "planar-mirror", 160, 120, {{"depth", 1}});
  const ImageError e = image_error(soff, planar);
  // Edges: pixels that differ by more than 16 of 255 in some channel.
  std::size_t edge = 0;
  for (std::size_t i = 0; i < soff.pixels.size(); ++i)
    for (int ch = 0; ch < 3; ++ch)
      if (std::abs(display_to_8bit(soff.pixels[i][ch]) - display_to_8bit(planar.pixels[i][ch])) > 16) {
        ++edge;
        break;
      }
  EXPECT_LT(e.mae8, 1.5) << "mean 8-bit difference over the frame";
  EXPECT_LT(edge, soff.pixels.size() / 50) << "more than 2% of the pixels differ by > 16: not only edges";
}

// The mean absolute 8-bit difference over the specular samples of `scene`'s G-buffer (the
// matrix's specular error).
double specular_mae8(const Scene& scene, const ImageRGBA& a, const ImageRGBA& b) {
  par::Executor ex(2);
  const GBuffer g = gbuffer_of(ex, scene, scene.cameras.front(), a.width, a.height);
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    if (!g.covered(i) || !is_specular(g.surface[i])) continue;
    for (int ch = 0; ch < 3; ++ch)
      sum += std::abs(display_to_8bit(a.pixels[i][ch]) - display_to_8bit(b.pixels[i][ch]));
    ++n;
  }
  return n ? sum / (3.0 * double(n)) : 0.0;
}

// Against the exact specular reference (one bounce, the same shading of the hits): soff is
// within a stated bound on every scene and well below environment mapping. At 160 × 120
// without supersampling most of what is left is the depth images' resampling of checker
// textures and the minification at curved reflectors' rims (SOFF §4.1.1).
TEST(SoffIntersect, SpecularErrorAgainstTheExactSpecularReference) {
  struct Case {
    const char* scene;
    double bound;
  };
  for (const Case& c : {Case{"sphere-in-room", 26.0}, Case{"mirror-corridor", 11.0}, Case{"living-room", 18.0}}) {
    const Scene s = load_scene(c.scene);
    const ImageRGBA ref = render_display(s, "specular-reference", 160, 120, {{"glossy_samples", 64}});
    const double soff = specular_mae8(s, render_display(s, "soff", 160, 120), ref);
    const double envmap = specular_mae8(s, render_display(s, "envmap", 160, 120), ref);
    EXPECT_LE(soff, c.bound) << c.scene;
    EXPECT_LT(soff, 0.8 * envmap) << c.scene << ": soff " << soff << ", envmap " << envmap;
    std::printf("%s: specular mae8 soff %.2f envmap %.2f\n", c.scene, soff, envmap);
  }
}

// SOFF §3.5: glossy samples average several lobe rays walked through a depth image widened
// by the cone; more rays bring the glossy floor closer to the converged lobe, and both stay
// far below environment mapping's error.
TEST(SoffIntersect, GlossyRaysConvergeTowardsTheReference) {
  const Scene s = load_scene("glossy-plane");
  const ImageRGBA ref = render_display(s, "specular-reference", 160, 120, {{"glossy_samples", 256}});
  const double few = specular_mae8(s, render_display(s, "soff", 160, 120, {{"glossy_rays", 8}}), ref);
  const double many = specular_mae8(s, render_display(s, "soff", 160, 120, {{"glossy_rays", 49}}), ref);
  const double envmap = specular_mae8(s, render_display(s, "envmap", 160, 120), ref);
  EXPECT_LT(many, 0.75 * few) << "8 rays " << few << ", 49 rays " << many;
  EXPECT_LT(few, 0.5 * envmap) << "8 rays " << few << ", envmap " << envmap;
  EXPECT_LE(many, 4.0);
}

// SOFF §4.4's second option: a reflected ray of a concave mirror bowl walked through the
// output image against the bowl's own samples finds the analytic second intersection with
// the sphere the bowl is cut from.
TEST(SoffConcave, SelfWalkFindsTheAnalyticSecondIntersection) {
  par::Executor ex(2);
  SceneBuilder b("bowl");
  const auto m = b.add_material(mirror("concave mirror"));
  const glm::vec3 centre(0.0f, 2.0f, 0.0f);
  const float radius = 2.0f;
  b.add_object("bowl", m, bowl(centre, radius, 75.0f, 160));
  const Scene s = b.take();
  const Camera cam = look({0.0f, 5.0f, 1.5f}, {0.0f, 0.6f, 0.0f}, 60.0f);
  const int w = 256, h = 256;
  const GBuffer g = gbuffer_of(ex, s, cam, w, h);
  const glm::mat4 vp = projection_matrix(cam, w, h) * view_matrix(cam);
  const glm::vec3 forward = glm::normalize(cam.target - cam.eye);
  const glm::ivec4 box(0, 0, w - 1, h - 1);
  int tested = 0, found = 0;
  double worst = 0.0;
  for (int y = 8; y < h; y += 16)
    for (int x = 8; x < w; x += 16) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      if (!g.covered(i)) continue;
      const glm::vec3 p = g.position.pixels[i];
      // A direction towards a point on the bowl's far side, well inside the rim.
      const glm::vec3 target = centre + radius * glm::normalize(glm::vec3(-p.x, -1.2f, -p.z) * 0.5f +
                                                                glm::vec3(0.3f, -1.0f, 0.2f));
      const glm::vec3 d = glm::normalize(target - p);
      const float t = -2.0f * glm::dot(p - centre, d);  // |p − c| = R: the other root
      const glm::vec3 hit = p + d * t;
      if (!(t > 0.3f)) continue;
      // Only second intersections the output camera sees (the bowl is open towards it).
      const glm::vec4 clip = vp * glm::vec4(hit, 1.0f);
      const int hx = int((clip.x / clip.w * 0.5f + 0.5f) * float(w)), hy = int((0.5f - clip.y / clip.w * 0.5f) * float(h));
      if (hx < 0 || hy < 0 || hx >= w || hy >= h) continue;
      const std::size_t hq = std::size_t(hy) * std::size_t(w) + std::size_t(hx);
      if (!g.covered(hq) || glm::length(g.position.pixels[hq] - hit) > 0.05f) continue;
      ++tested;
      const std::uint32_t q = soff_self_walk(g, vp, forward, g.object.pixels[i], box, p, d, 2.0f * radius);
      if (q == kNoId) continue;
      ++found;
      worst = std::max(worst, double(glm::length(g.position.pixels[q] - hit)));
    }
  ASSERT_GE(tested, 40);
  EXPECT_GE(found, tested * 95 / 100) << found << " of " << tested;
  // A sample of the 256² image spans about 4.2/256 of the bowl; the walk lands within a
  // few of them of the analytic point.
  EXPECT_LT(worst, 0.08) << "largest distance from the analytic second intersection";
}

// On the bowl scene the concave mirror's clusters are detected, their rays are intersected
// with the bowl itself, and the specular error against the exact reference falls below that
// of treating the clusters as convex (the first option of SOFF §4.4).
TEST(SoffConcave, SelfIntersectionLowersTheBowlError) {
  const Scene s = load_scene("bowl");
  par::Executor ex(2);
  const pipeline::Technique& t = pipeline::find_technique("soff");
  const auto run = [&](double concave) {
    pipeline::FrameSettings f;
    f.width = 160;
    f.height = 120;
    f.camera = s.cameras.front();
    f.params = {{"concave", concave}};
    return pipeline::render_frame(s, t, t.with_defaults(f), ex);
  };
  const pipeline::FrameResult with = run(1.0), without = run(0.0);
  const ImageRGBA ref = render_display(s, "specular-reference", 160, 120);
  const auto counter = [](const pipeline::FrameResult& r, const char* node, const char* name) {
    const par::NodeRecord* n = r.report.find(node);
    const auto it = n ? n->counters.find(name) : decltype(n->counters.end()){};
    return n && it != n->counters.end() ? it->second : -1.0;
  };
  EXPECT_GT(counter(with, "soff_cameras", "concave_clusters"), 0.0);
  EXPECT_GT(counter(with, "soff_intersect", "self_hits"), 100.0);
  EXPECT_EQ(counter(without, "soff_intersect", "self_hits"), 0.0);
  const double e_with = specular_mae8(s, with.display, ref), e_without = specular_mae8(s, without.display, ref);
  std::printf("bowl: specular mae8 with self-intersection %.2f, as convex %.2f\n", e_with, e_without);
  EXPECT_LT(e_with, 0.8 * e_without);
}

}  // namespace
}  // namespace speculum::raster
