// The warn corpus (tests/data/warn, made by tests/data/make_corpus.py): each file lacks one
// part (a texture, a .mtl). By default it loads with the part left out and one warning
// naming it; with strict it is an InputError naming the file, on one line.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

const std::string kWarn = SPECULUM_TEST_DATA "/warn/";

struct Loaded {
  Scene scene;
  std::vector<std::string> warnings;
};

Loaded load_with_report(const std::string& file) {
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  Loaded l{load_scene(file, o), {}};
  l.warnings = report.warnings;
  return l;
}

TEST(LoadWarnings, EveryWarnFileLoadsWithOneWarningAndFailsWhenStrict) {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(kWarn)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".gltf" || ext == ".glb" || ext == ".obj") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 5u);
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    const Loaded l = load_with_report(file);
    EXPECT_EQ(l.warnings.size(), 1u);
    EXPECT_GT(l.scene.mesh.triangle_count(), 0u);
    EXPECT_TRUE(l.scene.textures.empty());  // the one texture (if any) is left out
    SceneOptions strict;
    strict.strict = true;
    try {
      (void)load_scene(file, strict);
      ADD_FAILURE() << "loaded under strict";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), file);
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      EXPECT_NE(e.problem().find("--strict"), std::string::npos) << e.what();
      ASSERT_FALSE(l.warnings.empty());
      EXPECT_EQ(e.problem(), l.warnings.front() + " (--strict)");
    }
  }
}

TEST(LoadWarnings, EachNamesWhatIsMissingAndTheFallback) {
  const Loaded gltf = load_with_report(kWarn + "missing_texture.gltf");
  ASSERT_EQ(gltf.warnings.size(), 1u);
  EXPECT_EQ(gltf.warnings[0], "texture image 'no_such_texture.png' is missing or could not be decoded: drawn without it");
  ASSERT_EQ(gltf.scene.materials.size(), 1u);
  EXPECT_FALSE(gltf.scene.materials[0].base_color_texture.valid());  // factors alone

  const Loaded junk = load_with_report(kWarn + "undecodable_texture.gltf");
  ASSERT_EQ(junk.warnings.size(), 1u);
  EXPECT_EQ(junk.warnings[0], "texture image 'not_an_image.png' is missing or could not be decoded: drawn without it");

  const Loaded mtl = load_with_report(kWarn + "missing_mtl.obj");
  ASSERT_EQ(mtl.warnings.size(), 1u);
  EXPECT_EQ(mtl.warnings[0], "material library 'no_such_library.mtl' not found: default material used");
  for (const Material& m : mtl.scene.materials) EXPECT_EQ(m.name, "default");

  const Loaded map = load_with_report(kWarn + "missing_map.obj");
  ASSERT_EQ(map.warnings.size(), 1u);
  EXPECT_EQ(map.warnings[0], "texture 'no_such_map.png' not found: drawn without it");
  ASSERT_FALSE(map.scene.materials.empty());
  EXPECT_EQ(map.scene.materials[0].name, "painted");
  EXPECT_EQ(map.scene.materials[0].base_color, glm::vec4(0.5f, 0.25f, 1.0f, 1.0f));  // Kd kept
  EXPECT_FALSE(map.scene.materials[0].base_color_texture.valid());

  // ../good/checker.png exists but lies outside the OBJ's folder: never read.
  const Loaded outside = load_with_report(kWarn + "outside_map.obj");
  ASSERT_EQ(outside.warnings.size(), 1u);
  EXPECT_NE(outside.warnings[0].find("outside the OBJ's folder"), std::string::npos);

  const Loaded undecodable = load_with_report(kWarn + "undecodable_map.obj");
  ASSERT_EQ(undecodable.warnings.size(), 1u);
  EXPECT_NE(undecodable.warnings[0].find("'not_an_image.png' could not be decoded"), std::string::npos);
}

TEST(LoadWarnings, ARepeatedWarningIsKeptOnce) {
  LoadReport report;
  report.warn("a");
  report.warn("b");
  report.warn("a");
  EXPECT_EQ(report.warnings, (std::vector<std::string>{"a", "b"}));
}

}  // namespace
}  // namespace speculum
