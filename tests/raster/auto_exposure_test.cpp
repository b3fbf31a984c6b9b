// meter_exposure and the automatic tonemap (raster/composite.h): the analytic case (a frame
// of constant luminance Y meters to 0.18 / Y), the log average, what is left out, and the
// same value for any thread count.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "core/sampling.h"
#include "parallel/graph.h"
#include "raster/composite.h"

namespace speculum::raster {
namespace {

TEST(AutoExposure, ConstantLuminanceMetersToMiddleGreyOverY) {
  par::Executor ex(2);
  for (float y : {1e-4f, 0.05f, 1.0f, 43000.0f}) {
    // Grey and coloured pixels of the same luminance Y = 0.2126 R + 0.7152 G + 0.0722 B.
    ImageRGBA grey(37, 23, glm::vec4(y, y, y, 1.0f));
    EXPECT_NEAR(meter_exposure(ex, grey), 0.18 / y, 0.18 / y * 1e-6) << y;
    ImageRGBA green(37, 23, glm::vec4(0.0f, y / 0.7152f, 0.0f, 1.0f));
    EXPECT_NEAR(meter_exposure(ex, green), 0.18 / y, 0.18 / y * 1e-5) << y;
  }
}

TEST(AutoExposure, LogAverageLeavingOutBlackAndNonFinitePixels) {
  par::Executor ex(1);
  ImageRGBA img(4, 1);
  img.pixels = {glm::vec4(0.01f, 0.01f, 0.01f, 1), glm::vec4(1.0f, 1.0f, 1.0f, 1), glm::vec4(0.0f),
                glm::vec4(std::numeric_limits<float>::quiet_NaN())};
  // exp(mean(ln 0.01, ln 1)) = 0.1: exposure 1.8.
  EXPECT_NEAR(meter_exposure(ex, img), 1.8, 1.8e-6);
  img.pixels[3] = glm::vec4(std::numeric_limits<float>::infinity());
  EXPECT_NEAR(meter_exposure(ex, img), 1.8, 1.8e-6);
  // Nothing to meter: exposure 1.
  EXPECT_EQ(meter_exposure(ex, ImageRGBA(8, 8)), 1.0f);
}

TEST(AutoExposure, SameValueAndImageForEveryThreadCount) {
  ImageRGBA img(301, 211);
  for (std::size_t i = 0; i < img.size(); ++i) {
    const float v = std::exp(8.0f * std::sin(float(i) * 0.37f));  // spans ~7 decades
    img.pixels[i] = glm::vec4(v, 0.5f * v, 2.0f * v, 1.0f);
  }
  par::Executor one(1), two(2), eight(8);
  const float e = meter_exposure(one, img);
  EXPECT_EQ(meter_exposure(two, img), e);
  EXPECT_EQ(meter_exposure(eight, img), e);

  // Through the pass: the metered value is recorded and applied.
  auto run = [&](par::Executor& ex) {
    par::Graph g;
    auto in = g.input("radiance", img);
    auto out = g.add("tonemap", TonemapPass{1.0f, true}, in);
    g.request(out);
    const par::RunReport report = g.run(ex);
    double recorded = 0;
    for (const auto& n : report.nodes)
      if (n.name == "tonemap") recorded = n.counters.at("exposure");
    return std::make_pair(recorded, g.get(out));
  };
  const auto [r1, img1] = run(one);
  const auto [r2, img2] = run(two);
  EXPECT_EQ(r1, double(e));
  EXPECT_EQ(r2, double(e));
  const ImageRGBA expected = tonemap(one, img, e);
  ASSERT_EQ(img1.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(img1.pixels[i], expected.pixels[i]) << i;
    ASSERT_EQ(img2.pixels[i], expected.pixels[i]) << i;
  }
}

}  // namespace
}  // namespace speculum::raster
