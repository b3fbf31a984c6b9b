// See png_check.h.
#include "core/png_check.h"

#include <cstring>
#include <vector>

#include <png.h>

namespace speculum {

bool is_png(const unsigned char* bytes, std::size_t size) {
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return size >= 8 && std::memcmp(bytes, kSignature, 8) == 0;
}

std::string png_problem(const unsigned char* bytes, std::size_t size, long long max_pixels) {
  // The simplified API keeps errors and warnings in image.message instead of printing them
  // (libpng manual, "Simplified API").
  png_image image;
  std::memset(&image, 0, sizeof(image));
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes, size))
    return std::string("PNG: ") + image.message;
  if (static_cast<long long>(image.width) * image.height > max_pixels) {
    png_image_free(&image);
    return "PNG: absurd image size " + std::to_string(image.width) + "x" + std::to_string(image.height);
  }
  image.format = PNG_FORMAT_GRAY;  // the cheapest full decode: every row is inflated and unfiltered
  std::vector<unsigned char> pixels(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr)) return std::string("PNG: ") + image.message;
  return "";
}

}  // namespace speculum
