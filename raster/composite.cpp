// composite, supersample resolve and tonemap: see composite.h.
#include "raster/composite.h"

#include <algorithm>
#include <cmath>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace speculum::raster {

ImageRGBA composite(par::Executor& executor, const ImageRGBA& direct, const ImageRGBA& specular) {
  ImageRGBA out(direct.width, direct.height);
  executor.parallel_for("composite.add", out.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      out.pixels[i] = glm::vec4(glm::vec3(direct.pixels[i]) + glm::vec3(specular.pixels[i]), 1.0f);
  });
  return out;
}

ImageRGBA resolve_supersamples(par::Executor& executor, const ImageRGBA& samples, int k) {
  if (k <= 1) return samples;
  ImageRGBA out(samples.width / k, samples.height / k);
  const float inv = 1.0f / float(k * k);
  executor.parallel_for("resolve.box", out.size(), 2048, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const int x = int(i % out.width), y = int(i / out.width);
      glm::vec4 sum(0.0f);
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) sum += samples.at(x * k + sx, y * k + sy);
      out.pixels[i] = sum * inv;
    }
  });
  return out;
}

float meter_exposure(par::Executor& executor, const ImageRGBA& radiance) {
  struct Sum {
    double log_sum = 0.0;
    std::size_t count = 0;
  };
  const Sum total = executor.parallel_reduce(
      "tonemap.meter", radiance.size(), 8192, Sum{},
      [&](std::size_t begin, std::size_t end) {
        Sum s;
        for (std::size_t i = begin; i < end; ++i) {
          const glm::vec4& p = radiance.pixels[i];
          const double y = 0.2126 * p.x + 0.7152 * p.y + 0.0722 * p.z;
          if (std::isfinite(y) && y > 0.0) s.log_sum += std::log(y), ++s.count;
        }
        return s;
      },
      [](Sum a, const Sum& b) { return Sum{a.log_sum + b.log_sum, a.count + b.count}; });
  if (total.count == 0) return 1.0f;
  const double exposure = 0.18 / std::exp(total.log_sum / double(total.count));
  // A frame of luminance ~1e-38 would overflow the float; keep the value representable.
  return float(std::clamp(exposure, 1e-30, 1e30));
}

ImageRGBA tonemap(par::Executor& executor, const ImageRGBA& hdr, float exposure) {
  ImageRGBA out(hdr.width, hdr.height);
  executor.parallel_for("tonemap.aces", out.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      glm::vec4 c = hdr.pixels[i] * exposure;
      for (int ch = 0; ch < 3; ++ch) {
        const float x = std::max(c[ch], 0.0f);
        c[ch] = std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
      }
      c.w = 1.0f;
      out.pixels[i] = c;
    }
  });
  return out;
}

}  // namespace speculum::raster
