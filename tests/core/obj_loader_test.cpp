// OBJ + .mtl: material values, the texture decoded from sRGB, uvs flipped to glTF's
// convention, corners split by uv/normal; the assimp OBJ models that carry .mtl textures.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include "core/image.h"
#include "core/obj_loader.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

const Material* find_material(const Scene& s, const std::string& name) {
  for (const Material& m : s.materials)
    if (m.name == name) return &m;
  return nullptr;
}

TEST(ObjMtl, RoughnessFromNsInvertsThePhongExponent) {
  for (float n : {1.0f, 10.0f, 98.0f, 500.0f}) {
    Material m;
    m.roughness = roughness_from_phong_exponent(n);
    EXPECT_NEAR(m.phong_exponent(), n, n * 1e-4f) << n;
  }
  EXPECT_FLOAT_EQ(roughness_from_phong_exponent(0.0f), 1.0f);  // Ns 0: fully rough
  EXPECT_NEAR(roughness_from_phong_exponent(98.0f), std::pow(1.0f / 99.0f, 0.25f), 1e-6f);
}

TEST(ObjMtl, QuadMaterialsTextureAndUvs) {
  // tests/data/good/quad.obj + quad.mtl + checker.png (tests/data/make_corpus.py).
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  const Scene s = load_scene(SPECULUM_TEST_DATA "/good/quad.obj", o);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings.front();
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_EQ(s.objects[0].name, "quad");
  EXPECT_EQ(s.objects[0].triangle_count, 2u);
  EXPECT_EQ(s.objects[1].name, "sliver");
  EXPECT_EQ(s.objects[1].triangle_count, 1u);
  ASSERT_EQ(s.materials.size(), 2u);

  const Material* painted = find_material(s, "painted");
  ASSERT_NE(painted, nullptr);
  EXPECT_EQ(painted->base_color, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));  // Kd
  EXPECT_NEAR(painted->roughness, std::pow(1.0f / 99.0f, 0.25f), 1e-6f);  // Ns 98
  EXPECT_EQ(painted->metallic, 0.0f);
  EXPECT_EQ(painted->emissive, glm::vec3(0.5f, 0.0f, 2.0f));  // Ke
  EXPECT_EQ(painted->transmission, 0.0f);
  EXPECT_EQ(painted->kind(), MaterialKind::Diffuse);
  ASSERT_TRUE(painted->base_color_texture.valid());
  const ImageRGBA& tex = s.textures[static_cast<std::size_t>(painted->base_color_texture.texture)];
  ASSERT_EQ(tex.width, 2);
  ASSERT_EQ(tex.height, 2);
  // sRGB 8-bit → linear, rows top to bottom as stored.
  EXPECT_EQ(glm::vec3(tex.at(0, 0)), glm::vec3(1, 0, 0));
  EXPECT_EQ(glm::vec3(tex.at(1, 0)), glm::vec3(0, 1, 0));
  EXPECT_EQ(glm::vec3(tex.at(0, 1)), glm::vec3(0, 0, 1));
  EXPECT_NEAR(tex.at(1, 1).x, srgb_to_linear(128.0f / 255.0f), 1e-6f);
  EXPECT_NEAR(tex.at(1, 1).x, 0.2158605f, 1e-6f);

  const Material* glass = find_material(s, "glass");
  ASSERT_NE(glass, nullptr);
  EXPECT_FLOAT_EQ(glass->transmission, 0.75f);  // d 0.25
  EXPECT_FLOAT_EQ(glass->ior, 1.33f);           // Ni
  EXPECT_FLOAT_EQ(glass->roughness, 0.1f);      // Pr wins over the (absent) Ns
  EXPECT_FLOAT_EQ(glass->metallic, 0.5f);       // Pm
  EXPECT_EQ(glass->kind(), MaterialKind::Refractor);
  EXPECT_FALSE(glass->base_color_texture.valid());

  // The quad's four corners carry uv and normal; the sliver shares two positions without
  // them, so it gets its own three vertices: 7 in all.
  EXPECT_EQ(s.mesh.vertex_count(), 7u);
  for (std::size_t t = 0; t < 2; ++t) {
    EXPECT_EQ(s.mesh.triangle_material[t], static_cast<std::uint32_t>(painted - s.materials.data()));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = s.mesh.indices[3 * t + static_cast<std::size_t>(k)];
      const glm::vec3 p = s.mesh.positions[v];
      // vt (x, y) at position (x, y, 0), stored as (u, 1 - v): glTF's v runs down.
      EXPECT_EQ(s.mesh.uvs[v], glm::vec2(p.x, 1.0f - p.y));
      EXPECT_EQ(s.mesh.normals[v], glm::vec3(0, 0, 1));
    }
  }
  EXPECT_EQ(s.mesh.triangle_material[2], static_cast<std::uint32_t>(glass - s.materials.data()));
}

TEST(ObjMtl, AssimpSpiderCarriesItsTextures) {
  // spider.mtl names its maps with Windows separators (map_Kd .\SpiderTex.jpg).
  const std::string dir = "/usr/share/assimp/models/OBJ/";
  SPECULUM_REQUIRE(std::filesystem::exists(dir + "spider.obj"), "the Debian package assimp-testmodels");
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  o.strict = true;  // every map it uses must resolve and decode
  const Scene s = load_scene(dir + "spider.obj", o);
  const Material* skin = find_material(s, "Skin");
  ASSERT_NE(skin, nullptr);
  EXPECT_NEAR(skin->base_color.x, 0.827451f, 1e-6f);
  EXPECT_NEAR(skin->base_color.y, 0.792157f, 1e-6f);
  EXPECT_NEAR(skin->base_color.z, 0.772549f, 1e-6f);
  ASSERT_TRUE(skin->base_color_texture.valid());
  const ImageRGBA expect = read_image(dir + "wal67ar_small.jpg", true);
  const ImageRGBA& got = s.textures[static_cast<std::size_t>(skin->base_color_texture.texture)];
  ASSERT_EQ(got.width, expect.width);
  ASSERT_EQ(got.height, expect.height);
  EXPECT_EQ(got.pixels, expect.pixels);
  std::size_t textured = 0;
  for (const Material& m : s.materials) textured += m.base_color_texture.valid();
  EXPECT_EQ(textured, s.materials.size());  // every material the spider uses has a map_Kd
  EXPECT_GE(textured, 4u);
}

}  // namespace
}  // namespace speculum
