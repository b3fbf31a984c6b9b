#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/image.h"

namespace speculum {
namespace {

std::filesystem::path temp_dir() {
  auto dir = std::filesystem::temp_directory_path() / "speculum_image_test";
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(ImageIo, ExrRoundTripIsExact) {
  ImageRGBA img(7, 5);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      img.at(x, y) = glm::vec4(x * 0.37f, y * 1.5f + 100.0f, -0.25f * x, 1.0f / (1 + x + y));
  const std::string path = (temp_dir() / "round.exr").string();
  write_image(path, img);
  ImageRGBA back = read_image(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (std::size_t i = 0; i < img.size(); ++i) EXPECT_EQ(back.pixels[i], img.pixels[i]) << i;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The EXR header carries a capture date; writing the same pixels a second later must still
// give the same bytes (CI compares hashes of output files).
TEST(ImageIo, ExrBytesDoNotDependOnTheClock) {
  ImageRGBA img(3, 2, glm::vec4(0.25f, 0.5f, 2.0f, 1.0f));
  const std::string a = (temp_dir() / "clock_a.exr").string();
  const std::string b = (temp_dir() / "clock_b.exr").string();
  write_image(a, img);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  write_image(b, img);
  const std::string bytes_a = file_bytes(a);
  ASSERT_FALSE(bytes_a.empty());
  EXPECT_EQ(bytes_a, file_bytes(b));
}

TEST(ImageIo, PngEncodesSrgbAndDecodesBack) {
  ImageRGBA img(4, 1);
  img.pixels = {glm::vec4(0, 0, 0, 1), glm::vec4(0.5f, 0.5f, 0.5f, 1),
                glm::vec4(1, 1, 1, 1), glm::vec4(2, -1, 0.2140f, 1)};
  const std::string path = (temp_dir() / "srgb.png").string();
  write_image(path, img);
  ImageRGBA back = read_image(path);
  ASSERT_EQ(back.width, 4);
  EXPECT_NEAR(back.pixels[1].x, 0.5f, 0.005f);  // 8-bit sRGB quantization
  EXPECT_EQ(back.pixels[3].x, 1.0f);            // clamped
  EXPECT_EQ(back.pixels[3].y, 0.0f);
  EXPECT_NEAR(back.pixels[3].z, 0.2140f, 0.003f);
}

TEST(ImageIo, SrgbTransferFunctionsInvertEachOther) {
  for (int i = 0; i <= 1000; ++i) {
    float c = i / 1000.0f;
    EXPECT_NEAR(srgb_to_linear(linear_to_srgb(c)), c, 1e-5f);
  }
}

TEST(ImageIo, MissingFileNamesTheFile) {
  try {
    read_image("/nonexistent/dir/nothing.exr");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/nothing.exr"), std::string::npos);
  }
}

// A 55-byte Radiance file whose header declares 999999 × 99 pixels is refused from its
// header, before ~1.6 GB of floats are reserved for it (the fuzzer found it taking seconds).
TEST(ImageIo, HeaderDeclaringMorePixelsThanTheFileCanHoldIsRefused) {
  const auto path = temp_dir() / "huge_header.hdr";
  {
    std::ofstream out(path, std::ios::binary);
    out << "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 999999 +X 99\n";
  }
  try {
    read_image(path.string());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bytes can hold"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("huge_header.hdr"), std::string::npos) << e.what();
  }
}

TEST(ImageIo, UnsupportedOutputFormatIsRejectedWithoutWriting) {
  ImageRGBA img(2, 2);
  const auto path = temp_dir() / "out.bmpx";
  EXPECT_THROW(write_image(path.string(), img), InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace speculum
