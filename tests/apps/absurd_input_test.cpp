// Absurd sizes on the command line and in files are refused up front: one line naming the
// limit, exit status 2, and no memory taken for what was asked (the process's peak resident
// set stays that of a program that only parsed its options).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// Far below what any of the refused requests would take (10^10 pixels, 2^31 vertices...),
// far above a run that stops after parsing, sanitizer builds included.
constexpr long kStartupRssKb = 400 * 1024;

std::string refused(const std::string& args, const fs::path& dir) {
  const test::CommandResult r = test::run_speculum(args, dir);
  EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("speculum: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_GT(r.peak_rss_kb, 0) << args;
  EXPECT_LT(r.peak_rss_kb, kStartupRssKb) << args;
  EXPECT_FALSE(fs::exists(dir / "x.png")) << args;
  return r.err;
}

TEST(AbsurdInput, FrameSizesAndSamplesNameTheirLimit) {
  const fs::path dir = test::scratch_dir();
  std::string e = refused("render --width 100000 --height 100000 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "--width")) << e;
  EXPECT_TRUE(test::contains(e, "16384")) << e;
  e = refused("inspect --width 16384 --height 16384 -q -o out", dir);
  EXPECT_TRUE(test::contains(e, "at most 8388608 (2^23)")) << e;
  e = refused("render -t reference --width 1 --height 1 --spp 1000000000 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "--spp")) << e;
  EXPECT_TRUE(test::contains(e, "65536")) << e;
  e = refused("render -t reference --width 4096 --height 4096 --spp 65536 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "reference takes at most 67108864 (2^26)")) << e;
  e = refused("render -t yu-lod --width 1 --height 1 --spp 1000000000 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "--spp")) << e;
  e = refused("render --spp 1000000000 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "--spp")) << e;
}

TEST(AbsurdInput, SceneSizesNameTheirLimit) {
  const fs::path dir = test::scratch_dir();
  std::string e = refused("render sphere-in-room:size=10000000000 --width 1 --height 1 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "10000000]")) << e;
  e = refused("render sphere-in-room:size=10000001 --width 1 --height 1 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "10000000]")) << e;
}

// A file claiming more than it holds, or more than a scene may hold: refused from its
// header (glTF accessors, binary STL, OFF), before the geometry is read.
TEST(AbsurdInput, FileCountsNameTheirLimit) {
  const fs::path dir = test::scratch_dir();
  const std::string tri = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";  // 3 vertices, base64
  auto gltf = [&](const char* name, const std::string& accessors, int nodes) {
    std::string nodes_json, roots;
    for (int i = 0; i < nodes; ++i) {
      nodes_json += std::string(i ? "," : "") + "{\"mesh\":0}";
      roots += std::string(i ? "," : "") + std::to_string(i);
    }
    std::ofstream(dir / name) << "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,"
                                 "\"uri\":\"data:application/octet-stream;base64," << tri << "\"}],"
                                 "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[" << accessors
                              << "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"nodes\":["
                              << nodes_json << "],\"scenes\":[{\"nodes\":[" << roots << "]}],\"scene\":0}";
    return test::sh_quote((dir / name).string());
  };
  // 2^31 elements in a 36-byte buffer.
  std::string e = refused("render " + gltf("claim.gltf", "{\"bufferView\":0,\"componentType\":5126,\"count\":2147483648,"
                                                         "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}", 1) +
                              " --width 1 --height 1 -q -o x.png",
                          dir);
  EXPECT_TRUE(test::contains(e, "absurd count 2147483648 (more than the limit of 2^28)")) << e;
  // 2^27 elements (within an accessor's limit) in the same buffer.
  e = refused("render " + gltf("short.gltf", "{\"bufferView\":0,\"componentType\":5126,\"count\":134217728,"
                                             "\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}", 1) +
                  " --width 1 --height 1 -q -o x.png",
              dir);
  EXPECT_TRUE(test::contains(e, "more than the limit of 33554432 vertices (2^25)")) << e;
  // 2^28 - 1 zeros from no bytes at all (an accessor without a bufferView).
  e = refused("render " + gltf("zeros.gltf", "{\"componentType\":5126,\"count\":268435455,\"type\":\"VEC3\","
                                             "\"min\":[0,0,0],\"max\":[0,0,0]}", 1) +
                  " --width 1 --height 1 -q -o x.png",
              dir);
  EXPECT_TRUE(test::contains(e, "more than the limit of 33554432 vertices (2^25)")) << e;
  // A binary STL claiming 2^24 + 1 triangles.
  {
    std::string stl(80, ' ');
    const std::uint32_t n = (1u << 24) + 1;
    stl.append(reinterpret_cast<const char*>(&n), 4);
    stl.append(50, '\0');
    std::ofstream(dir / "big.stl", std::ios::binary) << stl;
  }
  e = refused("render " + test::sh_quote((dir / "big.stl").string()) + " --width 1 --height 1 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "16777217 triangles: more than the limit of 16777216 (2^24)")) << e;
  std::ofstream(dir / "big.off") << "OFF\n2000000000 2000000000 0\n0 0 0\n";
  e = refused("render " + test::sh_quote((dir / "big.off").string()) + " --width 1 --height 1 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(e, "header declares 2000000000 vertices but the file has only")) << e;
}

// Coordinates that overflow a float are named as such in every mesh format (not as "no faces"
// or a broken camera).
TEST(AbsurdInput, OverflowingCoordinatesAreNonFiniteVertices) {
  const fs::path dir = test::scratch_dir();
  const std::string ply_head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const struct {
    const char* name;
    std::string text;
  } files[] = {
      {"inf.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n"},
      {"inf.ply", ply_head + "0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n"},
      {"inf2.ply", ply_head + "0 0 0\n1e999 0 0\n0 1 0\n3 0 1 2\n"},
      {"inf.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e39 0 0\nvertex 0 1 0\n"
                  "endloop\nendfacet\nendsolid t\n"},
      {"inf.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n"},
  };
  for (const auto& f : files) {
    std::ofstream(dir / f.name) << f.text;
    const std::string e = refused("info " + test::sh_quote((dir / f.name).string()), dir);
    EXPECT_TRUE(test::contains(e, "non-finite vertex")) << f.name << ": " << e;
  }
}

}  // namespace
}  // namespace speculum
