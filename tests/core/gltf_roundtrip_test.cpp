// Export every built-in scene as .glb and .gltf and load it back: counts, geometry,
// materials, cameras and lights survive with identical counts.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/gltf_writer.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"

namespace speculum {
namespace {

TEST(GltfRoundTrip, EveryBuiltinSceneSurvivesExport) {
  const auto dir = testing::temp_dir("roundtrip");
  for (const BuiltinScene& def : builtin_scenes()) {
    SceneOptions o;
    o.size = 2000;
    const Scene src = load_scene(def.name, o);
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(std::string(def.name) + ext);
      const std::string path = (dir / (std::string(def.name) + ext)).string();
      write_gltf(src, path);
      const Scene back = load_scene(path);
      EXPECT_EQ(back.mesh.triangle_count(), src.mesh.triangle_count());
      EXPECT_EQ(back.mesh.vertex_count(), src.mesh.vertex_count());
      EXPECT_EQ(back.materials.size(), src.materials.size());
      EXPECT_EQ(back.textures.size(), src.textures.size());
      EXPECT_EQ(back.objects.size(), src.objects.size());
      EXPECT_EQ(back.cameras.size(), src.cameras.size());
      EXPECT_EQ(back.lights.size(), src.lights.size());
      // Geometry is stored as float32: bit-exact.
      EXPECT_EQ(back.mesh.positions, src.mesh.positions);
      EXPECT_EQ(back.mesh.indices, src.mesh.indices);
      EXPECT_EQ(back.mesh.triangle_material, src.mesh.triangle_material);
      for (std::size_t i = 0; i < src.materials.size() && i < back.materials.size(); ++i) {
        EXPECT_EQ(back.materials[i].kind(), src.materials[i].kind()) << src.materials[i].name;
        EXPECT_EQ(back.materials[i].name, src.materials[i].name);
        EXPECT_FLOAT_EQ(back.materials[i].ior, src.materials[i].ior);
        EXPECT_FLOAT_EQ(back.materials[i].transmission, src.materials[i].transmission);
        EXPECT_EQ(back.materials[i].base_color_texture.texture, src.materials[i].base_color_texture.texture);
      }
      // Textures pass through 8-bit sRGB PNG: equal within one 8-bit step.
      for (std::size_t t = 0; t < src.textures.size() && t < back.textures.size(); ++t) {
        ASSERT_EQ(back.textures[t].pixels.size(), src.textures[t].pixels.size());
        float err = 0.0f;
        for (std::size_t i = 0; i < src.textures[t].pixels.size(); ++i)
          for (int c = 0; c < 4; ++c)
            err = std::max(err, std::fabs(back.textures[t].pixels[i][c] - src.textures[t].pixels[i][c]));
        EXPECT_LT(err, 0.01f);
      }
      for (std::size_t c = 0; c < src.cameras.size() && c < back.cameras.size(); ++c) {
        EXPECT_LT(glm::length(back.cameras[c].eye - src.cameras[c].eye), 1e-5f);
        const glm::vec3 f0 = glm::normalize(src.cameras[c].target - src.cameras[c].eye);
        const glm::vec3 f1 = glm::normalize(back.cameras[c].target - back.cameras[c].eye);
        EXPECT_GT(glm::dot(f0, f1), 0.99999f);
        EXPECT_NEAR(back.cameras[c].vfov_degrees, src.cameras[c].vfov_degrees, 1e-3f);
      }
      for (std::size_t l = 0; l < src.lights.size() && l < back.lights.size(); ++l) {
        EXPECT_EQ(back.lights[l].type, src.lights[l].type);
        EXPECT_LT(glm::length(back.lights[l].position - src.lights[l].position), 1e-5f);
        EXPECT_FLOAT_EQ(back.lights[l].intensity, src.lights[l].intensity);
        if (src.lights[l].type != LightType::Point) {
          EXPECT_GT(glm::dot(back.lights[l].direction, src.lights[l].direction), 0.99999f);
        }
      }
    }
  }
  std::filesystem::remove_all(dir);
}

TEST(GltfRoundTrip, BadOutputPathIsInputErrorAndLeavesNoFile) {
  const Scene s = load_scene("bowl:size=1000");
  EXPECT_THROW(write_gltf(s, "/nonexistent/dir/out.glb"), InputError);
  const auto dir = testing::temp_dir("roundtrip_bad");
  EXPECT_THROW(write_gltf(s, (dir / "out.png").string()), InputError);
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum
