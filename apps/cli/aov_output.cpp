// G-buffer layers for `render --aov`: see aov_output.h.
#include "apps/cli/aov_output.h"

#include <algorithm>
#include <limits>

#include <glm/geometric.hpp>

#include "core/did_you_mean.h"
#include "core/error.h"

namespace speculum::cli {

const std::vector<std::string>& aov_names() {
  static const std::vector<std::string> names = {"albedo", "normal", "depth", "position", "roughness"};
  return names;
}

std::vector<std::string> parse_aovs(const std::string& list) {
  std::vector<std::string> out;
  std::string known;
  for (const std::string& n : aov_names()) known += (known.empty() ? "" : ", ") + n;
  std::size_t at = 0;
  while (at <= list.size()) {
    const std::size_t end = std::min(list.find(',', at), list.size());
    const std::string name = list.substr(at, end - at);
    at = end + 1;
    if (std::find(aov_names().begin(), aov_names().end(), name) == aov_names().end())
      throw InputError("--aov", "unknown layer '" + name + "'" + did_you_mean(name, aov_names()) +
                                    " (known: " + known + ")");
    if (std::find(out.begin(), out.end(), name) != out.end())
      throw InputError("--aov", "layer '" + name + "' given twice");
    out.push_back(name);
  }
  return out;
}

namespace {
std::vector<std::string> channels_of(const std::string& layer) {
  if (layer == "albedo") return {"R", "G", "B"};
  if (layer == "normal" || layer == "position") return {"X", "Y", "Z"};
  if (layer == "depth") return {"Z"};
  return {"Y"};  // roughness
}
}  // namespace

AovLayers make_aov_layers(const raster::GBuffer& g, int k, const Camera& camera,
                          const std::vector<std::string>& aovs) {
  AovLayers out;
  for (const std::string& layer : aovs)
    for (const std::string& c : channels_of(layer)) out.names.push_back(layer + "." + c);
  const int w = g.width / k, h = g.height / k;
  const std::size_t nc = out.names.size();
  out.data.assign(std::size_t(w) * std::size_t(h) * nc, 0.0f);
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const float inv = 1.0f / float(k * k);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::vec3 albedo(0.0f), normal(0.0f), position(0.0f);
      float roughness = 0.0f, depth = std::numeric_limits<float>::infinity();
      // Samples in a fixed order: the same sums, so the same bytes, every run.
      for (int sy = 0; sy < k; ++sy)
        for (int sx = 0; sx < k; ++sx) {
          const std::size_t i = std::size_t(y * k + sy) * std::size_t(g.width) + std::size_t(x * k + sx);
          if (!g.covered(i)) continue;
          albedo += g.surface[i].base_color;
          normal += g.normal.pixels[i];
          roughness += g.surface[i].roughness;
          const float d = glm::dot(g.position.pixels[i] - camera.eye, forward);
          if (d < depth) depth = d, position = g.position.pixels[i];
        }
      float* p = &out.data[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * nc];
      for (const std::string& layer : aovs) {
        if (layer == "albedo") *p++ = albedo.x * inv, *p++ = albedo.y * inv, *p++ = albedo.z * inv;
        else if (layer == "normal") *p++ = normal.x * inv, *p++ = normal.y * inv, *p++ = normal.z * inv;
        else if (layer == "position") *p++ = position.x, *p++ = position.y, *p++ = position.z;
        else if (layer == "depth") *p++ = depth;
        else *p++ = roughness * inv;
      }
    }
  return out;
}

}  // namespace speculum::cli
