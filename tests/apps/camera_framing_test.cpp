// The framing camera (core/scene.h framing_camera, fit_camera) and --view, --fit, --fov and
// a file camera's aspect ratio (apps/cli/camera_options.h, frame_options.h): every corner
// of the bounds projects inside the image, each view looks from its axis, bad fields of
// view are refused.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "apps/cli/camera_options.h"
#include "apps/cli/frame_options.h"
#include "core/error.h"
#include "core/gltf_writer.h"
#include "core/image.h"
#include "core/scene_loader.h"
#include "speculum_run.h"

namespace speculum {
namespace {

// Every corner of `b` in front of the camera, between its clip planes, and inside the
// image of `aspect` (normalized device coordinates within [-1, 1]).
void expect_corners_inside(const Camera& c, const Bounds& b, float aspect) {
  const glm::vec3 f = glm::normalize(c.target - c.eye);
  const glm::vec3 r = glm::normalize(glm::cross(f, c.up));
  const glm::vec3 u = glm::cross(r, f);
  const float tan_v = std::tan(glm::radians(c.vfov_degrees) * 0.5f), tan_h = tan_v * aspect;
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 p(k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z);
    const glm::vec3 q = p - c.eye;
    const float depth = glm::dot(q, f);
    ASSERT_GT(depth, c.znear) << "corner " << k;
    EXPECT_LT(depth, c.zfar) << "corner " << k;
    EXPECT_LE(std::abs(glm::dot(q, r) / (depth * tan_h)), 1.0f) << "corner " << k;
    EXPECT_LE(std::abs(glm::dot(q, u) / (depth * tan_v)), 1.0f) << "corner " << k;
  }
}

TEST(CameraFraming, EveryCornerOfTheBoundsProjectsInsideTheImage) {
  std::vector<Bounds> boxes(3);
  boxes[0].grow({-1, -1, -1}), boxes[0].grow({1, 1, 1});
  boxes[1].grow({10, 0, -3}), boxes[1].grow({10.5f, 40, -2});  // a tall thin box off-centre
  boxes[2].grow({-500, 2, 0}), boxes[2].grow({700, 3, 0.001f});  // a wide flat one
  for (const Bounds& b : boxes)
    for (View v : {View::Front, View::Back, View::Left, View::Right, View::Top, View::ThreeQuarter})
      for (float aspect : {0.5f, 1.0f, 4.0f / 3.0f, 2.4f}) {
        SCOPED_TRACE(std::string(to_string(v)) + " aspect " + std::to_string(aspect));
        const Camera c = framing_camera(b, v, aspect);
        EXPECT_TRUE(c.framed);
        expect_corners_inside(c, b, aspect);
        // Tight: the bounding sphere touches the narrower side of the view cone.
        const float radius = 0.5f * glm::length(b.extent());
        const float half_v = glm::radians(c.vfov_degrees) * 0.5f;
        const float half = std::min(half_v, std::atan(aspect * std::tan(half_v)));
        EXPECT_NEAR(glm::length(c.eye - b.center()) * std::sin(half), radius, radius * 1e-5f);
      }
}

TEST(CameraFraming, ViewsLookFromTheirAxes) {
  Bounds b;
  b.grow({-1, 0, -2}), b.grow({3, 1, 2});
  const struct { View view; glm::vec3 from; } cases[] = {
      {View::Front, {0, 0, 1}}, {View::Back, {0, 0, -1}}, {View::Left, {-1, 0, 0}},
      {View::Right, {1, 0, 0}}, {View::Top, {0, 1, 0}},
      {View::ThreeQuarter, glm::normalize(glm::vec3(std::sqrt(0.5f) * std::cos(glm::radians(30.0f)),
                                                    std::sin(glm::radians(30.0f)),
                                                    std::sqrt(0.5f) * std::cos(glm::radians(30.0f))))}};
  for (const auto& c : cases) {
    const Camera cam = framing_camera(b, c.view);
    EXPECT_NEAR(glm::dot(glm::normalize(cam.eye - cam.target), c.from), 1.0f, 1e-5f) << to_string(c.view);
    EXPECT_EQ(cam.target, b.center());
    EXPECT_EQ(pipeline::parse_view(to_string(c.view)), c.view);
  }
  EXPECT_THROW(pipeline::parse_view("sideways"), InputError);
}

TEST(CameraFraming, MeshFilesGetTheThreeQuarterViewAndViewFitOverrideAnyCamera) {
  const Scene tetra = load_scene(SPECULUM_TEST_DATA "/good/tetra.obj");
  ASSERT_EQ(tetra.cameras.size(), 1u);
  EXPECT_TRUE(tetra.cameras[0].framed);
  pipeline::CameraOverrides o;
  const Camera wide = pipeline::resolve_camera(tetra, o, 2.0f);
  EXPECT_EQ(wide.eye, framing_camera(tetra.bounds(), View::ThreeQuarter, 2.0f).eye);
  // A portrait image moves the default camera back so the sides still fit.
  const Camera tall = pipeline::resolve_camera(tetra, o, 0.5f);
  expect_corners_inside(tall, tetra.bounds(), 0.5f);
  EXPECT_GT(glm::length(tall.eye - tall.target), glm::length(wide.eye - wide.target));

  const Scene room = load_scene("sphere-in-room:size=2000");
  o.view = "top";
  const Camera top = pipeline::resolve_camera(room, o, 1.5f);
  EXPECT_NEAR(glm::normalize(top.eye - top.target).y, 1.0f, 1e-6f);
  expect_corners_inside(top, room.bounds(), 1.5f);
  // --fit keeps the scene camera's direction and fov and frames the bounds.
  o.view.clear();
  o.fit = true;
  const Camera& own = room.cameras.front();
  const Camera fitted = pipeline::resolve_camera(room, o, 1.5f);
  EXPECT_NEAR(glm::dot(glm::normalize(fitted.eye - fitted.target), glm::normalize(own.eye - own.target)),
              1.0f, 1e-5f);
  EXPECT_EQ(fitted.vfov_degrees, own.vfov_degrees);
  expect_corners_inside(fitted, room.bounds(), 1.5f);
}

TEST(CameraFraming, FieldOfViewOutsideZeroTo180IsRefused) {
  const Scene tetra = load_scene(SPECULUM_TEST_DATA "/good/tetra.obj");
  for (const char* bad : {"0", "-10", "180", "200", "nan", "inf", "wide", "30x"}) {
    pipeline::CameraOverrides o;
    o.fov_text = bad;
    try {
      (void)pipeline::resolve_camera(tetra, o);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "--fov") << bad;
    }
  }
  pipeline::CameraOverrides o;
  o.fov_text = "30";
  EXPECT_EQ(pipeline::resolve_camera(tetra, o).vfov_degrees, 30.0f);
}

TEST(CameraFraming, CommandLineRejectsBadFieldsOfViewAndViews) {
  const std::filesystem::path dir = test::scratch_dir();
  const std::string out = " -o " + test::sh_quote((dir / "out.png").string());
  for (const std::string bad : {"--fov 0", "--fov=-5", "--fov 180", "--fov nan", "--fov inf",
                                "--view sideways"}) {
    SCOPED_TRACE(bad);
    const test::CommandResult r = test::run_speculum(
        "-q render " + test::sh_quote(SPECULUM_TEST_DATA "/good/tetra.obj") + " --width 8 --height 8 " + bad + out, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind("speculum: --", 0), 0u) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.png"));
  }
  const test::CommandResult ok = test::run_speculum(
      "-q render " + test::sh_quote(SPECULUM_TEST_DATA "/good/tetra.obj") +
          " --width 8 --height 8 --view top --fov 60" + out, dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
}

TEST(CameraFraming, AFileCameraAspectRatioSetsTheHeightWhenNoSizeIsGiven) {
  // A glTF camera with aspectRatio 2 (written by the exporter, read by the loader).
  Scene mesh = load_scene(SPECULUM_TEST_DATA "/good/tetra.obj");
  mesh.cameras[0].aspect = 2.0f;
  const std::filesystem::path dir = test::scratch_dir();
  write_gltf(mesh, (dir / "wide.gltf").string());
  const Scene s = load_scene((dir / "wide.gltf").string());
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.cameras[0].aspect, 2.0f);
  EXPECT_FALSE(s.cameras[0].framed);
  pipeline::FrameOptions o;
  o.width = 640;
  o.height = 480;
  pipeline::FrameSettings f = pipeline::make_frame_settings(o, s);
  EXPECT_EQ(f.width, 640);
  EXPECT_EQ(f.height, 320);
  // Given sizes win (through the parser, as the commands see them).
  CLI::App app;
  pipeline::add_frame_options(app, o);
  app.parse(std::vector<std::string>{"100", "--height"});  // CLI11 takes the arguments reversed
  f = pipeline::make_frame_settings(o, s);
  EXPECT_EQ(f.height, 100);
  EXPECT_EQ(f.width, 200);
  CLI::App both;
  pipeline::FrameOptions given;
  pipeline::add_frame_options(both, given);
  both.parse(std::vector<std::string>{"50", "--height", "64", "--width"});
  f = pipeline::make_frame_settings(given, s);
  EXPECT_EQ(f.width, 64);
  EXPECT_EQ(f.height, 50);
  // `render` without a size: the default width, the camera's shape.
  const test::CommandResult r = test::run_speculum(
      "-q render " + test::sh_quote((dir / "wide.gltf").string()) + " --spp 1 -t envmap --cube-size 8 " +
          "--shadow-size 16 -o " + test::sh_quote((dir / "wide.png").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const ImageRGBA wide = read_image((dir / "wide.png").string());
  EXPECT_EQ(wide.width, 640);
  EXPECT_EQ(wide.height, 320);
}

}  // namespace
}  // namespace speculum
