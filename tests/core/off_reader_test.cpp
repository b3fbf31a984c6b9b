// core/off_reader.h: every variant of Geomview's OFF the reader accepts gives the exact values
// written (hand-made files), malformed files give one named problem before anything is
// reserved, and Debian's assimp-testmodels OFF files load to exactly what OpenMesh's reader
// (the loader these files went through before) makes of them.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "core/error.h"
#include "core/off_reader.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"
#include "tests/test_dependency.h"

namespace speculum {
namespace {

std::string off_problem(const std::string& text) {
  try {
    (void)read_off("t.off", text);
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "t.off");
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line";
    return e.problem();
  }
  return "(read)";
}

const std::vector<glm::vec3> kTriangle = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};

TEST(OffReader, PlainOffWithCommentsAndPolygonFans) {
  const OffMesh m = read_off("t.off",
                             "# a comment before the keyword\nOFF\n# counts next\n4 2 0\n"
                             "0 0 0\n1 0 0  # trailing comment\n1 1 0\n0 1 0\n"
                             "4 0 1 2 3\n3 3 2 1\n");
  EXPECT_EQ(m.positions, (std::vector<glm::vec3>{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}));
  // The quad fans out from its first corner, then the triangle.
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 1}));
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(m.uvs.empty());
  EXPECT_EQ(m.faces, 2u);
}

TEST(OffReader, KeywordIsOptionalAndCountsMayShareItsLine) {
  const std::string body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(read_off("t.off", "3 1 0\n" + body).positions, kTriangle);
  EXPECT_EQ(read_off("t.off", "OFF 3 1 0\n" + body).indices, (std::vector<std::uint32_t>{0, 1, 2}));
  // Free-form white space: a vertex may span lines, values may be signed or in exponent form.
  const OffMesh m = read_off("t.off", "OFF\n3 1 0\n+0 0\n0 1e0 0 0 0 1.0e+0\n0\n3 0 1 2");
  EXPECT_EQ(m.positions, kTriangle);
}

TEST(OffReader, ColoursNormalsAndTextureCoordinates) {
  // COFF: a colour of 4, 3 or 1 values to the end of the vertex's line; faces with colours.
  const OffMesh c = read_off("t.off",
                             "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 1 0\n0 1 0 7\n3 0 1 2 0.5 0.5 0.5 1\n");
  EXPECT_EQ(c.positions, kTriangle);
  EXPECT_EQ(c.indices, (std::vector<std::uint32_t>{0, 1, 2}));
  // NOFF: normals after the position; STOFF: texture coordinates; STCNOFF: all, in that order.
  const OffMesh n = read_off("t.off", "NOFF\n3 1 0\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
  EXPECT_EQ(n.normals, (std::vector<glm::vec3>{{0, 0, 2}, {0, 0, 1}, {0, 0, 1}}));
  const OffMesh st = read_off("t.off", "STOFF\n3 1 0\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 0.5\n3 0 1 2\n");
  EXPECT_EQ(st.uvs, (std::vector<glm::vec2>{{0, 0}, {1, 0}, {0, 0.5f}}));
  const OffMesh all =
      read_off("t.off", "STCNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1 1 0.25 0.75\n1 0 0 0 0 1 0.5 0.5 0.5 1 0\n0 1 0 0 0 1 3 0 1\n3 0 1 2\n");
  EXPECT_EQ(all.positions, kTriangle);
  EXPECT_EQ(all.normals, (std::vector<glm::vec3>(3, {0, 0, 1})));
  EXPECT_EQ(all.uvs, (std::vector<glm::vec2>{{0.25f, 0.75f}, {1, 0}, {0, 1}}));
}

TEST(OffReader, HomogeneousAndDimensionedVertices) {
  // 4OFF divides by w; nOFF with Ndim 3 is plain OFF, 4nOFF with Ndim 3 is 4OFF.
  const std::string faces = "3 0 1 2\n";
  EXPECT_EQ(read_off("t.off", "4OFF\n3 1 0\n0 0 0 2\n4 0 0 4\n0 0.5 0 0.5\n" + faces).positions, kTriangle);
  EXPECT_EQ(read_off("t.off", "nOFF\n3\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n" + faces).positions, kTriangle);
  EXPECT_EQ(read_off("t.off", "4nOFF\n3\n3 1 0\n0 0 0 1\n2 0 0 2\n0 1 0 1\n" + faces).positions, kTriangle);
  EXPECT_EQ(off_problem("nOFF\n4\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n" + faces),
            "OFF: 4-dimensional vertices (nOFF) cannot be rendered, only 3-D ones");
  EXPECT_EQ(off_problem("4OFF\n3 1 0\n0 0 0 1\n1 0 0 0\n0 1 0 1\n" + faces),
            "non-finite vertex 1 (a coordinate is NaN, infinite or overflows a float, or its homogeneous w is 0)");
}

// Binary OFF: big-endian 32-bit ints and floats after the line holding BINARY; each face ends
// with its colour count and that many floats.
std::string big_endian(std::initializer_list<std::uint32_t> words) {
  std::string s;
  for (std::uint32_t w : words)
    for (int b = 3; b >= 0; --b) s += static_cast<char>((w >> (8 * b)) & 0xffu);
  return s;
}
std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

TEST(OffReader, BinaryBigEndian) {
  const std::string head = "OFF BINARY # comment\n";
  const std::string counts = big_endian({3, 2, 0});
  const std::string verts = big_endian({bits(0), bits(0), bits(0), bits(1), bits(0), bits(0), bits(0), bits(1), bits(0)});
  // A triangle with a 4-value colour, then a 2-corner face (left out).
  const std::string faces = big_endian({3, 0, 1, 2, 4, bits(1), bits(0), bits(0), bits(1), 2, 0, 1, 0});
  const OffMesh m = read_off("t.off", head + counts + verts + faces);
  EXPECT_EQ(m.positions, kTriangle);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.short_faces, 1u);
  // Truncated, absurd counts, a corner count past the data, an index out of range.
  EXPECT_EQ(off_problem(head + counts + verts + faces.substr(0, 10)),
            "OFF face 0 claims 3 corners but the file holds only 6 more bytes");
  EXPECT_EQ(off_problem(head + counts + verts + faces.substr(0, 24)),
            "binary OFF data truncated: the file ends before face 0's colour");
  EXPECT_EQ(off_problem(head + big_endian({0x7fffffff, 1, 0}) + verts),
            "header declares 2147483647 vertices but the file has only 69 bytes");
  EXPECT_EQ(off_problem(head + counts + verts + big_endian({0x40000000, 0, 1, 2})),
            "OFF face 0 claims 1073741824 corners but the file holds only 12 more bytes");
  EXPECT_EQ(off_problem(head + counts + verts + big_endian({3, 0, 1, 3, 0, 3, 0, 1, 2, 0})),
            "OFF face 0: vertex index 3 is out of range (3 vertices)");
  EXPECT_EQ(off_problem(head + big_endian({3, 0xffffffffu, 0}) + verts), "binary OFF header: the face count is negative");
}

TEST(OffReader, ShortAndDegenerateFacesAreCountedAndLeftOut) {
  const OffMesh m = read_off("t.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0\n2 0 1\n3 0 0 1\n4 0 1 1 2\n");
  EXPECT_EQ(m.short_faces, 2u);
  // "3 0 0 1" is one degenerate triangle; "4 0 1 1 2" fans to (0 1 1), left out, and (0 1 2).
  EXPECT_EQ(m.degenerate_triangles, 2u);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(OffReader, MalformedFilesNameTheProblem) {
  const std::string v = "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_EQ(off_problem(""), "file holds no OFF data (only white space or comments)");
  EXPECT_EQ(off_problem("PLY\n"), "missing OFF header (neither the OFF keyword nor a vertex count comes first)");
  EXPECT_EQ(off_problem("XOFF\n3 1 0\n"), "OFF header: 'XOFF' is not an OFF keyword ([ST][C][N][4][n]OFF)");
  EXPECT_EQ(off_problem("OFF\n3 x 0\n"), "OFF header: the face count 'x' is not a whole number below 10^12");
  // Free-form white space: a missing edge count takes the first coordinate's place.
  EXPECT_EQ(off_problem("OFF\n3 1\n" + v), "OFF data truncated: the file ends before vertex 2");
  // Absurd counts are refused from the header, before anything is reserved.
  EXPECT_EQ(off_problem("OFF\n1000000000 1 0\n0 0 0\n"), "header declares 1000000000 vertices but the file has only 25 bytes");
  EXPECT_EQ(off_problem("OFF\n3 1000000000 0\n" + v), "header declares 1000000000 faces but the file has only 37 bytes");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n" + v + "400000000 0 1 2\n"),
            "OFF face 0 claims 400000000 corners but the file holds only 7 more bytes");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n" + v + "-50 0 1 2\n"), "OFF face 0 has a negative corner count '-50'");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n" + v + "3 0 1 3\n"), "OFF face 0: vertex index 3 is out of range (3 vertices)");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n" + v + "3 0 -1 2\n"), "OFF face 0: vertex index -1 is out of range (3 vertices)");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n" + v + "3 0 1 2.5\n"), "OFF face 0: vertex index '2.5' is not a whole number");
  EXPECT_EQ(off_problem("OFF\n3 2 0\n" + v + "3 0 1 2\n"),
            "OFF data truncated: the file ends before face 1 (the header declares 2 faces)");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n"),
            "OFF data truncated: the file ends before face 0 (the header declares 1 faces)");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1\n"), "OFF data truncated: the file ends before vertex 2");
  EXPECT_EQ(off_problem("OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n"), "OFF vertex 1: 'zero' is not a number");
  // Two faces on one line: the second face's values are read as the first one's colour (at
  // most 4 numbers), and the second face is missing.
  EXPECT_EQ(off_problem("OFF\n3 2 0\n" + v + "3 0 1 2 3 2 1 0\n"),
            "OFF data truncated: the file ends before face 1 (the header declares 2 faces)");
  EXPECT_EQ(off_problem("OFF\n3 2 0\n" + v + "3 0 1 2 4 2 1 0 9\n"),
            "OFF face 0: '9' after its corners is not part of a colour (0 to 4 numbers to the end of the line)");
  EXPECT_EQ(off_problem("COFF\n3 1 0\n0 0 0 1 1 1 1 1\n1 0 0\n0 1 0\n3 0 1 2\n"), "OFF vertex 0: more than 4 colour values");
}

// Coordinates that overflow a float (or a double), NaN and infinity: the vertex is named.
TEST(OffReader, NonFiniteVerticesAreNamed) {
  for (const char* bad : {"1e39", "-1e39", "1e999", "nan", "inf", "-inf"}) {
    SCOPED_TRACE(bad);
    EXPECT_EQ(off_problem(std::string("OFF\n3 1 0\n0 0 0\n1 ") + bad + " 0\n0 1 0\n3 0 1 2\n"),
              "non-finite vertex 1 (a coordinate is NaN, infinite or overflows a float)");
  }
  // Below the smallest float is zero, not an error.
  EXPECT_EQ(read_off("t.off", "OFF\n3 1 0\n0 0 1e-999\n1 0 0\n0 1 0\n3 0 1 2\n").positions, kTriangle);
}

// Through load_scene: the scene's mesh, normals from the file (normalised) or computed, the
// "no faces" cases, and a large header count rejected without reserving it.
TEST(OffReader, LoadSceneUsesTheReader) {
  const auto dir = testing::temp_dir("off_reader");
  const auto write = [&](const char* name, const std::string& text) {
    testing::write_text(dir / name, text);
    return (dir / name).string();
  };
  LoadReport report;
  SceneOptions options;
  options.report = &report;
  const Scene n = load_scene(write("n.off", "NOFF\n3 1 0\n0 0 0 0 0 2\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n"), options);
  EXPECT_EQ(n.mesh.normals, (std::vector<glm::vec3>(3, {0, 0, 1})));
  EXPECT_EQ(n.mesh.uvs.size(), 3u);
  EXPECT_TRUE(report.warnings.empty());
  const Scene s = load_scene(write("s.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n5 5 5\n2 0 1\n3 0 1 2\n"), options);
  EXPECT_EQ(s.mesh.triangle_count(), 1u);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("1 faces with fewer than 3 corners left out"), std::string::npos);
  auto load_problem = [&](const std::string& path) -> std::string {
    try {
      (void)load_scene(path);
    } catch (const InputError& e) {
      return e.problem();
    }
    return "(loaded)";
  };
  EXPECT_EQ(load_problem(write("none.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")), "contains no faces");
  EXPECT_EQ(load_problem(write("short.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n")),
            "contains no triangles (every face has fewer than 3 distinct corners)");
  std::filesystem::remove_all(dir);
}

// assimp-testmodels' OFF files: the same positions (in file order) and the same triangles (in
// the same order and winding) as OpenMesh's OFF reader gives; its invalid.off is rejected.
TEST(OffReader, AssimpModelsMatchOpenMesh) {
  const std::string root = "/usr/share/assimp/models/OFF/";
  SPECULUM_REQUIRE(std::filesystem::exists(root + "Wuson.off"), "the Debian package assimp-testmodels");
  for (const char* name : {"Cube.off", "Wuson.off"}) {
    SCOPED_TRACE(name);
    const Scene s = load_scene(root + name);
    OpenMesh::TriMesh_ArrayKernelT<> om;
    ASSERT_TRUE(OpenMesh::IO::read_mesh(om, root + name));
    ASSERT_EQ(s.mesh.positions.size(), om.n_vertices());
    for (auto vh : om.vertices()) {
      const auto& p = om.point(vh);
      EXPECT_EQ(s.mesh.positions[static_cast<std::size_t>(vh.idx())], glm::vec3(p[0], p[1], p[2])) << vh.idx();
    }
    ASSERT_EQ(s.mesh.triangle_count(), om.n_faces());
    std::vector<std::uint32_t> expect;
    for (auto fh : om.faces())
      for (auto vh : om.fv_range(fh)) expect.push_back(static_cast<std::uint32_t>(vh.idx()));
    EXPECT_EQ(s.mesh.indices, expect);
  }
  EXPECT_THROW((void)load_scene(root + "invalid.off"), InputError);
}

}  // namespace
}  // namespace speculum
