// --env FILE|sky|COLOR, --env-intensity, --env-rotate and the default studio light
// (apps/cli/frame_options.h apply_light_options): each lights a bare model (non-black image),
// the same bytes for 1 and 2 threads; a lit scene is left alone; bad values are one line and
// exit 2.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "apps/cli/frame_options.h"
#include "apps/techniques/render_frame.h"
#include "core/error.h"
#include "core/image.h"
#include "core/lighting_presets.h"
#include "core/scene_loader.h"
#include "speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

const char* kCube = SPECULUM_TEST_DATA "/good/tetra.obj";

// A small equirect: warm above the horizon, dark below, written by OpenImageIO.
fs::path write_equirect(const fs::path& dir, const std::string& name) {
  const int w = 32, h = 16;
  std::vector<float> pixels(std::size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* p = &pixels[(std::size_t(y) * w + x) * 3];
      const float up = y < h / 2 ? 1.0f : 0.1f;
      p[0] = 1.5f * up, p[1] = 1.0f * up, p[2] = 0.6f * up + 0.02f * x;
    }
  const fs::path path = dir / name;
  auto out = OIIO::ImageOutput::create(path.string());
  EXPECT_TRUE(out);
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  EXPECT_TRUE(out->open(path.string(), spec));
  EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  out->close();
  return path;
}

struct Rendered {
  ImageRGBA display;
  std::vector<std::string> warnings;
  Scene scene;
};

Rendered render(const std::string& scene_name, pipeline::FrameOptions o, int threads) {
  o.technique = "envmap";
  o.width = 48;
  o.height = 36;
  Rendered r;
  r.scene = load_scene(scene_name);
  const pipeline::FrameSettings f = pipeline::make_frame_settings(o, r.scene);
  r.warnings = pipeline::apply_light_options(o, r.scene, f.camera);
  par::Executor ex(threads);
  r.display = pipeline::render_frame(r.scene, pipeline::find_technique("envmap"), f, ex).display;
  return r;
}

float brightest(const ImageRGBA& img) {
  float m = 0.0f;
  for (const glm::vec4& p : img.pixels) m = std::max({m, p.x, p.y, p.z});
  return m;
}

bool same_bytes(const ImageRGBA& a, const ImageRGBA& b) {
  return a.size() == b.size() &&
         std::memcmp(a.pixels.data(), b.pixels.data(), a.size() * sizeof(glm::vec4)) == 0;
}

TEST(LightingOptions, EachEnvironmentLightsABareModelDeterministically) {
  const fs::path dir = test::scratch_dir();
  const std::string exr = write_equirect(dir, "env.exr").string();
  const std::string hdr = write_equirect(dir, "env.hdr").string();
  for (const std::string& env : {exr, hdr, std::string("sky"), std::string("0.5,0.6,0.7"),
                                std::string("0.4"), std::string()}) {
    SCOPED_TRACE(env.empty() ? "default light" : env);
    pipeline::FrameOptions o;
    o.env = env;
    o.env_rotate = 30.0f;
    o.exposure = "auto";
    const Rendered one = render(kCube, o, 1);
    const Rendered two = render(kCube, o, 2);
    EXPECT_GT(brightest(one.display), 0.05f);
    EXPECT_TRUE(same_bytes(one.display, two.display));
    // The default light, and only it, is announced, on one line.
    if (env.empty()) {
      ASSERT_EQ(one.warnings.size(), 1u);
      EXPECT_EQ(one.warnings[0].rfind("speculum: warning: " + std::string(kCube) + ": no lights", 0), 0u);
      EXPECT_EQ(one.warnings[0].find('\n'), std::string::npos);
      EXPECT_EQ(one.scene.lights.size(), 1u);
    } else {
      EXPECT_TRUE(one.warnings.empty());
      EXPECT_TRUE(one.scene.lights.empty());
    }
  }
}

TEST(LightingOptions, NoDefaultLightKeepsTheBlackAndLitScenesAreLeftAlone) {
  pipeline::FrameOptions o;
  o.no_default_light = true;
  const Rendered black = render(kCube, o, 2);
  EXPECT_TRUE(black.warnings.empty());
  EXPECT_EQ(brightest(black.display), 0.0f);

  // A built-in scene with lights: no substitution, the scene as it was built.
  const Rendered lit = render("sphere-in-room:size=2000", pipeline::FrameOptions{}, 2);
  const Scene plain = load_scene("sphere-in-room:size=2000");
  EXPECT_TRUE(lit.warnings.empty());
  EXPECT_EQ(lit.scene.lights.size(), plain.lights.size());
  EXPECT_EQ(lit.scene.environment.constant, plain.environment.constant);
  EXPECT_EQ(lit.scene.environment.intensity, plain.environment.intensity);
  // And the frame through the options at exposure 1 is, byte for byte, the frame of the
  // scene as built with the settings a recipe gets by default.
  pipeline::FrameOptions fixed;
  fixed.exposure = "1";
  const Rendered via_options = render("sphere-in-room:size=2000", fixed, 2);
  pipeline::FrameSettings f;
  f.width = 48;
  f.height = 36;
  f.camera = plain.cameras.front();
  par::Executor ex(2);
  const ImageRGBA direct = pipeline::render_frame(plain, pipeline::find_technique("envmap"), f, ex).display;
  EXPECT_TRUE(same_bytes(via_options.display, direct));
}

TEST(LightingOptions, IntensityScalesAndRotationTurnsTheSceneEnvironment) {
  Scene s = load_scene("glossy-plane:size=2000");
  ASSERT_TRUE(s.environment.has_image());
  const Environment before = s.environment;
  pipeline::FrameOptions o;
  o.env_intensity = 2.5f;
  o.env_rotate = 360.0f;  // a whole turn: the same pixels
  EXPECT_TRUE(pipeline::apply_light_options(o, s, s.cameras.front()).empty());
  EXPECT_EQ(s.environment.intensity, before.intensity * 2.5f);
  ASSERT_EQ(s.environment.equirect.size(), before.equirect.size());
  for (std::size_t i = 0; i < before.equirect.size(); i += 97)
    EXPECT_NEAR(s.environment.equirect.pixels[i].x, before.equirect.pixels[i].x, 1e-4f);
}

TEST(LightingOptions, ParseEnvironment) {
  const Environment grey = pipeline::parse_environment("0.25");
  EXPECT_FALSE(grey.has_image());
  EXPECT_EQ(grey.constant, glm::vec3(0.25f));
  const Environment colour = pipeline::parse_environment("0.5,0.6,0.7");
  EXPECT_EQ(colour.constant, glm::vec3(0.5f, 0.6f, 0.7f));
  const Environment sky = pipeline::parse_environment("sky");
  EXPECT_EQ(sky.equirect.width, 512);
  for (const char* bad : {"-1", "0.1,-0.2,0.3", "nan", "inf,1,1", "", "1,2"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(pipeline::parse_environment(bad), InputError);
  }
  const fs::path dir = test::scratch_dir();
  try {
    pipeline::parse_environment((dir / "missing.hdr").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), (dir / "missing.hdr").string());
  }
  // Non-finite pixels are refused, naming the file.
  ImageRGBA nan_image(4, 2, glm::vec4(1.0f));
  nan_image.at(1, 1).y = std::numeric_limits<float>::quiet_NaN();
  write_image((dir / "nan.exr").string(), nan_image);
  EXPECT_THROW(pipeline::parse_environment((dir / "nan.exr").string()), InputError);
}

TEST(LightingOptions, CommandLineWarnsOnceAndRejectsBadValues) {
  const fs::path dir = test::scratch_dir();
  const std::string out = " -o " + test::sh_quote((dir / "out.png").string());
  const std::string cube = test::sh_quote(kCube);
  const test::CommandResult r =
      test::run_speculum("render " + cube + " --width 32 --height 24" + out, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // One warning line about the default light, one line with the metered exposure.
  const std::string warning = "speculum: warning: " + std::string(kCube) + ": no lights and no environment";
  std::size_t warnings = 0;
  for (std::size_t at = r.err.find(warning); at != std::string::npos; at = r.err.find(warning, at + 1)) ++warnings;
  EXPECT_EQ(warnings, 1u) << r.err;
  EXPECT_NE(r.err.find("speculum: exposure auto: "), std::string::npos) << r.err;
  // --quiet: nothing on stderr.
  const test::CommandResult q =
      test::run_speculum("-q render " + cube + " --width 32 --height 24" + out, dir);
  ASSERT_EQ(q.status, 0) << q.err;
  EXPECT_EQ(q.err, "");
  EXPECT_GT(brightest(read_image((dir / "out.png").string())), 0.05f);

  for (const std::string bad : {"--env nosuch.hdr", "--env 1,2", "--env=-0.5", "--env-intensity=-1",
                                "--env-intensity nan", "--exposure 0", "--exposure=-1",
                                "--exposure nan", "--exposure inf", "--exposure bright"}) {
    SCOPED_TRACE(bad);
    const test::CommandResult e =
        test::run_speculum("-q render " + cube + " --width 8 --height 8 " + bad + out, dir);
    EXPECT_EQ(e.status, 2) << e.err;
    EXPECT_EQ(e.err.rfind("speculum: ", 0), 0u) << e.err;
    EXPECT_EQ(e.err.find('\n'), e.err.size() - 1) << e.err;
  }
}

}  // namespace
}  // namespace speculum
