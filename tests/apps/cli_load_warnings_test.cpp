// render, inspect and profile print the loader's warnings (as `info` lists them) once
// each as `speculum: warning: FILE: ...`; --strict turns a missing texture into exit 2.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include "speculum_run.h"

namespace speculum::test {
namespace {

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

const std::string kMissing = SPECULUM_TEST_DATA "/warn/missing_texture.gltf";
const std::string kSmall = " --width 8 --height 8 -t envmap";

TEST(CliLoadWarnings, RenderInspectProfilePrintEachWarningOnce) {
  const auto dir = scratch_dir();
  const std::string line = "speculum: warning: " + kMissing +
                           ": texture image 'no_such_texture.png' is missing or could not be decoded: drawn without it\n";
  const auto out = dir / "out.png";
  const CommandResult render = run_speculum("render " + sh_quote(kMissing) + kSmall + " -o " + sh_quote(out.string()), dir);
  EXPECT_EQ(render.status, 0) << render.err;
  EXPECT_EQ(count(render.err, line), 1u) << render.err;
  EXPECT_EQ(count(render.err, "missing or could not be decoded"), 1u) << render.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  const CommandResult inspect =
      run_speculum("inspect " + sh_quote(kMissing) + kSmall + " -o " + sh_quote((dir / "insp").string()), dir);
  EXPECT_EQ(inspect.status, 0) << inspect.err;
  EXPECT_EQ(count(inspect.err, line), 1u) << inspect.err;
  const CommandResult profile = run_speculum("profile " + sh_quote(kMissing) + kSmall + " --repeat 1 --warmup 0", dir);
  EXPECT_EQ(profile.status, 0) << profile.err;
  EXPECT_EQ(count(profile.err, line), 1u) << profile.err;
  // info lists the same warning.
  const CommandResult info = run_speculum("info " + sh_quote(kMissing), dir);
  EXPECT_NE(info.out.find("texture image 'no_such_texture.png' is missing"), std::string::npos) << info.out;
  // --quiet keeps stderr free of warnings.
  const CommandResult quiet = run_speculum("render --quiet " + sh_quote(kMissing) + kSmall + " -o " + sh_quote(out.string()), dir);
  EXPECT_EQ(quiet.status, 0);
  EXPECT_EQ(quiet.err.find("warning"), std::string::npos) << quiet.err;
  std::filesystem::remove_all(dir);
}

TEST(CliLoadWarnings, StrictMakesAMissingTextureAnInputError) {
  const auto dir = scratch_dir();
  const auto out = dir / "out.png";
  const CommandResult r =
      run_speculum("render " + sh_quote(kMissing) + kSmall + " --strict -o " + sh_quote(out.string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_EQ(r.err, "speculum: " + kMissing +
                       ": texture image 'no_such_texture.png' is missing or could not be decoded: drawn without it (--strict)\n");
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string obj = SPECULUM_TEST_DATA "/warn/missing_mtl.obj";
  const CommandResult o = run_speculum("render " + sh_quote(obj) + kSmall + " --strict -o " + sh_quote(out.string()), dir);
  EXPECT_EQ(o.status, 2);
  EXPECT_EQ(lines(o.err), 1u) << o.err;
  EXPECT_NE(o.err.find("no_such_library.mtl"), std::string::npos) << o.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

TEST(CliLoadWarnings, RecomputedNormalsReachRender) {
  const std::string file = "/usr/share/assimp/models/glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb";
  SPECULUM_REQUIRE(std::filesystem::exists(file), "the Debian package assimp-testmodels");
  const auto dir = scratch_dir();
  const CommandResult r = run_speculum("render " + sh_quote(file) + kSmall + " -o " + sh_quote((dir / "o.png").string()), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count(r.err, "speculum: warning: " + file + ": mesh 0 'Mesh' primitive 0: 4 zero or non-finite normals, recomputed\n"), 1u)
      << r.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum::test
