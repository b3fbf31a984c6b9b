// --eye/--target/--up/--fov (apps/cli/camera_options.h): a moved camera gets near/far
// planes fitted to the scene's bounds (core/scene.h fit_clip_planes) instead of keeping the
// scene camera's, which for a mesh file are tight around the framing view; without an eye or
// target override the scene camera is kept exactly.
#include "apps/cli/camera_options.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include "core/scene_loader.h"
#include "raster/visibility.h"
#include "speculum_run.h"

namespace speculum {
namespace {

// A tetrahedron inscribed in the cube [-0.5, 0.5]^3.
std::filesystem::path write_tetra(const std::filesystem::path& dir) {
  const auto path = dir / "tetra.ply";
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
         "0.5 0.5 0.5\n-0.5 -0.5 0.5\n-0.5 0.5 -0.5\n0.5 -0.5 -0.5\n"
         "3 0 1 2\n3 0 3 1\n3 0 2 3\n3 1 3 2\n";
  return path;
}

// Smallest and largest view depth of the scene's vertices seen from `cam`.
std::pair<float, float> vertex_depth_range(const Scene& scene, const Camera& cam) {
  const glm::vec3 forward = glm::normalize(cam.target - cam.eye);
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (const glm::vec3& p : scene.mesh.positions) {
    lo = std::min(lo, glm::dot(p - cam.eye, forward));
    hi = std::max(hi, glm::dot(p - cam.eye, forward));
  }
  return {lo, hi};
}

std::size_t covered(const raster::VisibilityBuffer& v) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < v.triangle.size(); ++i) n += v.triangle.pixels[i] != kNoId;
  return n;
}

// Renders the resolved camera and the same view with generous hand-set planes (near well
// inside the nearest vertex, far well beyond the farthest): the samples must agree exactly.
void expect_drawn_like_direct_camera(const Scene& scene, const Camera& resolved, float direct_near,
                                     std::size_t min_covered) {
  Camera direct = resolved;
  direct.znear = direct_near;
  direct.zfar = 100.0f;
  const auto [lo, hi] = vertex_depth_range(scene, resolved);
  if (lo > 0.0f) {
    EXPECT_LT(resolved.znear, lo) << "near plane cuts the nearest vertex";
  }
  EXPECT_GT(resolved.zfar, hi) << "far plane cuts the farthest vertex";
  EXPECT_GT(resolved.znear, 0.0f);
  par::Executor ex(2);
  const int w = 160, h = 120;
  const auto got = raster::render_visibility(ex, scene, resolved, w, h);
  const auto want = raster::render_visibility(ex, scene, direct, w, h);
  EXPECT_GE(covered(got), min_covered);
  EXPECT_EQ(covered(got), covered(want));
  std::size_t differing = 0;
  for (std::size_t i = 0; i < got.triangle.size(); ++i)
    differing += got.triangle.pixels[i] != want.triangle.pixels[i];
  EXPECT_EQ(differing, 0u);
}

class CameraOptions : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir();
    tetra_ = load_scene(write_tetra(dir_).string());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
  Scene tetra_;
};

TEST_F(CameraOptions, EyeBeyondTheFramingFarPlaneStillSeesTheMesh) {
  // The framing camera of a unit-sized mesh has far ≈ 4; from (3,3,3) the whole
  // tetrahedron lies beyond it (the bug: covered_fraction 0).
  pipeline::CameraOverrides o;
  o.eye = "3,3,3";
  o.target = "0,0,0";
  const Camera resolved = pipeline::resolve_camera(tetra_, o);
  Camera old_behaviour = resolved;
  old_behaviour.znear = tetra_.cameras.front().znear;
  old_behaviour.zfar = tetra_.cameras.front().zfar;
  ASSERT_LT(old_behaviour.zfar, vertex_depth_range(tetra_, resolved).first)
      << "precondition: the scene camera's far plane would clip the whole mesh";
  par::Executor ex(1);
  EXPECT_EQ(covered(raster::render_visibility(ex, tetra_, old_behaviour, 160, 120)), 0u);
  expect_drawn_like_direct_camera(tetra_, resolved, 0.01f, 200);
  // Depth precision stays reasonable: near is not a tiny fraction of far.
  EXPECT_GT(resolved.znear, 0.1f * resolved.zfar);
}

TEST_F(CameraOptions, EyeNearerThanTheFramingNearPlaneKeepsNearbyGeometry) {
  pipeline::CameraOverrides o;
  o.eye = "0,0.1,0.9";
  o.target = "0,0,0";
  const Camera resolved = pipeline::resolve_camera(tetra_, o);
  ASSERT_GT(tetra_.cameras.front().znear, vertex_depth_range(tetra_, resolved).first)
      << "precondition: the scene camera's near plane would cut the nearest vertex";
  expect_drawn_like_direct_camera(tetra_, resolved, 1e-3f, 2000);
}

TEST_F(CameraOptions, EyeInsideTheMeshSeesItAllAround) {
  pipeline::CameraOverrides o;
  o.eye = "0,0,0.05";
  o.target = "0.1,0.05,-1";
  const Camera resolved = pipeline::resolve_camera(tetra_, o);
  EXPECT_GE(resolved.znear, resolved.zfar * 1e-4f * 0.999f);  // depth ratio bounded
  expect_drawn_like_direct_camera(tetra_, resolved, 1e-4f, 160 * 120);
}

TEST_F(CameraOptions, WithoutEyeOrTargetTheSceneCameraIsKept) {
  const Scene scene = load_scene("sphere-in-room");
  const Camera& c = scene.cameras.front();
  for (int variant = 0; variant < 3; ++variant) {
    pipeline::CameraOverrides o;
    if (variant == 1) o.fov = 30.0f;
    if (variant == 2) o.up = "0.1,1,0";
    const Camera r = pipeline::resolve_camera(scene, o);
    EXPECT_EQ(r.znear, c.znear) << " variant " << variant;
    EXPECT_EQ(r.zfar, c.zfar) << " variant " << variant;
    EXPECT_EQ(r.eye, c.eye);
  }
}

// A mesh file has no camera: its framing camera is refitted for the image's aspect and
// field of view (core/scene.h framing_camera), the same for any override of fov and up.
TEST_F(CameraOptions, AMeshFileIsFramedForTheImage) {
  const Bounds b = tetra_.bounds();
  EXPECT_TRUE(tetra_.cameras.front().framed);
  for (int variant = 0; variant < 2; ++variant) {
    pipeline::CameraOverrides o;
    if (variant == 1) o.fov = 30.0f;
    const Camera r = pipeline::resolve_camera(tetra_, o, 4.0f / 3.0f);
    const Camera expected = framing_camera(b, View::ThreeQuarter, 4.0f / 3.0f, variant ? 30.0f : 45.0f);
    EXPECT_EQ(r.eye, expected.eye) << variant;
    EXPECT_EQ(r.znear, expected.znear) << variant;
    EXPECT_EQ(r.zfar, expected.zfar) << variant;
    const float radius = std::max(0.5f * glm::length(b.extent()), 1e-3f);
    const float dist = radius / std::sin(glm::radians(variant ? 30.0f : 45.0f) * 0.5f);
    EXPECT_NEAR(glm::length(r.eye - b.center()), dist, dist * 1e-6f);
    EXPECT_EQ(r.zfar, dist + radius * 2.0f);
  }
}

TEST_F(CameraOptions, FitClipPlanesUsesTheNearestBoxCornerForLongBoxes) {
  // A 100 × 1 × 1 box seen from its side at distance 2: the sphere around it would put
  // near at 1e-4 × far; the nearest corner (depth 1.5) allows 0.9 × 1.5.
  Bounds b;
  b.grow({-50, -0.5f, -0.5f});
  b.grow({50, 0.5f, 0.5f});
  Camera cam;
  cam.eye = {0, 0, 2};
  cam.target = {0, 0, 0};
  const Camera fitted = fit_clip_planes(cam, b);
  EXPECT_FLOAT_EQ(fitted.znear, 0.9f * 1.5f);
  EXPECT_GT(fitted.zfar, std::sqrt(50.0f * 50.0f + 2.5f * 2.5f));
  // Empty bounds: unchanged.
  const Camera same = fit_clip_planes(cam, Bounds{});
  EXPECT_EQ(same.znear, cam.znear);
  EXPECT_EQ(same.zfar, cam.zfar);
}

TEST_F(CameraOptions, BenchRasterFromAMovedEyeCoversSamples) {
  const auto ply = dir_ / "tetra.ply";
  const auto r = test::run_speculum("-q --threads 1 bench raster " + test::sh_quote(ply.string()) +
                                        " --eye 3,3,3 --target 0,0,0 --width 160 --height 120"
                                        " --repeat 1 --json",
                                    dir_);
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.out, m, std::regex("\"covered_fraction\": ([0-9.]+)"))) << r.out;
  EXPECT_GT(std::stod(m[1].str()), 0.01) << r.out;
}

}  // namespace
}  // namespace speculum
