// LDR-FLIP (core/image_flip.h), used by `compare --metric flip`: identical images give 0,
// every per-pixel value lies in [0, 1], the metric is symmetric, black vs white is near the
// top of the scale, more noise gives more error, and mismatched sizes are bad input.
#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image_flip.h"
#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

// A smooth colour pattern with some edges (squares) in it.
ImageRGBA pattern(int w, int h) {
  ImageRGBA img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool square = (x / 8 + y / 8) % 2 == 0;
      img.at(x, y) = {0.2f + 0.6f * float(x) / float(w), square ? 0.7f : 0.2f, 0.5f * float(y) / float(h), 1.0f};
    }
  return img;
}

// `img` with a deterministic pseudo-random offset of up to ±amplitude per channel.
ImageRGBA noisy(const ImageRGBA& img, float amplitude) {
  ImageRGBA out = img;
  std::uint32_t state = 12345u;
  for (auto& p : out.pixels)
    for (int c = 0; c < 3; ++c) {
      state = state * 1664525u + 1013904223u;
      const float u = float(state >> 8) / float(1u << 24);
      p[c] = std::clamp(p[c] + amplitude * (2.0f * u - 1.0f), 0.0f, 1.0f);
    }
  return out;
}

TEST(Flip, IdenticalImagesHaveZeroError) {
  const ImageRGBA a = pattern(40, 30);
  const FlipResult r = flip_error(a, a);
  EXPECT_EQ(r.mean, 0.0);
  EXPECT_EQ(r.max, 0.0);
  ASSERT_EQ(r.error.width, 40);
}

TEST(Flip, ValuesInUnitRangeAndSymmetric) {
  const ImageRGBA a = pattern(40, 30), b = noisy(a, 0.3f);
  const FlipResult ab = flip_error(a, b), ba = flip_error(b, a);
  for (float e : ab.error.pixels) {
    EXPECT_GE(e, 0.0f);
    EXPECT_LE(e, 1.0f);
  }
  EXPECT_EQ(ab.error.pixels, ba.error.pixels);
  EXPECT_EQ(ab.mean, ba.mean);
  EXPECT_GT(ab.mean, 0.0);
}

TEST(Flip, BlackAgainstWhiteIsNearTheTop) {
  const ImageRGBA black(32, 32, glm::vec4(0, 0, 0, 1)), white(32, 32, glm::vec4(1, 1, 1, 1));
  const FlipResult r = flip_error(black, white);
  // HyAB 100 against the green–blue maximum lands in the compressed top band (0.95, 1).
  EXPECT_GT(r.mean, 0.95);
  EXPECT_LE(r.max, 1.0);
}

TEST(Flip, MoreNoiseMoreError) {
  const ImageRGBA a = pattern(48, 32);
  double previous = 0;
  for (float amplitude : {0.02f, 0.08f, 0.3f}) {
    const double e = flip_error(a, noisy(a, amplitude)).mean;
    EXPECT_GT(e, previous) << amplitude;
    previous = e;
  }
}

TEST(Flip, SizeMismatchIsBadInput) {
  EXPECT_THROW(flip_error(pattern(8, 8), pattern(8, 9)), InputError);
}

TEST(Flip, CompareExitStatusWithFlip) {
  const auto dir = test::scratch_dir();
  const std::string a = (dir / "a.png").string(), b = (dir / "b.png").string();
  write_image(a, pattern(40, 30));
  write_image(b, noisy(pattern(40, 30), 0.1f));
  auto r = test::run_speculum("compare " + test::sh_quote(a) + " " + test::sh_quote(b) +
                                  " --metric flip --max 0.9 --diff " + test::sh_quote((dir / "d.png").string()),
                              dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("flip "), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(dir / "d.png"));
  r = test::run_speculum("compare " + test::sh_quote(a) + " " + test::sh_quote(b) + " --metric flip --max 0.001", dir);
  EXPECT_EQ(r.status, 1) << r.out;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum
