// Built-in scenes: valid at both ends of the size range, triangle counts track the size,
// deterministic, outward-facing closed shapes, and the parameters are honoured.
#include <cmath>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "core/mesh_normals.h"
#include "core/procedural_geometry.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"

namespace speculum {
namespace {

TEST(ProceduralScenes, EveryNamedSceneIsListedAndDefaultExists) {
  const char* names[] = {"sphere-in-room", "glossy-plane", "mirror-corridor", "living-room",  "glass-sphere", "bowl",
                         "bumpy-sphere",   "ellipsoid",    "bathroom",        "caustic-ring", "water-slab"};
  EXPECT_EQ(builtin_scenes().size(), std::size(names));
  for (const char* name : names) EXPECT_NE(find_builtin_scene(name), nullptr) << name;
  EXPECT_NE(find_builtin_scene(default_scene_name()), nullptr);
}

TEST(ProceduralScenes, TriangleCountTracksSizeAndSceneIsComplete) {
  for (const BuiltinScene& def : builtin_scenes()) {
    for (std::uint64_t size : {std::uint64_t{1000}, std::uint64_t{20000}, std::uint64_t{200000}}) {
      SCOPED_TRACE(std::string(def.name) + " size " + std::to_string(size));
      SceneOptions o;
      o.size = size;
      const Scene s = load_scene(def.name, o);
      const double ratio = double(s.mesh.triangle_count()) / double(size);
      // Grids round to whole cells: within 35% at 1K, much closer at larger sizes.
      EXPECT_GT(ratio, size == 1000 ? 0.65 : 0.85);
      EXPECT_LT(ratio, size == 1000 ? 1.6 : 1.15);
      EXPECT_FALSE(s.lights.empty());
      EXPECT_FALSE(s.cameras.empty());
      EXPECT_GE(s.materials.size(), 2u);
      for (const auto& c : s.cameras) EXPECT_NO_THROW(validate_camera(c, s.name));
      // Every material is used (export/re-import keeps the count) and every texture too.
      std::vector<int> used(s.materials.size(), 0);
      for (auto m : s.mesh.triangle_material) used[m] = 1;
      for (std::size_t i = 0; i < used.size(); ++i) EXPECT_TRUE(used[i]) << s.materials[i].name;
      // Cameras look at something: the scene's centre is in front of the main camera.
      const Bounds b = s.bounds();
      const Camera& cam = s.cameras[0];
      EXPECT_GT(glm::dot(glm::normalize(cam.target - cam.eye), b.center() - cam.eye), 0.0f);
    }
  }
}

TEST(ProceduralScenes, TechniqueMaterialsArePresent) {
  auto kinds = [](const char* name) {
    std::array<int, 4> k{};
    for (const auto& m : load_scene(name).materials) ++k[static_cast<int>(m.kind())];
    return k;
  };
  EXPECT_GE(kinds("sphere-in-room")[int(MaterialKind::Mirror)], 1);
  EXPECT_GE(kinds("glossy-plane")[int(MaterialKind::Glossy)], 1);
  EXPECT_GE(kinds("mirror-corridor")[int(MaterialKind::Mirror)], 1);
  const auto room = kinds("living-room");
  EXPECT_GE(room[int(MaterialKind::Mirror)], 2);
  EXPECT_GE(room[int(MaterialKind::Glossy)], 2);
  EXPECT_GE(room[int(MaterialKind::Refractor)], 1);
  const Scene glass = load_scene("glass-sphere");
  bool found = false;
  for (const auto& m : glass.materials)
    if (m.kind() == MaterialKind::Refractor) {
      found = true;
      EXPECT_EQ(m.transmission, 1.0f);
      EXPECT_EQ(m.ior, 1.5f);
    }
  EXPECT_TRUE(found);
  EXPECT_EQ(glass.lights[0].type, LightType::Point);
}

TEST(ProceduralScenes, DeterministicBitForBit) {
  const Scene a = load_scene("living-room:size=5000");
  const Scene b = load_scene("living-room:size=5000");
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.normals, b.mesh.normals);
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);
  const Scene c = load_scene("glossy-plane:size=2000");
  const Scene d = load_scene("glossy-plane:size=2000");
  EXPECT_EQ(c.environment.equirect.pixels, d.environment.equirect.pixels);
}

TEST(ProceduralScenes, SizeInNameWinsAndSuffixesParse) {
  SceneOptions o;
  o.size = 1000;
  const Scene a = load_scene("glass-sphere:size=50k", o);
  EXPECT_GT(a.mesh.triangle_count(), 45000u);
  EXPECT_LT(a.mesh.triangle_count(), 55000u);
}

TEST(ProceduralScenes, BumpySphereFollowsTheDisplacementFormula) {
  const Scene flat = load_scene("bumpy-sphere:size=8000,amplitude=0");
  const Scene bumpy = load_scene("bumpy-sphere:size=8000,n=5,amplitude=0.1");
  ASSERT_EQ(flat.mesh.vertex_count(), bumpy.mesh.vertex_count());
  const Object* sphere = nullptr;
  for (const auto& o : bumpy.objects)
    if (o.name == "bumpy sphere") sphere = &o;
  ASSERT_NE(sphere, nullptr);
  // Oracle: |p - c| = R (1 + a cos(n d.x) cos(n d.y)) with d the undisplaced direction.
  const glm::vec3 center(0, 1.2f, 0);
  double max_err = 0.0;
  for (std::size_t t = sphere->first_triangle; t < sphere->first_triangle + sphere->triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = bumpy.mesh.indices[3 * t + k];
      const glm::vec3 d = glm::normalize(flat.mesh.positions[v] - center);
      const double expect = 1.0 * (1.0 + 0.1 * std::cos(5.0 * d.x) * std::cos(5.0 * d.y));
      max_err = std::max(max_err, std::fabs(glm::length(bumpy.mesh.positions[v] - center) - expect));
    }
  EXPECT_LT(max_err, 1e-5);
}

TEST(ProceduralGeometry, ClosedShapesFaceOutward) {
  using namespace procedural;
  auto outward_fraction = [](const MeshData& m, glm::vec3 c) {
    std::size_t out = 0, total = 0;
    for (std::size_t i = 0; i < m.indices.size(); i += 3) {
      const glm::vec3 a = m.positions[m.indices[i]], b = m.positions[m.indices[i + 1]],
                      d = m.positions[m.indices[i + 2]];
      const glm::vec3 n = glm::cross(b - a, d - a);
      if (glm::length(n) < 1e-12f) continue;
      ++total;
      out += glm::dot(n, (a + b + d) / 3.0f - c) > 0.0f;
    }
    return double(out) / double(total);
  };
  EXPECT_EQ(outward_fraction(sphere({1, 2, 3}, 2.0f, 12), {1, 2, 3}), 1.0);
  EXPECT_EQ(outward_fraction(box({0, 0, 0}, {1, 2, 3}, 3, false), {0.5f, 1, 1.5f}), 1.0);
  EXPECT_EQ(outward_fraction(box({0, 0, 0}, {1, 2, 3}, 3, true), {0.5f, 1, 1.5f}), 0.0);
  // A bowl's reflecting side faces its centre.
  EXPECT_EQ(outward_fraction(bowl({0, 0, 0}, 1.0f, 60.0f, 10), {0, 0, 0}), 0.0);
  // Sphere area converges to 4 pi r^2 from below.
  Scene s;
  const MeshData m = sphere({0, 0, 0}, 1.0f, 64);
  double area = 0.0;
  for (std::size_t i = 0; i < m.indices.size(); i += 3)
    area += 0.5 * glm::length(glm::cross(m.positions[m.indices[i + 1]] - m.positions[m.indices[i]],
                                         m.positions[m.indices[i + 2]] - m.positions[m.indices[i]]));
  EXPECT_NEAR(area, 4.0 * 3.14159265358979, 0.01 * 4.0 * 3.14159265358979);
  EXPECT_LT(area, 4.0 * 3.14159265358979);
}

}  // namespace
}  // namespace speculum
