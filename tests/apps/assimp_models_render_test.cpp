// A new user's first render: every glTF, OBJ, PLY, OFF and STL model of Debian's
// assimp-testmodels that loads renders with the default options to an image that is not
// black, and the light-less ones say that the default studio light was used. Files that do
// not load fail with one InputError naming the file, never another exception or a crash.
// In-process (one executor, 64×48 envmap frames), so the whole sweep takes seconds.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include "apps/cli/frame_options.h"
#include "apps/techniques/render_frame.h"
#include "core/error.h"
#include "core/lighting_presets.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

constexpr const char* kModels = "/usr/share/assimp/models";
constexpr std::uintmax_t kMaxBytes = 20u << 20;

TEST(AssimpModelsRender, EveryLoadableModelRendersNonBlackWithTheDefaults) {
  SPECULUM_REQUIRE(std::filesystem::exists(kModels), "the Debian package assimp-testmodels");
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(kModels)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb" || ext == ".obj" || ext == ".ply" ||
                                ext == ".off" || ext == ".stl"))
      files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 60u);
  std::size_t rendered = 0, nonblack = 0, defaulted = 0, rejected = 0, skipped = 0;
  par::Executor executor(2);
  const pipeline::Technique& envmap = pipeline::find_technique("envmap");
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    if (std::filesystem::file_size(file) > kMaxBytes) {
      ++skipped;
      continue;
    }
    Scene scene;
    try {
      scene = load_scene(file);
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), file);
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      ++rejected;
      continue;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not an InputError: " << e.what();
      continue;
    }
    // The options `speculum render FILE` uses, at a small size.
    pipeline::FrameOptions o;
    o.exposure = "auto";
    o.width = 64;
    o.height = 48;
    const pipeline::FrameSettings f = pipeline::make_frame_settings(o, scene);
    const bool unlit = scene_is_unlit(scene);
    const std::vector<std::string> warnings = pipeline::apply_light_options(o, scene, f.camera);
    EXPECT_EQ(warnings.size(), unlit ? 1u : 0u);
    if (unlit) {
      ++defaulted;
      EXPECT_EQ(warnings[0].rfind("speculum: warning: " + file + ": no lights and no environment", 0), 0u);
    }
    const pipeline::FrameResult r = pipeline::render_frame(scene, envmap, f, executor);
    // Not black: some pixel reaches 1/255 of the display range.
    float brightest = 0.0f;
    for (const glm::vec4& p : r.display.pixels) brightest = std::max({brightest, p.x, p.y, p.z});
    EXPECT_GE(brightest, 1.0f / 255.0f);
    nonblack += brightest >= 1.0f / 255.0f;
    ++rendered;
  }
  std::printf("assimp models: %zu files, %zu rendered, %zu non-black (%zu with the default light), "
              "%zu rejected with an InputError, %zu skipped (> 20 MB)\n",
              files.size(), rendered, nonblack, defaulted, rejected, skipped);
  EXPECT_EQ(rendered + rejected + skipped, files.size());
  EXPECT_GE(rendered, 50u);
}

}  // namespace
}  // namespace speculum
