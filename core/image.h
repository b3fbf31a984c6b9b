// Image buffers: float RGBA radiance, single-channel float, and integer id buffers.
// Row-major, origin at the top-left pixel, pixel centres at (x + 0.5, y + 0.5).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

namespace speculum {

template <class Pixel>
struct Buffer2D {
  int width = 0;
  int height = 0;
  std::vector<Pixel> pixels;

  Buffer2D() = default;
  Buffer2D(int w, int h, Pixel fill = Pixel{})
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * h, fill) {}

  std::size_t size() const { return pixels.size(); }
  bool empty() const { return pixels.empty(); }
  Pixel& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  const Pixel& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
};

using ImageRGBA = Buffer2D<glm::vec4>;  // linear radiance / colour
using ImageF = Buffer2D<float>;         // depth, distance, scalar fields
using IdBuffer = Buffer2D<std::uint32_t>;

constexpr std::uint32_t kNoId = 0xffffffffu;

// Reads EXR, HDR, PNG, JPEG (anything OpenImageIO reads) as linear RGBA float.
// 8-bit images are decoded from sRGB unless `srgb_to_linear` is false (data textures
// such as normal or metallic-roughness maps). Throws InputError naming the file.
ImageRGBA read_image(const std::string& path, bool srgb_to_linear = true);

// Writes linear RGBA float: `.exr` keeps floats; `.png` is clamped and sRGB-encoded
// (tone-map first for HDR content). Written to a temporary file then renamed, so a
// failure never leaves a half-written output. Throws InputError naming the file.
void write_image(const std::string& path, const ImageRGBA& image);
void write_image(const std::string& path, const ImageF& image);
// Writes an EXR whose channels are named (`names`, e.g. "R","G","B","A","albedo.R",
// "normal.X", "depth.Z": OpenImageIO's layer.channel convention), `interleaved` holding
// names.size() floats per pixel, rows top to bottom. Same temporary-file rule.
void write_exr_channels(const std::string& path, int width, int height,
                        const std::vector<std::string>& names, const std::vector<float>& interleaved);

float srgb_to_linear(float c);
float linear_to_srgb(float c);

}  // namespace speculum
