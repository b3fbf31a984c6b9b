// sample_bilinear_repeat (core/shading.h) against the repeat wrap written out with a modulo
// for every index, bit for bit: inside the image, across its edges, many periods away on
// either side, on sides of one texel and of odd sizes.
#include <gtest/gtest.h>

#include <cmath>

#include "core/sampling.h"
#include "core/shading.h"

namespace speculum {
namespace {

glm::vec4 modulo_wrapped_lookup(const ImageRGBA& image, glm::vec2 uv) {
  const float fx = uv.x * static_cast<float>(image.width) - 0.5f;
  const float fy = uv.y * static_cast<float>(image.height) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float ax = fx - x0f, ay = fy - y0f;
  auto wrap = [](long long i, int n) { long long r = i % n; return static_cast<int>(r < 0 ? r + n : r); };
  const long long x0 = static_cast<long long>(x0f), y0 = static_cast<long long>(y0f);
  const int xa = wrap(x0, image.width), xb = wrap(x0 + 1, image.width);
  const int ya = wrap(y0, image.height), yb = wrap(y0 + 1, image.height);
  const glm::vec4 top = image.at(xa, ya) * (1.0f - ax) + image.at(xb, ya) * ax;
  const glm::vec4 bottom = image.at(xa, yb) * (1.0f - ax) + image.at(xb, yb) * ax;
  return top * (1.0f - ay) + bottom * ay;
}

TEST(TextureLookup, RepeatWrapGivesTheBitsOfTheModuloForEveryIndex) {
  for (const auto [w, h] : {std::pair{1, 1}, std::pair{3, 5}, std::pair{16, 16}, std::pair{7, 2}}) {
    ImageRGBA image(w, h);
    for (std::size_t i = 0; i < image.size(); ++i)
      image.pixels[i] = glm::vec4(random_float(std::uint32_t(i), 0, 0, 3), random_float(std::uint32_t(i), 0, 1, 3),
                                  float(i), 1.0f);
    for (std::uint32_t k = 0; k < 20000; ++k) {
      // Within [0, 1) for half of them, else up to ±40 periods away.
      const glm::vec2 u = random_float2(k, 0, 0, 5);
      const float spread = k % 2 == 0 ? 1.0f : 80.0f;
      const glm::vec2 uv = k % 2 == 0 ? u : (u - 0.5f) * spread;
      ASSERT_EQ(sample_bilinear_repeat(image, uv), modulo_wrapped_lookup(image, uv)) << w << "x" << h << " " << k;
    }
  }
}

}  // namespace
}  // namespace speculum
