// The bad-input corpus (tests/data/bad, made by tests/data/make_corpus.py): every file must
// be rejected with InputError naming the file — never a crash or another exception.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

std::vector<std::string> bad_files() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(SPECULUM_TEST_DATA "/bad"))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(BadInput, CorpusIsComplete) {
  // Guards against the corpus silently shrinking (each category of the issue is present).
  const auto files = bad_files();
  EXPECT_GE(files.size(), 40u);
  for (const char* needed :
       {"empty.gltf", "truncated.glb", "invalid_json.gltf", "missing_bin.gltf",
        "index_out_of_range.gltf", "nan_position.gltf", "inf_position.glb",
        "unsupported_extension.gltf", "draco_required.gltf", "meshopt_required.gltf",
        "gltf_1_0.gltf", "gltf_1_0.glb", "gltf_1_0_no_asset.gltf", "unsupported_file_type.xyz", "node_cycle.gltf",
        "absurd_count.gltf", "absurd_count.ply", "absurd_count.off", "absurd_count.stl",
        "index_out_of_range.obj", "truncated.stl"})
    EXPECT_TRUE(std::filesystem::exists(std::string(SPECULUM_TEST_DATA "/bad/") + needed)) << needed;
}

TEST(BadInput, EveryFileGivesInputErrorNamingIt) {
  for (const std::string& file : bad_files()) {
    SCOPED_TRACE(file);
    try {
      (void)load_scene(file);
      ADD_FAILURE() << "loaded without error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), file);
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos);
      EXPECT_FALSE(e.problem().empty());
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line";
    } catch (const std::exception& e) {
      ADD_FAILURE() << "threw a non-InputError: " << e.what();
    }
  }
}

TEST(BadInput, SpecificProblemsAreNamed) {
  auto problem = [](const std::string& name) {
    try {
      (void)load_scene(std::string(SPECULUM_TEST_DATA "/bad/") + name);
    } catch (const InputError& e) {
      return e.problem();
    }
    return std::string("(no error)");
  };
  EXPECT_NE(problem("node_cycle.gltf").find("cycle"), std::string::npos);
  EXPECT_NE(problem("index_out_of_range.gltf").find("out of range"), std::string::npos);
  EXPECT_NE(problem("nan_position.gltf").find("NaN or infinite"), std::string::npos);
  EXPECT_NE(problem("truncated.glb").find("truncated"), std::string::npos);
  EXPECT_NE(problem("unsupported_extension.gltf").find("KHR_draco_mesh_compression"), std::string::npos);
  // Unsupported content names itself, not the symptom (an invalid bufferView, no triangles).
  EXPECT_EQ(problem("draco_required.gltf"), "extension KHR_draco_mesh_compression is not supported");
  EXPECT_EQ(problem("meshopt_required.gltf"), "extension EXT_meshopt_compression is not supported");
  EXPECT_EQ(problem("two_unsupported_extensions.gltf"),
            "extensions KHR_draco_mesh_compression, EXT_meshopt_compression are not supported");
  for (const char* v1 : {"gltf_1_0.gltf", "gltf_1_0.glb", "gltf_1_0_no_asset.gltf"})
    EXPECT_EQ(problem(v1), "glTF 1.0 is not supported, 2.0 is") << v1;
  EXPECT_NE(problem("absurd_count.gltf").find("absurd"), std::string::npos);
  EXPECT_NE(problem("empty.glb").find("empty"), std::string::npos);
  EXPECT_NE(problem("point_cloud.ply").find("no faces"), std::string::npos);
}

TEST(BadInput, AssimpGltf1AndDracoFilesNameTheUnsupportedContent) {
  const std::string models = "/usr/share/assimp/models/";
  SPECULUM_REQUIRE(std::filesystem::exists(models + "glTF"), "the Debian package assimp-testmodels");
  auto problem = [](const std::string& file) {
    try {
      (void)load_scene(file);
    } catch (const InputError& e) {
      return e.problem();
    }
    return std::string("(no error)");
  };
  std::size_t v1 = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(models + "glTF")) {
    const std::string ext = e.path().extension().string();
    if (ext != ".gltf" && ext != ".glb") continue;
    SCOPED_TRACE(e.path().string());
    EXPECT_EQ(problem(e.path().string()), "glTF 1.0 is not supported, 2.0 is");
    ++v1;
  }
  EXPECT_GE(v1, 7u);
  EXPECT_EQ(problem(models + "glTF2/draco/2CylinderEngine.gltf"),
            "extension KHR_draco_mesh_compression is not supported");
}

TEST(BadInput, MissingFileAndUnknownName) {
  for (const std::string& name : {std::string(SPECULUM_TEST_DATA "/bad/no_such_file.glb"),
                                 std::string("/nonexistent/dir/scene.obj"),
                                 std::string("no-such-builtin-scene"),
                                 std::string("sphere-in-room:size=12"),
                                 std::string("sphere-in-room:size=abc"),
                                 std::string("sphere-in-room:colour=3"),
                                 std::string("bumpy-sphere:n=-1"),
                                 // Option names match whole: not a piece of one, not empty.
                                 std::string("bumpy-sphere:mplitude=0.1"),
                                 std::string("bumpy-sphere:=0.1"),
                                 std::string("sphere-in-room:size=10000000000")}) {
    SCOPED_TRACE(name);
    try {
      (void)load_scene(name);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), name);
    }
  }
}

}  // namespace
}  // namespace speculum
