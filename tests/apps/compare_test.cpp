// `speculum compare`: exit status 0 within the bound, 1 outside, 2 on bad input, and the
// printed metrics equal the known 8-bit differences of generated PNGs.
#include <cmath>
#include <map>
#include <sstream>

#include "core/image.h"
#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;
using test::sh_quote;
using test::run_speculum;

// A display image whose 8-bit values are exactly `value(x, y, c)`.
ImageRGBA image_of_8bit(int w, int h, int (*value)(int, int, int)) {
  ImageRGBA img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) = {srgb_to_linear(value(x, y, 0) / 255.0f), srgb_to_linear(value(x, y, 1) / 255.0f),
                      srgb_to_linear(value(x, y, 2) / 255.0f), 1.0f};
  return img;
}

int gradient(int x, int y, int c) { return (x * 7 + y * 3 + c * 50) % 200 + 20; }
// The gradient with pixel (3, 2) brighter by 10 in red and 4 in blue.
int gradient_changed(int x, int y, int c) {
  const int v = gradient(x, y, c);
  if (x == 3 && y == 2) return v + (c == 0 ? 10 : c == 2 ? 4 : 0);
  return v;
}

std::map<std::string, double> parse_metrics(const std::string& out) {
  std::map<std::string, double> m;
  std::istringstream in(out);
  std::string key;
  double value;
  while (in >> key >> value) {
    m[key] = value;
    in.ignore(1 << 20, '\n');
  }
  return m;
}

class CompareTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = test::scratch_dir();
    a = (dir / "a.png").string();
    b = (dir / "b.png").string();
    write_image(a, image_of_8bit(kW, kH, gradient));
    write_image(b, image_of_8bit(kW, kH, gradient_changed));
  }
  void TearDown() override { fs::remove_all(dir); }
  static constexpr int kW = 16, kH = 8;
  fs::path dir;
  std::string a, b;
};

TEST_F(CompareTest, MetricsEqualTheKnownDifference) {
  const auto r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(b), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = parse_metrics(r.out);
  const double n = 3.0 * kW * kH;
  EXPECT_NEAR(m.at("mae8"), 14.0 / n, 1e-6);
  const double rmse = std::sqrt((100.0 + 16.0) / n) / 255.0;
  EXPECT_NEAR(m.at("rmse"), rmse, 1e-8);
  EXPECT_NEAR(m.at("psnr"), 20.0 * std::log10(1.0 / rmse), 1e-3);
  EXPECT_EQ(m.at("max8"), 10.0);
  EXPECT_EQ(m.at("differing_pixels"), 1.0);
}

TEST_F(CompareTest, IdenticalImagesHaveZeroErrorAndCappedPsnr) {
  const auto r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(a) + " --metric psnr --max 99", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto m = parse_metrics(r.out);
  EXPECT_EQ(m.at("mae8"), 0.0);
  EXPECT_EQ(m.at("psnr"), 100.0);
}

TEST_F(CompareTest, ExitStatusFollowsTheBound) {
  const double mae8 = 14.0 / (3.0 * kW * kH);
  auto status = [&](const std::string& metric, double max) {
    std::ostringstream args;
    args.precision(10);
    args << "compare " << sh_quote(a) << " " << sh_quote(b) << " --metric " << metric << " --max " << max;
    return run_speculum(args.str(), dir).status;
  };
  EXPECT_EQ(status("mae8", mae8 * 1.01), 0);
  EXPECT_EQ(status("mae8", mae8 * 0.99), 1);
  EXPECT_EQ(status("rmse", 0.01), 0);
  EXPECT_EQ(status("rmse", 0.001), 1);
  EXPECT_EQ(status("psnr", 50), 0);  // psnr ≈ 53.3 dB: "within" means at least the bound
  EXPECT_EQ(status("psnr", 55), 1);
}

TEST_F(CompareTest, BadInputExitsTwo) {
  const std::string missing = (dir / "missing.png").string();
  auto r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(missing), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  const std::string small = (dir / "small.png").string();
  write_image(small, image_of_8bit(kW / 2, kH, gradient));
  r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(small) + " --max 1", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("sizes differ"), std::string::npos) << r.err;
  r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(b) + " --metric nope", dir);
  EXPECT_EQ(r.status, 2);
}

TEST_F(CompareTest, DiffHeatMapIsBlackWhereEqualAndWhiteAtTheLargestDifference) {
  const std::string diff = (dir / "diff.png").string();
  const auto r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(b) + " --diff " + sh_quote(diff), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const ImageRGBA heat = read_image(diff);
  ASSERT_EQ(heat.width, kW);
  ASSERT_EQ(heat.height, kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::vec4 p = heat.at(x, y);
      if (x == 3 && y == 2)
        EXPECT_GT(std::min({p.x, p.y, p.z}), 0.99f);
      else
        EXPECT_EQ(p.x + p.y + p.z, 0.0f) << x << "," << y;
    }
}

}  // namespace
}  // namespace speculum
