// `speculum scenes export` says, on one stderr line, that the environment is carried only
// for speculum (other viewers will not show it); --quiet silences it; `info` on the export
// reports the same environment as on the built-in scene.
#include <string>

#include <gtest/gtest.h>

#include "speculum_run.h"

namespace speculum::test {
namespace {

std::size_t line_count(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

std::string environment_line(const std::string& info) {
  const auto at = info.find("environment:");
  return at == std::string::npos ? "?" : info.substr(at, info.find('\n', at) - at);
}

TEST(CliExportEnvironment, WarnsOnceUnlessQuietAndInfoSeesItBack) {
  const auto dir = scratch_dir();
  for (const std::string scene : {"sphere-in-room", "glossy-plane"}) {  // constant, equirect
    SCOPED_TRACE(scene);
    const std::string out = (dir / (scene + ".glb")).string();
    const CommandResult loud = run_speculum("scenes export " + scene + " " + sh_quote(out) + " --size 2000", dir);
    ASSERT_EQ(loud.status, 0) << loud.err;
    EXPECT_EQ(line_count(loud.err), 1u) << loud.err;
    EXPECT_NE(loud.err.find("warning"), std::string::npos) << loud.err;
    EXPECT_NE(loud.err.find(out), std::string::npos) << loud.err;
    EXPECT_NE(loud.err.find("extras.speculum_environment"), std::string::npos) << loud.err;

    const CommandResult quiet = run_speculum("--quiet scenes export " + scene + " " + sh_quote(out) + " --size 2000", dir);
    ASSERT_EQ(quiet.status, 0) << quiet.err;
    EXPECT_EQ(quiet.err, "");

    // `info` prints the environment's size/colour and intensity (the source differs: the
    // export names the .glb), so compare the line without its parenthesised source.
    auto without_source = [](std::string line) {
      const auto open = line.find('('), close = line.find(')');
      if (line.find("equirect") != std::string::npos && open != std::string::npos && close != std::string::npos)
        line.erase(open, close - open + 1);
      return line;
    };
    const CommandResult a = run_speculum("info " + scene + " --size 2000", dir);
    const CommandResult b = run_speculum("info " + sh_quote(out), dir);
    ASSERT_EQ(a.status, 0) << a.err;
    ASSERT_EQ(b.status, 0) << b.err;
    EXPECT_NE(environment_line(a.out), "?");
    EXPECT_EQ(without_source(environment_line(b.out)), without_source(environment_line(a.out)));
  }
  // A file with no environment (black) loses nothing in other viewers: no warning.
  const std::string out = (dir / "triangle.glb").string();
  const CommandResult plain =
      run_speculum("scenes export " + sh_quote(SPECULUM_TEST_DATA "/good/triangle.gltf") + " " + sh_quote(out), dir);
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(plain.err, "");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum::test
