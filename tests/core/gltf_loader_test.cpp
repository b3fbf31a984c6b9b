// glTF loader: container variants agree, textures decode to linear exactly as OpenImageIO
// does, strips/fans convert, node transforms flatten to world space, extensions map.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"
#include <glm/gtc/constants.hpp>

#include "core/error.h"
#include "core/gltf_loader.h"
#include "core/image.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"

namespace speculum {
namespace {

using testing::temp_dir;
using testing::write_text;

const std::string kAssimp = "/usr/share/assimp/models/glTF2/";

void expect_same_geometry(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.mesh.positions.size(), b.mesh.positions.size());
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);
  for (std::size_t i = 0; i < a.mesh.positions.size(); ++i) {
    EXPECT_EQ(a.mesh.positions[i], b.mesh.positions[i]);
    EXPECT_EQ(a.mesh.normals[i], b.mesh.normals[i]);
    EXPECT_EQ(a.mesh.uvs[i], b.mesh.uvs[i]);
  }
}

TEST(GltfLoader, TriangleGltfAndGlbAgree) {
  const Scene a = load_scene(SPECULUM_TEST_DATA "/good/triangle.gltf");
  const Scene b = load_scene(SPECULUM_TEST_DATA "/good/triangle.glb");
  expect_same_geometry(a, b);
  ASSERT_EQ(a.mesh.triangle_count(), 1u);
  EXPECT_EQ(a.mesh.positions[1], glm::vec3(1, 0, 0));
  // No normals in the file: computed, and the triangle lies in z = 0 wound CCW from +Z.
  for (const auto& n : a.mesh.normals) EXPECT_EQ(n, glm::vec3(0, 0, 1));
  ASSERT_EQ(a.materials.size(), 1u);
  EXPECT_EQ(a.materials[0].kind(), MaterialKind::Mirror);
  ASSERT_EQ(a.cameras.size(), 1u);  // the framing default
  EXPECT_EQ(a.objects.size(), 1u);
}

TEST(GltfLoader, BoxTexturedVariantsAgreeAndTextureIsLinear) {
  SPECULUM_REQUIRE(std::filesystem::exists(kAssimp), "the Debian package assimp-testmodels");
  const Scene sep = load_scene(kAssimp + "BoxTextured-glTF/BoxTextured.gltf");
  const Scene emb = load_scene(kAssimp + "BoxTextured-glTF-Embedded/BoxTextured.gltf");
  const Scene glb = load_scene(kAssimp + "BoxTextured-glTF-Binary/BoxTextured.glb");
  expect_same_geometry(sep, emb);
  expect_same_geometry(sep, glb);
  EXPECT_EQ(sep.mesh.triangle_count(), 12u);
  ASSERT_EQ(sep.textures.size(), 1u);
  ASSERT_EQ(glb.textures.size(), 1u);
  EXPECT_EQ(sep.textures[0].pixels, glb.textures[0].pixels);
  // Oracle: OpenImageIO's sRGB decode of the same PNG.
  const ImageRGBA ref = read_image(kAssimp + "BoxTextured-glTF/CesiumLogoFlat.png", true);
  ASSERT_EQ(ref.width, sep.textures[0].width);
  ASSERT_EQ(ref.height, sep.textures[0].height);
  double max_err = 0.0;
  for (std::size_t i = 0; i < ref.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c)
      max_err = std::max(max_err, double(std::fabs(ref.pixels[i][c] - sep.textures[0].pixels[i][c])));
  EXPECT_LT(max_err, 1e-4);
  EXPECT_TRUE(sep.materials[0].base_color_texture.valid());
}

TEST(GltfLoader, StripsAndFansBecomeTheSameQuad) {
  SPECULUM_REQUIRE(std::filesystem::exists(kAssimp), "the Debian package assimp-testmodels");
  const std::string dir = kAssimp + "glTF-Asset-Generator/Mesh_PrimitiveMode/Mesh_PrimitiveMode_";
  const Scene ref = load_scene(dir + "06.gltf");  // plain triangles
  const double area = testing::total_area(ref);
  ASSERT_GT(area, 0.0);
  for (const char* id : {"04", "05", "11", "12", "13", "14", "15"}) {
    SCOPED_TRACE(id);
    const Scene s = load_scene(dir + id + std::string(".gltf"));
    EXPECT_EQ(s.mesh.triangle_count(), 2u);
    EXPECT_NEAR(testing::total_area(s), area, 1e-6 * area);
    // Every triangle winds the same way as the reference's first triangle.
    const glm::vec3 facing = glm::normalize(testing::triangle_cross(ref, 0));
    for (std::size_t t = 0; t < s.mesh.triangle_count(); ++t)
      EXPECT_GT(glm::dot(glm::normalize(testing::triangle_cross(s, t)), facing), 0.99f);
  }
  // Points and lines are skipped with a count; a file with nothing else is rejected.
  LoadReport report;
  SceneOptions opts;
  opts.report = &report;
  EXPECT_THROW((void)load_scene(dir + "00.gltf", opts), InputError);
  EXPECT_EQ(report.skipped_primitives, 1u);
}

// A unit quad in z = 0 (u along +x, v downward in y) in a .bin beside a hand-written .gltf.
std::string write_quad(const std::filesystem::path& dir) {
  const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
  const std::uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
  std::string bin(92, '\0');
  std::memcpy(bin.data(), pos, 48);
  std::memcpy(bin.data() + 48, uv, 32);
  std::memcpy(bin.data() + 80, idx, 12);
  write_text(dir / "quad.bin", bin);
  return R"("buffers": [{"uri": "quad.bin", "byteLength": 92}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                  {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
                {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
  "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}])";
}

TEST(GltfLoader, NodeHierarchyIsFlattenedToWorldSpace) {
  const auto dir = temp_dir("gltf_nodes");
  const std::string common = write_quad(dir);
  // Parent: translate (1,2,3). Child: rotate 90 deg about +Z, scale 2. Second instance
  // mirrored by scale (-1,1,1) to check that winding follows the normals.
  const float s = std::sqrt(0.5f);
  write_text(dir / "nodes.gltf", R"({"asset": {"version": "2.0"}, "scene": 0,
  "scenes": [{"nodes": [0, 2]}],
  "nodes": [{"translation": [1, 2, 3], "children": [1]},
            {"mesh": 0, "rotation": [0, 0, )" + std::to_string(s) + ", " + std::to_string(s) + R"(], "scale": [2, 2, 2]},
            {"mesh": 0, "scale": [-1, 1, 1]}],
  "materials": [{"name": "m"}], )" + common + "}");
  const Scene scene = load_scene((dir / "nodes.gltf").string());
  ASSERT_EQ(scene.mesh.triangle_count(), 4u);
  ASSERT_EQ(scene.objects.size(), 2u);
  // Vertex (1,0,0): scale → (2,0,0), rotate → (0,2,0), translate → (1,4,3).
  const glm::vec3 p = scene.mesh.positions[1];
  EXPECT_NEAR(p.x, 1.0f, 1e-5f);
  EXPECT_NEAR(p.y, 4.0f, 1e-5f);
  EXPECT_NEAR(p.z, 3.0f, 1e-5f);
  EXPECT_NEAR(scene.mesh.positions[5].x, -1.0f, 1e-6f);  // mirrored instance
  for (std::size_t t = 0; t < scene.mesh.triangle_count(); ++t) {
    const glm::vec3 n = scene.mesh.normals[scene.mesh.indices[3 * t]];
    EXPECT_GT(glm::dot(glm::normalize(testing::triangle_cross(scene, t)), n), 0.99f) << t;
  }
  std::filesystem::remove_all(dir);
}

TEST(GltfLoader, MaterialsLightsCamerasAndExtensions) {
  const auto dir = temp_dir("gltf_ext");
  const std::string common = write_quad(dir);
  // 2x2 normal map so the material needs tangents.
  ImageRGBA nmap(2, 2, glm::vec4(0.5f, 0.5f, 1.0f, 1.0f));
  write_image((dir / "normal.png").string(), nmap);
  write_text(dir / "ext.gltf", R"({"asset": {"version": "2.0"}, "scene": 0,
  "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_lights_punctual",
                     "KHR_texture_transform", "KHR_materials_emissive_strength"],
  "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "point", "intensity": 5, "color": [1, 0.5, 0.25]},
      {"type": "spot", "intensity": 7, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.4}},
      {"type": "directional", "intensity": 2}]}},
  "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
  "nodes": [{"mesh": 0},
            {"translation": [0, 5, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [1, 1, 1], "rotation": [-0.7071068, 0, 0, 0.7071068], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"camera": 0, "translation": [0, 0, 4]}],
  "cameras": [{"type": "perspective", "name": "cam", "perspective": {"yfov": 0.5, "znear": 0.1, "zfar": 50}}],
  "images": [{"uri": "normal.png"}],
  "textures": [{"source": 0}],
  "materials": [{"name": "glass", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.1},
                 "emissiveFactor": [1, 0.5, 0],
                 "normalTexture": {"index": 0, "scale": 0.5,
                    "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "rotation": 1.5707963, "scale": [2, 2]}}},
                 "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                "KHR_materials_ior": {"ior": 1.33},
                                "KHR_materials_emissive_strength": {"emissiveStrength": 4}}}], )" + common + "}");
  const Scene s = load_scene((dir / "ext.gltf").string());
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.kind(), MaterialKind::Refractor);
  EXPECT_FLOAT_EQ(m.transmission, 1.0f);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  EXPECT_EQ(m.emissive, glm::vec3(4.0f, 2.0f, 0.0f));
  EXPECT_FLOAT_EQ(m.normal_scale, 0.5f);
  ASSERT_TRUE(m.normal_texture.valid());
  // T R S applied to uv (1,0): S → (2,0), R(90°) = [[0, 1], [-1, 0]] → (0,-2), T → (0.5,-2).
  const glm::vec3 uv = m.normal_texture.uv_transform * glm::vec3(1, 0, 1);
  EXPECT_NEAR(uv.x, 0.5f, 1e-5f);
  EXPECT_NEAR(uv.y, -2.0f, 1e-5f);
  // Normal map → tangents computed: unit, orthogonal to n, along dP/du = +x; the quad's v
  // runs down the image while y goes up, so the image's up is +y = cross(n, t): the map is
  // not mirrored and the handedness is +1.
  ASSERT_EQ(s.mesh.tangents.size(), s.mesh.positions.size());
  for (const auto& t : s.mesh.tangents) {
    EXPECT_NEAR(t.x, 1.0f, 1e-5f);
    EXPECT_NEAR(std::fabs(t.y) + std::fabs(t.z), 0.0f, 1e-5f);
    EXPECT_EQ(t.w, 1.0f);
  }
  ASSERT_EQ(s.lights.size(), 3u);
  EXPECT_EQ(s.lights[0].type, LightType::Point);
  EXPECT_EQ(s.lights[0].position, glm::vec3(0, 5, 0));
  EXPECT_EQ(s.lights[0].color, glm::vec3(1, 0.5f, 0.25f));
  EXPECT_EQ(s.lights[1].type, LightType::Spot);
  EXPECT_FLOAT_EQ(s.lights[1].outer_cone, 0.4f);
  // Rotation -90° about X turns -Z into -Y: the spot points down.
  EXPECT_NEAR(s.lights[1].direction.y, -1.0f, 1e-5f);
  EXPECT_EQ(s.lights[2].type, LightType::Directional);
  EXPECT_NEAR(s.lights[2].direction.z, -1.0f, 1e-6f);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.cameras[0].name, "cam");
  EXPECT_EQ(s.cameras[0].eye, glm::vec3(0, 0, 4));
  EXPECT_NEAR(s.cameras[0].target.z, 3.0f, 1e-6f);
  EXPECT_NEAR(s.cameras[0].vfov_degrees, 0.5f * 180.0f / glm::pi<float>(), 1e-4f);
  EXPECT_FLOAT_EQ(s.cameras[0].zfar, 50.0f);
  std::filesystem::remove_all(dir);
}

TEST(GltfLoader, AssimpCamerasFileGivesPerspectiveCamera) {
  SPECULUM_REQUIRE(std::filesystem::exists(kAssimp), "the Debian package assimp-testmodels");
  const Scene s = load_scene(kAssimp + "cameras/Cameras.gltf");
  ASSERT_FALSE(s.cameras.empty());
  for (const auto& c : s.cameras) {
    EXPECT_GT(c.vfov_degrees, 0.0f);
    EXPECT_LT(c.vfov_degrees, 180.0f);
  }
}

// uv' = T·R·S·uv with R = [[cos, sin], [-sin, cos]] (KHR_texture_transform; uvs turn
// counter-clockwise, the image clockwise as v points down).
glm::vec2 apply(const TextureRef& ref, glm::vec2 uv) {
  return glm::vec2(ref.uv_transform * glm::vec3(uv, 1.0f));
}

TEST(KhrTextureTransform, SpecExampleSelectsTheLowerLeftQuadrant) {
  // The extension's example: offset [0, 1], rotation π/2, scale 0.5 "utilizes only the
  // lower left quadrant of the source image, rotated clockwise 90°": the unit square maps
  // to u in [0, 0.5], v in [0.5, 1] (v down), (0,0) to the image's bottom-left corner.
  const auto dir = temp_dir("khr_tt_example");
  const std::string common = write_quad(dir);
  write_image((dir / "base.png").string(), ImageRGBA(2, 2, glm::vec4(1.0f)));
  write_text(dir / "t.gltf", R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "extensionsUsed": ["KHR_texture_transform"], "images": [{"uri": "base.png"}], "textures": [{"source": 0}],
  "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
      "extensions": {"KHR_texture_transform": {"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}}}}], )" +
                                 common + "}");
  const Scene s = load_scene((dir / "t.gltf").string());
  const TextureRef& ref = s.materials[0].base_color_texture;
  ASSERT_TRUE(ref.valid());
  const glm::vec2 corners[4][2] = {{{0, 0}, {0, 1}}, {{1, 0}, {0, 0.5f}}, {{1, 1}, {0.5f, 0.5f}}, {{0, 1}, {0.5f, 1}}};
  for (const auto& [in, out] : corners) {
    SCOPED_TRACE(::testing::Message() << in.x << "," << in.y);
    EXPECT_NEAR(apply(ref, in).x, out.x, 1e-6f);
    EXPECT_NEAR(apply(ref, in).y, out.y, 1e-6f);
  }
  std::filesystem::remove_all(dir);
}

TEST(KhrTextureTransform, KhronosTextureTransformTestUvs) {
  // Khronos' TextureTransformTest: the arrow of "Rotation" and "All" must point at the
  // green marker, which needs the spec's rotation direction. Expected values by hand.
  const std::string file = kAssimp + "textureTransform/TextureTransformTest.gltf";
  SPECULUM_REQUIRE(std::filesystem::exists(file), "the Debian package assimp-testmodels");
  const Scene s = load_scene(file);
  auto material = [&](const std::string& name) -> const Material& {
    for (const Material& m : s.materials)
      if (m.name == name) return m;
    ADD_FAILURE() << "no material " << name;
    return s.materials[0];
  };
  auto expect_uv = [](const TextureRef& ref, glm::vec2 in, glm::vec2 out) {
    SCOPED_TRACE(::testing::Message() << "uv " << in.x << "," << in.y);
    ASSERT_TRUE(ref.valid());
    EXPECT_NEAR(apply(ref, in).x, out.x, 1e-5f);
    EXPECT_NEAR(apply(ref, in).y, out.y, 1e-5f);
  };
  // Offsets move the origin.
  expect_uv(material("Offset U").base_color_texture, {0, 0}, {0.5f, 0});
  expect_uv(material("Offset V").base_color_texture, {0.25f, 0.25f}, {0.25f, 0.75f});
  expect_uv(material("Offset UV").base_color_texture, {0.5f, 0.5f}, {1, 1});
  // Rotation 22.5°: (1,0) → (cos, -sin) = (0.9238795, -0.3826834); (0,1) → (sin, cos).
  const TextureRef& rotation = material("Rotation").base_color_texture;
  expect_uv(rotation, {1, 0}, {0.9238795f, -0.3826834f});
  expect_uv(rotation, {0, 1}, {0.3826834f, 0.9238795f});
  expect_uv(rotation, {0, 0}, {0, 0});
  // Scale 1.5.
  expect_uv(material("Scale").base_color_texture, {1, 1}, {1.5f, 1.5f});
  // All: S = 1.5, R = 0.3 rad (cos 0.9553365, sin 0.2955202), T = (-0.2, -0.1).
  // (1,0) → (1.5, 0) → (1.4330048, -0.4432803) → (1.2330048, -0.5432803);
  // (0,1) → (0, 1.5) → (0.4432803, 1.4330048) → (0.2432803, 1.3330048).
  const TextureRef& all = material("All").base_color_texture;
  expect_uv(all, {1, 0}, {1.2330048f, -0.5432803f});
  expect_uv(all, {0, 1}, {0.2432803f, 1.3330048f});
  expect_uv(all, {0, 0}, {-0.2f, -0.1f});
}

}  // namespace
}  // namespace speculum
