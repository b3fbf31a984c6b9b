#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <OpenImageIO/imageio.h>

#include "core/error.h"
#include "core/image.h"
#include "core/output_file.h"
#include "core/png_check.h"

namespace speculum {

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float linear_to_srgb(float c) {
  return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

namespace {

constexpr long long kMaxPixels = 1ll << 28;  // 16384^2: anything larger is refused

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

// OpenEXR sizes each header attribute's value before reading it (OpenEXR 3.1 allocated 2 GB
// for a string attribute of a 40-byte file, found by fuzzing): the header is walked first and
// every attribute must fit in the file. The layout ("OpenEXR file layout", "Header"): magic
// and version (4 bytes each), then per part a list of attributes, each a name and a type name
// (NUL-terminated, at most 255 bytes with the long-names flag, else 31) and an int32 size,
// ended by an empty name; a multi-part file ends its list of headers with an empty header.
void check_exr_header(const std::string& path, const std::string& bytes) {
  auto bad = [&](const std::string& what) { throw InputError(path, "malformed EXR header: " + what); };
  if (bytes.size() < 8) bad("truncated");
  const std::uint32_t version = static_cast<unsigned char>(bytes[4]) | static_cast<unsigned char>(bytes[5]) << 8 |
                                static_cast<unsigned char>(bytes[6]) << 16 |
                                static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[7])) << 24;
  const bool multipart = version & 0x1000;
  const std::size_t max_name = (version & 0x400) ? 255 : 31;
  std::size_t at = 8;
  auto name = [&]() {
    const std::size_t end = bytes.find('\0', at);
    if (end == std::string::npos) bad("truncated");
    if (end - at > max_name) bad("name longer than " + std::to_string(max_name) + " bytes");
    std::string n = bytes.substr(at, end - at);
    at = end + 1;
    return n;
  };
  for (int part = 0;; ++part) {
    int attributes = 0;
    for (std::string n = name(); !n.empty(); n = name(), ++attributes) {
      (void)name();  // the type name
      if (bytes.size() - at < 4) bad("truncated");
      std::int32_t size = 0;
      std::memcpy(&size, bytes.data() + at, 4);
      at += 4;
      if (size < 0 || static_cast<std::size_t>(size) > bytes.size() - at)
        bad("attribute '" + n.substr(0, 40) + "' claims " + std::to_string(size) + " bytes, the file holds " +
            std::to_string(bytes.size() - at) + " more");
      at += static_cast<std::size_t>(size);
    }
    if (!multipart || attributes == 0 || part > 10000) return;
  }
}

}  // namespace

ImageRGBA read_image(const std::string& path, bool to_linear) {
  if (!std::filesystem::exists(path)) throw InputError(path, "no such file");
  {
    std::ifstream file(path, std::ios::binary);
    char magic[4] = {};
    file.read(magic, 4);
    if (file && std::memcmp(magic, "\x76\x2f\x31\x01", 4) == 0) {
      file.seekg(0);
      const std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
      check_exr_header(path, bytes);
    }
    if (file && std::memcmp(magic, "\x89PNG", 4) == 0) {
      file.seekg(0);
      const std::string bytes{std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
      const std::string problem =
          png_problem(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), kMaxPixels);
      if (!problem.empty()) throw InputError(path, "cannot read image: " + problem);
    }
  }
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string msg = OIIO::geterror();
    if (msg.empty()) msg = "not a readable image";
    auto nl = msg.find('\n');
    throw InputError(path, "cannot read image: " + msg.substr(0, nl));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
      static_cast<long long>(spec.width) * spec.height > kMaxPixels)
    throw InputError(path, "absurd image size " + std::to_string(spec.width) + "x" +
                               std::to_string(spec.height));
  // No format this reads packs more than about a thousand samples into a byte (deflate's
  // limit is 1032:1; run-length codes stay far below), so a header that declares more than
  // kMaxSamplesPerByte samples per byte of the file is refused before its buffer is reserved.
  constexpr double kMaxSamplesPerByte = 2048.0;
  const double samples = double(spec.width) * double(spec.height) * double(spec.nchannels);
  const double file_bytes = double(std::filesystem::file_size(path));
  if (samples > kMaxSamplesPerByte * file_bytes)
    throw InputError(path, "header declares " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                               " pixels, more than " + std::to_string(static_cast<long long>(file_bytes)) +
                               " bytes can hold");
  const int nc = spec.nchannels;
  std::vector<float> data(static_cast<std::size_t>(spec.width) * spec.height * nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, data.data())) {
    std::string msg = in->geterror();
    throw InputError(path, "truncated or corrupt image: " + msg.substr(0, msg.find('\n')));
  }
  const bool is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                        spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  const bool decode = to_linear && !is_float;
  ImageRGBA img(spec.width, spec.height, glm::vec4(0, 0, 0, 1));
  for (std::size_t i = 0; i < img.size(); ++i) {
    const float* p = &data[i * nc];
    glm::vec4 c(0, 0, 0, 1);
    if (nc == 1 || nc == 2) {
      c = glm::vec4(p[0], p[0], p[0], nc == 2 ? p[1] : 1.0f);
    } else {
      c = glm::vec4(p[0], p[1], p[2], nc >= 4 ? p[3] : 1.0f);
    }
    if (decode) {
      c.x = srgb_to_linear(c.x);
      c.y = srgb_to_linear(c.y);
      c.z = srgb_to_linear(c.z);
    }
    img.pixels[i] = c;
  }
  return img;
}

namespace {

// Writes interleaved float channels through a temporary file (core/output_file.h).
// `names` empty: OpenImageIO's default channel names (R, G, B, A / Y).
void write_float_channels(const std::string& path, int w, int h, int nc,
                          const std::vector<float>& linear,
                          const std::vector<std::string>& names = {}) {
  const std::string ext = extension_of(path);
  const bool is_exr = ext == ".exr";
  const bool is_png = ext == ".png";
  if (!is_exr && !is_png) throw InputError(path, "unsupported output format (use .png or .exr)");
  if (w <= 0 || h <= 0) throw InputError(path, "refusing to write an empty image");

  OutputFile file(path);
  const std::string& tmp = file.temp_path();
  auto out = OIIO::ImageOutput::create(tmp);
  if (!out) throw InputError(path, "no image writer for this format");

  bool ok = false;
  if (is_exr) {
    OIIO::ImageSpec spec(w, h, nc, OIIO::TypeDesc::FLOAT);
    if (!names.empty()) {
      spec.channelnames = names;
      spec.alpha_channel = -1;
      for (int c = 0; c < nc; ++c)
        if (names[static_cast<std::size_t>(c)] == "A") spec.alpha_channel = c;
    }
    spec.attribute("compression", "zip");
    // OpenEXR stamps the write time into `capDate`; a fixed value keeps the file bytes a
    // function of the pixels only (same inputs, same bytes: docs/architecture.md).
    spec.attribute("DateTime", "1970:01:01 00:00:00");
    ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::FLOAT, linear.data());
  } else {
    std::vector<unsigned char> bytes(linear.size());
    for (std::size_t i = 0; i < linear.size(); ++i) {
      const bool alpha = nc == 4 && (i % 4) == 3;
      float v = linear[i];
      if (!(v >= 0.0f)) v = 0.0f;  // also maps NaN to 0
      v = std::min(v, 1.0f);
      if (!alpha) v = linear_to_srgb(v);
      bytes[i] = static_cast<unsigned char>(std::lround(v * 255.0f));
    }
    OIIO::ImageSpec spec(w, h, nc, OIIO::TypeDesc::UINT8);
    ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  ok = out->close() && ok;
  if (!ok) {
    // OpenImageIO's message names the temporary file: name the user's instead.
    std::string msg = out->geterror();
    msg = msg.substr(0, msg.find('\n'));
    for (std::size_t at; (at = msg.find(tmp)) != std::string::npos;) msg.replace(at, tmp.size(), path);
    throw InputError(path, "cannot write image: " + (msg.empty() ? std::string("the image writer failed") : msg));
  }
  file.commit();
}

}  // namespace

void write_image(const std::string& path, const ImageRGBA& image) {
  std::vector<float> data(image.size() * 4);
  for (std::size_t i = 0; i < image.size(); ++i) {
    data[i * 4 + 0] = image.pixels[i].x;
    data[i * 4 + 1] = image.pixels[i].y;
    data[i * 4 + 2] = image.pixels[i].z;
    data[i * 4 + 3] = image.pixels[i].w;
  }
  write_float_channels(path, image.width, image.height, 4, data);
}

void write_image(const std::string& path, const ImageF& image) {
  write_float_channels(path, image.width, image.height, 1, image.pixels);
}

void write_exr_channels(const std::string& path, int width, int height,
                        const std::vector<std::string>& names, const std::vector<float>& interleaved) {
  if (extension_of(path) != ".exr") throw InputError(path, "named layers need an .exr output");
  const int nc = static_cast<int>(names.size());
  if (nc == 0 || interleaved.size() != std::size_t(width) * std::size_t(height) * names.size())
    throw std::invalid_argument("write_exr_channels: channel data does not match the names");
  write_float_channels(path, width, height, nc, interleaved, names);
}

}  // namespace speculum
