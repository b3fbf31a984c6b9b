// The last passes of a feed-forward frame (raster/composite.h): composite (direct +
// specular, the SOFF lerp with the Fresnel weights already in the layers), the k×k box
// resolve and the exposure + Narkowicz ACES tonemap.
#include "raster/composite.h"

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

namespace speculum::raster {
namespace {

// The documented tonemap of one channel, in double: Narkowicz's ACES fit, clamped to [0, 1].
double aces(double x) {
  x = std::max(x, 0.0);
  return std::clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Deterministic, non-trivial pixel values.
glm::vec4 pattern(int x, int y, float scale) {
  return glm::vec4(scale * float((x * 7 + y * 3) % 11), scale * float((x + 2 * y) % 5),
                   scale * float((x * y) % 13), 0.25f * float((x + y) % 4));
}

// A w × h image of pattern(x, y, scale), or of pattern(y, x, scale) when `transposed`.
ImageRGBA pattern_image(int w, int h, float scale, bool transposed = false) {
  ImageRGBA im(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.at(x, y) = transposed ? pattern(y, x, scale) : pattern(x, y, scale);
  return im;
}

TEST(Composite, IsDirectPlusSpecularPerChannelWithOpaqueAlpha) {
  // More pixels than one parallel chunk (8192), so every chunk is covered.
  const int w = 150, h = 70;
  const ImageRGBA direct = pattern_image(w, h, 0.5f), specular = pattern_image(w, h, 0.125f, true);
  par::Executor ex(2);
  const ImageRGBA out = composite(ex, direct, specular);
  ASSERT_EQ(out.width, w);
  ASSERT_EQ(out.height, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4 d = direct.at(x, y), s = specular.at(x, y), c = out.at(x, y);
      for (int ch = 0; ch < 3; ++ch) ASSERT_FLOAT_EQ(c[ch], d[ch] + s[ch]) << x << "," << y;
      ASSERT_EQ(c.w, 1.0f);
    }
}

TEST(Composite, ZeroSpecularKeepsDirectAndZeroDirectKeepsSpecular) {
  const ImageRGBA a = pattern_image(3, 2, 0.3f), zero(3, 2, glm::vec4(0.0f));
  par::Executor ex(1);
  const ImageRGBA l = composite(ex, a, zero), r = composite(ex, zero, a);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(glm::vec3(l.pixels[i]), glm::vec3(a.pixels[i]));
    EXPECT_EQ(glm::vec3(r.pixels[i]), glm::vec3(a.pixels[i]));
  }
}

TEST(ResolveSupersamples, OneByOneIsTheIdentity) {
  const ImageRGBA samples = pattern_image(5, 3, 1.5f);
  par::Executor ex(2);
  const ImageRGBA out = resolve_supersamples(ex, samples, 1);
  ASSERT_EQ(out.width, 5);
  ASSERT_EQ(out.height, 3);
  for (std::size_t i = 0; i < samples.size(); ++i) EXPECT_EQ(out.pixels[i], samples.pixels[i]);
}

TEST(ResolveSupersamples, TwoByTwoBoxOfAHandMadeBuffer) {
  // 4×2 samples → 2×1 pixels; each pixel the mean of its 2×2 block (alpha included).
  ImageRGBA s(4, 2);
  s.at(0, 0) = {1, 0, 0, 1};
  s.at(1, 0) = {0, 1, 0, 1};
  s.at(0, 1) = {0, 0, 1, 0};
  s.at(1, 1) = {3, 3, 3, 0};  // left pixel: (4, 4, 4, 2) / 4
  s.at(2, 0) = {8, 8, 8, 1};
  s.at(3, 0) = {0, 0, 0, 1};
  s.at(2, 1) = {0, 0, 0, 1};
  s.at(3, 1) = {0, 0, 0, 1};  // right pixel: one bright sample of four
  par::Executor ex(2);
  const ImageRGBA out = resolve_supersamples(ex, s, 2);
  ASSERT_EQ(out.width, 2);
  ASSERT_EQ(out.height, 1);
  EXPECT_EQ(out.at(0, 0), glm::vec4(1.0f, 1.0f, 1.0f, 0.5f));
  EXPECT_EQ(out.at(1, 0), glm::vec4(2.0f, 2.0f, 2.0f, 1.0f));
}

TEST(ResolveSupersamples, KByKIsTheBlockMean) {
  for (int k : {2, 3, 4}) {
    SCOPED_TRACE(k);
    const int w = 7, h = 5;  // output size; samples are (w·k)×(h·k)
    const ImageRGBA s = pattern_image(w * k, h * k, 0.25f);
    par::Executor ex(2);
    const ImageRGBA out = resolve_supersamples(ex, s, k);
    ASSERT_EQ(out.width, w);
    ASSERT_EQ(out.height, h);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double sum[4] = {0, 0, 0, 0};
        for (int sy = 0; sy < k; ++sy)
          for (int sx = 0; sx < k; ++sx)
            for (int ch = 0; ch < 4; ++ch) sum[ch] += s.at(x * k + sx, y * k + sy)[ch];
        for (int ch = 0; ch < 4; ++ch)
          EXPECT_NEAR(out.at(x, y)[ch], sum[ch] / (k * k), 1e-5) << x << "," << y << " ch " << ch;
      }
  }
}

TEST(ResolveSupersamples, AConstantBufferStaysConstant) {
  const glm::vec4 c(0.3f, 1.7f, 42.0f, 1.0f);
  ImageRGBA s(9, 6, c);
  par::Executor ex(2);
  const ImageRGBA out = resolve_supersamples(ex, s, 3);
  ASSERT_EQ(out.width, 3);
  ASSERT_EQ(out.height, 2);
  for (const glm::vec4& p : out.pixels)
    for (int ch = 0; ch < 4; ++ch) EXPECT_NEAR(p[ch], c[ch], 1e-5f * std::abs(c[ch]));
}

TEST(Tonemap, BlackAndNegativeGoToZeroWithOpaqueAlpha) {
  ImageRGBA hdr(2, 1);
  hdr.at(0, 0) = {0, 0, 0, 0};
  hdr.at(1, 0) = {-1, -0.001f, -100, 0.5f};
  par::Executor ex(1);
  const ImageRGBA out = tonemap(ex, hdr, 3.0f);
  for (const glm::vec4& p : out.pixels) EXPECT_EQ(p, glm::vec4(0, 0, 0, 1));
}

TEST(Tonemap, MatchesTheNarkowiczAcesFitTimesExposure) {
  const float values[] = {0.01f, 0.1f, 0.18f, 0.5f, 1.0f, 2.0f, 4.0f, 7.0f};
  for (float exposure : {1.0f, 0.5f, 2.5f}) {
    SCOPED_TRACE(exposure);
    ImageRGBA hdr(8, 1);
    for (int i = 0; i < 8; ++i) hdr.at(i, 0) = {values[i], values[7 - i], 0.5f * values[i], 0.0f};
    par::Executor ex(2);
    const ImageRGBA out = tonemap(ex, hdr, exposure);
    for (int i = 0; i < 8; ++i) {
      const glm::vec4 in = hdr.at(i, 0), p = out.at(i, 0);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(p[ch], aces(double(in[ch]) * exposure), 1e-6) << i << " ch " << ch;
      EXPECT_EQ(p.w, 1.0f);
    }
  }
  // One value by hand: x = 1 → (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16.
  ImageRGBA one(1, 1, glm::vec4(1.0f));
  par::Executor ex(1);
  EXPECT_NEAR(tonemap(ex, one).at(0, 0).x, 2.54 / 3.16, 1e-6);
}

TEST(Tonemap, IsMonotoneAndSaturatesAtOne) {
  // A ramp from 0 to 100 in one channel: non-decreasing, strictly increasing where the fit
  // is below 1 (up to x ≈ 7.24), within [0, 1], and 1 far beyond.
  const int n = 20000;
  ImageRGBA hdr(n, 1);
  for (int i = 0; i < n; ++i) hdr.at(i, 0) = glm::vec4(100.0f * float(i) / float(n - 1), 0, 0, 1);
  par::Executor ex(2);
  const ImageRGBA out = tonemap(ex, hdr);
  for (int i = 0; i < n; ++i) {
    const float v = out.at(i, 0).x;
    ASSERT_GE(v, 0.0f);
    ASSERT_LE(v, 1.0f);
    if (i == 0) continue;
    const float prev = out.at(i - 1, 0).x;
    ASSERT_GE(v, prev) << "x = " << hdr.at(i, 0).x;
    if (hdr.at(i, 0).x < 7.0f) {
      ASSERT_GT(v, prev) << "x = " << hdr.at(i, 0).x;
    }
  }
  EXPECT_EQ(out.at(n - 1, 0).x, 1.0f);
  EXPECT_EQ(out.at(0, 0).x, 0.0f);
}

TEST(Tonemap, ChannelsAreIndependent) {
  ImageRGBA a(1, 1, glm::vec4(0.2f, 0.2f, 0.2f, 1.0f)), b(1, 1, glm::vec4(0.2f, 5.0f, 0.0f, 1.0f));
  par::Executor ex(1);
  EXPECT_EQ(tonemap(ex, a).at(0, 0).x, tonemap(ex, b).at(0, 0).x);
}

}  // namespace
}  // namespace speculum::raster
