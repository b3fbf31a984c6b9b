// Every glTF 2.0 file of Debian's assimp-testmodels either loads into a valid scene or is
// rejected with InputError — never a crash and never another exception.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

constexpr const char* kModels = "/usr/share/assimp/models/glTF2";
constexpr std::uintmax_t kMaxBytes = 50u << 20;

TEST(AssimpGltfSweep, EachFileLoadsOrIsRejectedCleanly) {
  SPECULUM_REQUIRE(std::filesystem::exists(kModels), "the Debian package assimp-testmodels");
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(kModels)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb")) files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 40u);
  std::size_t loaded = 0, rejected = 0, skipped_large = 0;
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    if (std::filesystem::file_size(file) > kMaxBytes) {
      ++skipped_large;
      continue;
    }
    try {
      const Scene s = load_scene(file);
      s.validate();
      EXPECT_GT(s.mesh.triangle_count(), 0u);
      EXPECT_GT(s.mesh.vertex_count(), 0u);
      EXPECT_FALSE(s.materials.empty());
      EXPECT_FALSE(s.cameras.empty());
      EXPECT_FALSE(s.objects.empty());
      ++loaded;
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), file);
      ++rejected;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "non-InputError exception: " << e.what();
    }
  }
  std::printf("assimp glTF2 sweep: %zu files, %zu loaded, %zu rejected, %zu skipped (> 50 MB)\n",
              files.size(), loaded, rejected, skipped_large);
  EXPECT_EQ(loaded + rejected + skipped_large, files.size());
}

// The known-broken files of the set must be rejected, not silently accepted.
TEST(AssimpGltfSweep, KnownBrokenFilesAreRejected) {
  SPECULUM_REQUIRE(std::filesystem::exists(kModels), "the Debian package assimp-testmodels");
  for (const char* rel : {"IndexOutOfRange/IndexOutOfRange.gltf",
                          "IndexOutOfRange/AllIndicesOutOfRange.gltf", "MissingBin/BoxTextured.gltf",
                          "RecursiveNodes/RecursiveNodes.gltf",
                          "BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb"}) {
    const std::string file = std::string(kModels) + "/" + rel;
    SCOPED_TRACE(file);
    EXPECT_THROW((void)load_scene(file), InputError);
  }
}

}  // namespace
}  // namespace speculum
