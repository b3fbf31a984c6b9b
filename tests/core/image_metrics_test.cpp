// Image metrics: exact values on hand-made images, and in-memory metrics equal to the
// metrics of the PNG files written from the same images.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/image_metrics.h"

namespace speculum {
namespace {

TEST(ImageMetrics, IdenticalImagesHaveZeroErrorAndCappedPsnr) {
  ImageRGBA a(5, 3, glm::vec4(0.3f, 0.6f, 0.9f, 1.0f));
  const ImageError e = image_error(a, a);
  EXPECT_EQ(e.mae8, 0.0);
  EXPECT_EQ(e.rmse, 0.0);
  EXPECT_EQ(e.psnr, kPsnrIdentical);
  EXPECT_EQ(e.differing_pixels, 0u);
}

TEST(ImageMetrics, BlackVersusWhiteInOnePixel) {
  ImageRGBA a(2, 2, glm::vec4(0, 0, 0, 1)), b = a;
  b.at(1, 0) = glm::vec4(1, 1, 1, 0);  // alpha is ignored
  const ImageError e = image_error(a, b);
  EXPECT_DOUBLE_EQ(e.mae8, 255.0 / 4.0);
  EXPECT_DOUBLE_EQ(e.rmse, std::sqrt(0.25));
  EXPECT_NEAR(e.psnr, 20.0 * std::log10(2.0), 1e-12);
  EXPECT_EQ(e.max8, 255.0);
  EXPECT_EQ(e.differing_pixels, 1u);
}

TEST(ImageMetrics, SizeMismatchIsAnInputError) {
  EXPECT_THROW(image_error(ImageRGBA(2, 2), ImageRGBA(2, 3), "a.png vs b.png"), InputError);
}

TEST(ImageMetrics, MatchesTheMetricOfTheWrittenPngs) {
  ImageRGBA a(17, 9), b(17, 9);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 17; ++x) {
      a.at(x, y) = glm::vec4(x / 16.0f, y / 8.0f, 0.5f * (x + y) / 24.0f, 1.0f);
      b.at(x, y) = glm::vec4(std::sqrt(x / 16.0f), y / 9.0f, 0.25f, 1.0f);
    }
  const auto dir = std::filesystem::temp_directory_path() / "speculum_metrics_test";
  std::filesystem::create_directories(dir);
  write_image((dir / "a.png").string(), a);
  write_image((dir / "b.png").string(), b);
  const ImageError mem = image_error(a, b);
  const ImageError file = image_error(read_image((dir / "a.png").string()),
                                      read_image((dir / "b.png").string()));
  EXPECT_EQ(mem.mae8, file.mae8);
  EXPECT_EQ(mem.rmse, file.rmse);
  EXPECT_GT(mem.mae8, 0.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum
