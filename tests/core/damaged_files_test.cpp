// Every loader on damaged copies of valid files: each file cut at many lengths and with
// single bytes flipped at many places must load or be rejected with one InputError naming
// it (one line) — never a crash, a hang or another exception. The positions are a fixed
// sequence, so the test is deterministic; under ASan it also catches out-of-bounds reads.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <unistd.h>

#include "tests/test_dependency.h"

#include "core/error.h"
#include "core/scene_loader.h"
#include "tests/core/scene_test_util.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
}

template <class T>
void put(std::string& b, T v, bool big_endian = false) {
  char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  if (big_endian) std::reverse(raw, raw + sizeof(T));
  b.append(raw, sizeof(T));
}

// A binary PLY tetrahedron with uchar/int face lists (the common layout) in either byte order.
std::string binary_ply(bool big_endian) {
  std::string b = std::string("ply\nformat ") + (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f}) put(b, f, big_endian);
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    b += char(3);
    for (int i : f) put(b, i, big_endian);
  }
  return b;
}

// A binary STL of the same tetrahedron.
std::string binary_stl() {
  std::string b(80, ' ');
  put(b, std::uint32_t{4});
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}}) {
    for (int k = 0; k < 3; ++k) put(b, 0.0f);
    for (int i : f)
      for (int k = 0; k < 3; ++k) put(b, v[i][k]);
    put(b, std::uint16_t{0});
  }
  return b;
}

struct Outcome {
  std::size_t loaded = 0, rejected = 0;
};

// Loads `file` (already written): a scene, or one InputError naming the file on one line.
void load_or_reject(const fs::path& file, Outcome& out) {
  try {
    (void)load_scene(file.string());
    ++out.loaded;
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), file.string());
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    ++out.rejected;
  } catch (const std::exception& e) {
    ADD_FAILURE() << file << ": not an InputError: " << e.what();
  }
}

// `bytes` as `name` in `dir`, cut at about 40 lengths (every length for short files) and with
// 64 single bytes inverted (one at a time) at positions spread over the file.
Outcome damage(const fs::path& dir, const std::string& name, const std::string& bytes) {
  Outcome out;
  const fs::path file = dir / name;
  const std::size_t n = bytes.size();
  const std::size_t step = std::max<std::size_t>(1, n / 40);
  for (std::size_t len = 0; len < n; len += step) {
    SCOPED_TRACE(name + " cut at " + std::to_string(len));
    write_bytes(file, bytes.substr(0, len));
    load_or_reject(file, out);
  }
  for (std::size_t k = 0; k < 64; ++k) {
    const std::size_t at = (k * 7919 + k * k * 31) % n;
    SCOPED_TRACE(name + " byte " + std::to_string(at) + " inverted");
    std::string flipped = bytes;
    flipped[at] = static_cast<char>(~static_cast<unsigned char>(flipped[at]));
    write_bytes(file, flipped);
    load_or_reject(file, out);
  }
  write_bytes(file, bytes);
  return out;
}

fs::path damaged_scratch(const std::string& what) { return testing::temp_dir("damaged_" + what); }

TEST(DamagedFiles, TestDataFilesCutAndFlippedLoadOrAreRejected) {
  const fs::path good = fs::path(SPECULUM_TEST_DATA) / "good";
  const fs::path dir = damaged_scratch("good");
  for (const char* companion : {"quad.mtl", "checker.png"}) fs::copy_file(good / companion, dir / companion);
  std::size_t rejected = 0;
  for (const char* name : {"triangle.gltf", "triangle.glb", "tetra.obj", "quad.obj", "tetra.off", "tetra.ply", "tetra.stl"}) {
    const std::string bytes = read_bytes(good / name);
    ASSERT_FALSE(bytes.empty()) << name;
    const Outcome o = damage(dir, name, bytes);
    rejected += o.rejected;
    // The intact file loads (the last write restores it).
    Outcome intact;
    load_or_reject(dir / name, intact);
    EXPECT_EQ(intact.loaded, 1u) << name;
  }
  EXPECT_GT(rejected, 100u);  // the damage is real: most cuts are refused
  fs::remove_all(dir);
}

TEST(DamagedFiles, BinaryPlyBothEndiansAndBinaryStlCutAndFlipped) {
  const fs::path dir = damaged_scratch("binary");
  const struct {
    const char* name;
    std::string bytes;
  } files[] = {{"le.ply", binary_ply(false)}, {"be.ply", binary_ply(true)}, {"tetra.stl", binary_stl()}};
  for (const auto& f : files) {
    Outcome intact;
    write_bytes(dir / f.name, f.bytes);
    load_or_reject(dir / f.name, intact);
    ASSERT_EQ(intact.loaded, 1u) << f.name << " (the undamaged file must load)";
    const Outcome o = damage(dir, f.name, f.bytes);
    EXPECT_GT(o.rejected, 10u) << f.name;
  }
  fs::remove_all(dir);
}

// A few real-world files of Debian's assimp-testmodels, one per format and encoding.
TEST(DamagedFiles, RealWorldFilesCutAndFlippedLoadOrAreRejected) {
  const fs::path models = "/usr/share/assimp/models";
  SPECULUM_REQUIRE(fs::exists(models), "the Debian package assimp-testmodels");
  const fs::path dir = damaged_scratch("assimp");
  std::size_t tried = 0;
  for (const char* rel : {"glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", "glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf",
                          "PLY/cube_binary.ply", "PLY/cube.ply", "STL/Spider_binary.stl",
                          "STL/triangle.stl", "OFF/Cube.off", "OBJ/box.obj"}) {
    const fs::path src = models / rel;
    if (!fs::exists(src)) continue;
    ++tried;
    (void)damage(dir, src.filename().string(), read_bytes(src));
  }
  EXPECT_GE(tried, 6u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum
