// What the PLY and STL formats promise, checked before OpenMesh reads a file: PLY values of
// their declared types, face corners naming existing vertices (ASCII and binary, both byte
// orders), short faces reported; ASCII STL facets of exactly three finite vertices, and the
// binary/ASCII decision made on the declared size. Each broken file is one InputError.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path dir = fs::temp_directory_path() / ("speculum_mesh_rules_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary | std::ios::trunc) << bytes;
  return dir / name;
}

// The InputError's message without the "file: " prefix ("" when the file loads).
std::string problem(const fs::path& file, LoadReport* report = nullptr) {
  SceneOptions o;
  o.report = report;
  try {
    load_scene(file.string(), o);
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(e.source(), file.string());
    return m;
  }
  return "";
}

const std::string kPlyHead =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
const std::string kVerts = "0 0 0\n1 0 0\n0 1 0\n";

#define EXPECT_PROBLEM(file, text) EXPECT_NE(problem(file).find(text), std::string::npos) << problem(file)

TEST(MeshFormatRules, AsciiPlyValuesMustMatchTheirDeclaredTypes) {
  EXPECT_EQ(problem(write("ok.ply", kPlyHead + kVerts + "3 0 1 2\n")), "");
  EXPECT_PROBLEM(write("word.ply", kPlyHead + "0 0 0\n1 0 abc\n0 1 0\n3 0 1 2\n"), "PLY value 'abc' is not a number");
  EXPECT_PROBLEM(write("frac.ply", kPlyHead + kVerts + "3 0 1 2.5\n"),
                 "PLY list item '2.5' is not an integer of its declared type");
  std::string uchar_head = kPlyHead;
  uchar_head.replace(uchar_head.find("uchar int"), 9, "uchar uchar");
  EXPECT_PROBLEM(write("range.ply", uchar_head + kVerts + "3 0 1 256\n"),
                 "PLY list item '256' is not an integer of its declared type");
}

TEST(MeshFormatRules, PlyFaceCornersMustNameExistingVertices) {
  EXPECT_PROBLEM(write("idx.ply", kPlyHead + kVerts + "3 0 1 99\n"),
                 "face 0 corner 2 indexes vertex 99, the file has 3 vertices");
  EXPECT_PROBLEM(write("neg.ply", kPlyHead + kVerts + "3 0 -5 1\n"), "face 0 corner 1 indexes vertex -5");
  // Binary, both byte orders, int corners.
  for (const bool big : {false, true}) {
    std::string b = kPlyHead;
    b.replace(b.find("ascii"), 5, big ? "binary_big_endian" : "binary_little_endian");
    auto put = [&](auto v) {
      char raw[sizeof(v)];
      std::memcpy(raw, &v, sizeof(v));
      if (big) std::reverse(raw, raw + sizeof(v));
      b.append(raw, sizeof(v));
    };
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(f);
    b += char(3);
    const std::string good = b;
    for (std::int32_t i : {0, 1, 2}) put(i);
    EXPECT_EQ(problem(write(big ? "be_ok.ply" : "le_ok.ply", b)), "") << big;
    b = good;
    for (std::int32_t i : {0, 1, 7}) put(i);
    EXPECT_PROBLEM(write(big ? "be.ply" : "le.ply", b), "face 0 corner 2 indexes vertex 7, the file has 3 vertices");
    b = good;
    for (std::int32_t i : {0, -1, 2}) put(i);
    EXPECT_PROBLEM(write(big ? "be_neg.ply" : "le_neg.ply", b), "face 0 corner 1 indexes vertex -1");
  }
}

TEST(MeshFormatRules, PlyFacesWithFewerThanThreeCornersAreReported) {
  std::string head = kPlyHead;
  head.replace(head.find("element face 1"), 14, "element face 2");
  LoadReport report;
  EXPECT_EQ(problem(write("two.ply", head + kVerts + "3 0 1 2\n2 0 1\n"), &report), "");
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("1 faces with fewer than 3 corners left out"), std::string::npos);
}

TEST(MeshFormatRules, NonManifoldPlyFacesAreKept) {
  // Three triangles on the edge 0-1: OpenMesh's importer keeps the third by duplicating
  // vertices (were a face refused, the loader would warn how many triangles were left out).
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 3\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n";
  const fs::path file = write("non_manifold.ply", ply);
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  const Scene s = load_scene(file.string(), o);
  EXPECT_EQ(s.mesh.triangle_count(), 3u);
  EXPECT_TRUE(report.warnings.empty());
}

TEST(MeshFormatRules, PlyFacesOpenMeshRefusesAreReported) {
  std::string head = kPlyHead;
  head.replace(head.find("element face 1"), 14, "element face 2");
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  const Scene s = load_scene(write("repeated_corner.ply", head + kVerts + "3 0 1 2\n3 0 0 1\n").string(), o);
  EXPECT_EQ(s.mesh.triangle_count(), 1u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0], "1 triangles left out (degenerate faces OpenMesh refuses)");
}

const std::string kFacet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";

TEST(MeshFormatRules, AsciiStlFacetsHaveThreeFiniteVertices) {
  EXPECT_EQ(problem(write("ok.stl", "solid t\n" + kFacet + "endsolid t\n")), "");
  EXPECT_EQ(problem(write("no_end.stl", "solid t\n" + kFacet)), "") << "a missing endsolid is tolerated";
  EXPECT_EQ(problem(write("nan_normal.stl", "solid t\nfacet normal nan nan nan\n" + kFacet.substr(kFacet.find("outer")))), "")
      << "the normal is recomputed";
  // kFacet with its first `from` replaced by `to`.
  const auto facet_with = [](const std::string& from, const std::string& to) {
    std::string f = kFacet;
    return f.replace(f.find(from), from.size(), to);
  };
  EXPECT_PROBLEM(write("nan_vertex.stl", "solid t\n" + facet_with("vertex 0 1 0", "vertex 0 1 nan")),
                 "ASCII STL line 6: non-finite vertex");
  EXPECT_PROBLEM(write("word.stl", "solid t\n" + facet_with("vertex 1 0 0", "vertex 1 0 x")),
                 "ASCII STL line 5: vertex 'x' is not a number");
  EXPECT_PROBLEM(write("four.stl", "solid t\n" + facet_with("endloop", "vertex 1 1 0\nendloop")),
                 "a facet has more than 3 vertices");
  EXPECT_PROBLEM(write("two.stl", "solid t\n" + facet_with("vertex 0 1 0\n", "")), "a facet has 2 vertices, not 3");
  EXPECT_PROBLEM(write("cut.stl", "solid t\n" + kFacet.substr(0, kFacet.find("vertex"))), "ASCII STL is truncated inside a facet");
  EXPECT_PROBLEM(write("empty_solid.stl", "solid t\nendsolid t\n"), "contains no faces");
}

TEST(MeshFormatRules, BinaryStlIsRecognisedBySizeAndItsCountMustMatch) {
  std::string b = "solid but binary";  // many exporters start binary headers with "solid"
  b.resize(80, ' ');
  const std::uint32_t one = 1;
  b.append(reinterpret_cast<const char*>(&one), 4);
  for (float f : {0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) b.append(reinterpret_cast<const char*>(&f), 4);
  b.append(2, '\0');
  EXPECT_EQ(problem(write("solid_binary.stl", b)), "");
  std::string other = b;
  other.replace(0, 5, "SOLID");
  EXPECT_PROBLEM(write("trailing.stl", other + "xxxx"), "binary STL declares 1 triangles (134 bytes) but the file has 138");
  EXPECT_PROBLEM(write("short.stl", other.substr(0, 120)), "(truncated)");
}

TEST(MeshFormatRules, ObjVerticesHaveThreeCoordinatesAndFaceIndicesFitAnInt) {
  const std::string v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(problem(write("ok.obj", v + "vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\nf -3//-1 -2//-1 -1//-1\n")), "");
  EXPECT_PROBLEM(write("two_coords.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n"),
                 "vertex 2 has 2 coordinates (OBJ's v line needs x y z)");
  EXPECT_PROBLEM(write("wrap.obj", v + "f 1 2 3 99999999999999999999\n"),
                 "line 4: face index '99999999999999999999' is not an integer within the int range");
  EXPECT_PROBLEM(write("word_index.obj", v + "f 1 2/x 3\n"), "line 4: face index 'x' is not an integer");
  LoadReport report;
  EXPECT_EQ(problem(write("short_face.obj", v + "f 1 2\nf 1 2 3\n"), &report), "");
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0], "1 faces with fewer than 3 corners left out");
}

// The built-in scene spec NAME[:key=value,...]: each key once, size a whole number.
TEST(SceneSpecRules, KeysAreGivenOnceAndSizeIsWhole) {
  auto spec_problem = [](const std::string& spec) -> std::string {
    try {
      (void)parse_builtin_spec(spec);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(spec_problem("bowl:size=2000,"), "");
  EXPECT_EQ(spec_problem("bowl:size=1.5k"), "");
  EXPECT_EQ(spec_problem("bowl:size=1000,size=2000"), "bowl:size=1000,size=2000: option 'size' is given twice");
  EXPECT_EQ(spec_problem("bumpy-sphere:n=3,n=4"), "bumpy-sphere:n=3,n=4: option 'n' is given twice");
  EXPECT_EQ(spec_problem("bowl:size=1000.5"), "bowl:size=1000.5: size must be a whole number");
}

}  // namespace
}  // namespace speculum
