// `render --aov`: the G-buffer layers land in the EXR under OpenImageIO's layer.channel names,
// with values known analytically: looking straight down at the top face of sphere-in-room's
// blue box (y = 1.2, albedo (0.2, 0.3, 0.8)) from 2 units above, every pixel sees that face,
// so depth.Z is 2, normal is +Y and albedo the material's, at any supersampling; the
// reference tracer writes the same layers (the same raster G-buffer at the pixel centres);
// the beauty channels are the image written without --aov.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

struct Exr {
  int width = 0, height = 0;
  std::vector<std::string> names;
  std::vector<float> data;
  // Channel `name` of pixel (x, y); fails the test if there is no such channel.
  float at(const std::string& name, int x, int y) const {
    const auto it = std::find(names.begin(), names.end(), name);
    EXPECT_NE(it, names.end()) << name;
    if (it == names.end()) return -1e30f;
    const std::size_t c = std::size_t(it - names.begin());
    return data[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * names.size() + c];
  }
};

Exr read_exr(const fs::path& path) {
  Exr e;
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << path;
  if (!in) return e;
  const OIIO::ImageSpec& spec = in->spec();
  e.width = spec.width, e.height = spec.height;
  e.names = spec.channelnames;
  e.data.resize(std::size_t(e.width) * std::size_t(e.height) * e.names.size());
  EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, e.data.data())) << in->geterror();
  return e;
}

const std::string kView =
    "sphere-in-room --width 33 --height 33 --eye -2.6,3.2,-1.4 --target -2.6,1.2,-1.4 --up 0,0,-1 "
    "--fov 30 -q ";

TEST(Aov, LayersHoldTheAnalyticDepthNormalAndAlbedo) {
  const fs::path dir = test::scratch_dir();
  for (const char* spp : {"1", "4"}) {
    SCOPED_TRACE(std::string("spp ") + spp);
    const fs::path out = dir / "aov.exr";
    const auto r = test::run_speculum("render " + kView + "--spp " + spp +
                                          " --aov albedo,normal,depth,position,roughness -o " +
                                          test::sh_quote(out.string()),
                                      dir);
    ASSERT_EQ(r.status, 0) << r.err;
    const Exr e = read_exr(out);
    ASSERT_EQ(e.width, 33);
    std::vector<std::string> sorted = e.names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, (std::vector<std::string>{"A", "B", "G", "R", "albedo.B", "albedo.G", "albedo.R",
                                                "depth.Z", "normal.X", "normal.Y", "normal.Z", "position.X",
                                                "position.Y", "position.Z", "roughness.Y"}));
    for (int y = 0; y < e.height; ++y)
      for (int x = 0; x < e.width; ++x) {
        ASSERT_NEAR(e.at("depth.Z", x, y), 2.0f, 1e-4f) << x << "," << y;
        ASSERT_NEAR(e.at("normal.Y", x, y), 1.0f, 1e-5f);
        ASSERT_NEAR(e.at("normal.X", x, y), 0.0f, 1e-5f);
        ASSERT_NEAR(e.at("albedo.R", x, y), 0.2f, 1e-6f);
        ASSERT_NEAR(e.at("albedo.G", x, y), 0.3f, 1e-6f);
        ASSERT_NEAR(e.at("albedo.B", x, y), 0.8f, 1e-6f);
        ASSERT_NEAR(e.at("position.Y", x, y), 1.2f, 1e-5f);
      }
    // The centre pixel looks along the axis: it sees the point looked at (at 1 spp exactly; at
    // 2×2 its nearest sample, a quarter pixel off: 2·2·tan 15° / 33 / 4 ≈ 0.008 per axis).
    const float tolerance = std::string(spp) == "1" ? 1e-4f : 0.0082f;
    EXPECT_NEAR(e.at("position.X", 16, 16), -2.6f, tolerance);
    EXPECT_NEAR(e.at("position.Z", 16, 16), -1.4f, tolerance);
  }
}

TEST(Aov, BeautyIsUnchangedAndTheReferenceWritesTheSameLayers) {
  const fs::path dir = test::scratch_dir();
  const std::string layers = " --aov depth,normal,albedo -o ";
  ASSERT_EQ(test::run_speculum("render " + kView + "-o " + test::sh_quote((dir / "plain.exr").string()), dir).status, 0);
  ASSERT_EQ(test::run_speculum("render " + kView + layers + test::sh_quote((dir / "envmap.exr").string()), dir).status, 0);
  const auto r = test::run_speculum("render " + kView + "-t reference" + layers +
                                        test::sh_quote((dir / "reference.exr").string()),
                                    dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Exr plain = read_exr(dir / "plain.exr"), env = read_exr(dir / "envmap.exr"),
            ref = read_exr(dir / "reference.exr");
  for (int y = 0; y < 33; ++y)
    for (int x = 0; x < 33; ++x) {
      for (const char* c : {"R", "G", "B", "A"}) ASSERT_EQ(env.at(c, x, y), plain.at(c, x, y)) << c;
      for (const char* c : {"depth.Z", "normal.X", "normal.Y", "normal.Z", "albedo.R", "albedo.G", "albedo.B"})
        ASSERT_EQ(ref.at(c, x, y), env.at(c, x, y)) << c << " " << x << "," << y;
    }
}

TEST(Aov, NeedsAnExrAndKnownLayers) {
  const fs::path dir = test::scratch_dir();
  for (const char* args : {"render -q --aov depth -o x.png", "render -q --aov depth,depth -o x.exr",
                           "render -q --aov '' -o x.exr"}) {
    const auto r = test::run_speculum(args, dir);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("speculum: --aov", 0), 0u) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
  EXPECT_FALSE(fs::exists(dir / "x.exr"));
}

}  // namespace
}  // namespace speculum
