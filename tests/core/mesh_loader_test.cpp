// OBJ (tinyobjloader) and PLY/OFF/STL (OpenMesh): the same tetrahedron in four formats loads to the same
// geometry, with area-weighted normals matching a hand-computed oracle.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/mesh_normals.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"

namespace speculum {
namespace {

TEST(MeshLoader, TetrahedronInAllFormats) {
  for (const char* name : {"tetra.obj", "tetra.off", "tetra.ply", "tetra.stl"}) {
    SCOPED_TRACE(name);
    const Scene s = load_scene(std::string(SPECULUM_TEST_DATA "/good/") + name);
    EXPECT_EQ(s.mesh.triangle_count(), 4u);
    EXPECT_EQ(s.objects.size(), 1u);
    EXPECT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.cameras.size(), 1u);
    // Area of the unit right tetrahedron: three legs of 1/2 and a face of sqrt(3)/2.
    EXPECT_NEAR(testing::total_area(s), 1.5 + std::sqrt(3.0) / 2.0, 1e-5);
    const Bounds b = s.bounds();
    EXPECT_EQ(b.lo, glm::vec3(0.0f));
    EXPECT_EQ(b.hi, glm::vec3(1.0f));
    // Every face winds outward (away from the centroid).
    const glm::vec3 c(0.25f);
    for (std::size_t t = 0; t < 4; ++t) {
      const glm::vec3 a = s.mesh.positions[s.mesh.indices[3 * t]];
      EXPECT_GT(glm::dot(testing::triangle_cross(s, t), a - c), 0.0f) << t;
    }
    // The vertex at the origin touches the three leg faces (normals -x,-y,-z, area 1/2
    // each): its area-weighted normal is -(1,1,1)/sqrt(3). STL duplicates vertices, so
    // only formats with shared vertices are checked.
    if (std::string(name) != "tetra.stl") {
      const auto it = std::find(s.mesh.positions.begin(), s.mesh.positions.end(), glm::vec3(0.0f));
      ASSERT_NE(it, s.mesh.positions.end());
      const glm::vec3 n = s.mesh.normals[static_cast<std::size_t>(it - s.mesh.positions.begin())];
      EXPECT_NEAR(n.x, -1.0f / std::sqrt(3.0f), 1e-5f);
      EXPECT_NEAR(n.y, -1.0f / std::sqrt(3.0f), 1e-5f);
      EXPECT_NEAR(n.z, -1.0f / std::sqrt(3.0f), 1e-5f);
    }
  }
}

// OpenMesh trusts the corner count of every face; the loader walks the data first. A binary
// PLY triangle loads; the same file whose face claims 4 billion (or 200) corners, or whose
// corner count is negative, is one InputError; an OFF face claiming more corners than the file
// holds values likewise.
TEST(MeshLoader, FaceCornerCountsMustFitInTheFile) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "speculum_corner_counts";
  fs::create_directories(dir);
  auto binary_ply = [&](const char* count_type, const std::string& count_bytes) {
    std::string head = std::string("ply\nformat binary_little_endian 1.0\nelement vertex 3\n") +
                       "property float x\nproperty float y\nproperty float z\nelement face 1\n" +
                       "property list " + count_type + " int vertex_indices\nend_header\n";
    const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::int32_t idx[3] = {0, 1, 2};
    std::string body(reinterpret_cast<const char*>(v), sizeof v);
    body += count_bytes;
    body.append(reinterpret_cast<const char*>(idx), sizeof idx);
    const fs::path p = dir / "tri.ply";
    std::ofstream(p, std::ios::binary) << head << body;
    return p.string();
  };
  auto problem = [](const std::string& path) -> std::string {
    try {
      (void)load_scene(path);
    } catch (const InputError& e) {
      return e.problem();
    }
    return "loaded";
  };
  EXPECT_EQ(load_scene(binary_ply("uchar", std::string(1, '\3'))).mesh.triangle_count(), 1u);
  EXPECT_EQ(problem(binary_ply("uint", std::string(4, '\xff'))),
            "PLY data truncated or malformed: fewer bytes than the header declares");
  EXPECT_EQ(problem(binary_ply("uchar", std::string(1, '\xc8'))),
            "PLY data truncated or malformed: fewer bytes than the header declares");
  EXPECT_EQ(problem(binary_ply("char", std::string(1, '\xff'))), "PLY list count is negative");
  const fs::path off = dir / "tri.off";
  std::ofstream(off) << "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n400000000 0 1\n";
  EXPECT_EQ(problem(off.string()), "OFF face 1 claims 400000000 corners but the file holds only 5 more bytes");
  std::ofstream(off) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(load_scene(off.string()).mesh.triangle_count(), 1u);
  fs::remove_all(dir);
}

TEST(MeshNormals, AreaWeightingOracle) {
  // Two triangles sharing vertex 0: one in z=0 facing +z (area 2) and one in x=0 facing
  // +x (area 0.5). The shared vertex normal is the area-weighted sum (0.5, 0, 2), normalised.
  const std::vector<glm::vec3> p = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 1, 0}, {0, 0, 1}};
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 3, 4};
  const auto n = area_weighted_normals(p, idx);
  const glm::vec3 expect = glm::normalize(glm::vec3(0.5f, 0.0f, 2.0f));
  EXPECT_NEAR(glm::length(n[0] - expect), 0.0f, 1e-6f);
  EXPECT_EQ(n[1], glm::vec3(0, 0, 1));
  EXPECT_EQ(n[4], glm::vec3(1, 0, 0));
}

TEST(MeshNormals, TangentsAreUnitOrthogonalAndFollowU) {
  // A tilted quad whose u runs along e1 and v along e2.
  const glm::vec3 e1 = glm::normalize(glm::vec3(1, 1, 0)), e2(0, 0, -1);
  const std::vector<glm::vec3> p = {glm::vec3(0), e1, e1 + e2, e2};
  const std::vector<glm::vec2> uv = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3};
  const auto n = area_weighted_normals(p, idx);
  const auto t = uv_tangents(p, n, uv, idx);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(glm::length(glm::vec3(t[i])), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::vec3(t[i]), n[i]), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::vec3(t[i]), e1), 1.0f, 1e-6f);
    // Handedness (glTF: the map's +Y is up the image, against v): cross(n, t) * w points
    // along -dP/dv = -e2.
    EXPECT_GT(glm::dot(glm::cross(n[i], glm::vec3(t[i])) * t[i].w, -e2), 0.99f);
  }
}

}  // namespace
}  // namespace speculum
