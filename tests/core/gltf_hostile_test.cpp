// Scenes written by an attacker: JSON nested far deeper than any glTF, byte ranges the
// glTF 2.0 schema forbids (negative or fractional offsets and counts), and URIs that reach
// outside the scene's folder (absolute, `..`, a symlink). Each is one InputError naming the
// problem — never a crash, and never a read of the outside file unless allowed.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/scene_loader.h"
#include "tests/core/scene_test_util.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

fs::path hostile_scratch(const std::string& name) { return testing::temp_dir("hostile_" + name); }

// One triangle (positions in a data URI), optionally a base-colour image at `image_uri`,
// and `buffer_view` as the position bufferView's JSON.
std::string triangle_gltf(const std::string& image_uri = "",
                          const std::string& buffer_view = R"({"buffer":0,"byteOffset":0,"byteLength":36})",
                          const std::string& count = "3") {
  // (0,0,0) (1,0,0) (0,1,0) as little-endian floats, base64.
  const std::string data = "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
  std::string material = R"({"pbrMetallicRoughness":{}})";
  std::string images;
  if (!image_uri.empty()) {
    material = R"({"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}})";
    images = R"("images":[{"uri":")" + image_uri + R"("}],"textures":[{"source":0}],)";
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0}]}],"materials":[)" +
         material + "]," + images +
         R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)" + data + R"("}],)"
         R"("bufferViews":[)" + buffer_view + "]," +
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + count +
         R"(,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})";
}

std::string load_error(const fs::path& file, bool allow = false) {
  SceneOptions o;
  o.allow_external_files = allow;
  try {
    load_scene(file.string(), o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GltfHostile, ValidTriangleLoads) {
  const fs::path dir = hostile_scratch("valid");
  testing::write_text(dir / "ok.gltf", triangle_gltf());
  EXPECT_EQ(load_error(dir / "ok.gltf"), "");
}

TEST(GltfHostile, DeepNestingIsRejectedBeforeParsing) {
  const fs::path dir = hostile_scratch("deep");
  const std::string deep = std::string(300000, '[') + std::string(300000, ']');
  testing::write_text(dir / "deep.gltf", R"({"asset":{"version":"2.0"},"extras":)" + deep + "}");
  EXPECT_NE(load_error(dir / "deep.gltf").find("JSON nests deeper than 256 levels"), std::string::npos);
  // Brackets inside strings do not count.
  std::string quoted = triangle_gltf();
  quoted.insert(quoted.size() - 1, R"(,"extras":{"s":")" + std::string(1000, '[') + R"("})");
  testing::write_text(dir / "quoted.gltf", quoted);
  EXPECT_EQ(load_error(dir / "quoted.gltf"), "");
}

TEST(GltfHostile, SchemaMinimumsOfByteRangesAreChecked) {
  const fs::path dir = hostile_scratch("minimums");
  const struct {
    const char* name;
    std::string json;
    const char* message;
  } cases[] = {
      {"negative_offset", triangle_gltf("", R"({"buffer":0,"byteOffset":-4,"byteLength":36})"),
       "bufferViews[0].byteOffset is -4"},
      {"fractional_length", triangle_gltf("", R"({"buffer":0,"byteLength":35.5})"),
       "bufferViews[0].byteLength is 35.5"},
      {"missing_length", triangle_gltf("", R"({"buffer":0})"), "bufferViews[0].byteLength is missing"},
      {"stride", triangle_gltf("", R"({"buffer":0,"byteLength":36,"byteStride":2})"),
       "bufferViews[0].byteStride is 2"},
      {"zero_count", triangle_gltf("", R"({"buffer":0,"byteLength":36})", "0"), "accessors[0].count is 0"},
      {"huge_count", triangle_gltf("", R"({"buffer":0,"byteLength":36})", "1e300"), "accessors[0].count is"},
  };
  for (const auto& c : cases) {
    testing::write_text(dir / (std::string(c.name) + ".gltf"), c.json);
    const std::string e = load_error(dir / (std::string(c.name) + ".gltf"));
    EXPECT_NE(e.find(c.message), std::string::npos) << c.name << ": " << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(GltfHostile, UrisOutsideTheSceneFolderAreRefusedUnlessAllowed) {
  const fs::path root = hostile_scratch("outside");
  const fs::path scene_dir = root / "scene";
  fs::create_directories(scene_dir);
  testing::write_text(root / "secret.png", "not an image");  // outside the scene's folder
  testing::write_text(scene_dir / "inside.png", "not an image either");
  fs::create_symlink(root / "secret.png", scene_dir / "link.png");
  const struct {
    const char* name;
    std::string uri;
    bool refused;
  } cases[] = {
      {"absolute", (root / "secret.png").string(), true},
      {"dotdot", "../secret.png", true},
      {"symlink", "link.png", true},
      {"inside", "inside.png", false},
  };
  for (const auto& c : cases) {
    const fs::path file = scene_dir / (std::string(c.name) + ".gltf");
    testing::write_text(file, triangle_gltf(c.uri));
    const std::string e = load_error(file);
    if (c.refused) {
      EXPECT_NE(e.find("outside the scene's folder (--allow-external-files allows it)"), std::string::npos)
          << c.name << ": " << e;
      // Allowed: the file is read (and, not being an image, left out with a warning).
      EXPECT_EQ(load_error(file, true), "") << c.name;
    } else {
      EXPECT_EQ(e, "") << c.name;
    }
  }
}

}  // namespace
}  // namespace speculum
