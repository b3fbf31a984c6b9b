// The real speculum binary on bad input (exit 2, one stderr line naming the file, no
// output file) and on the scenes/info commands.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace {

struct CommandResult {
  int status = -1;
  std::string out, err;
};

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::filesystem::path scratch() {
  auto dir = std::filesystem::temp_directory_path() /
             ("speculum_cli_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  std::filesystem::create_directories(dir);
  return dir;
}

CommandResult run(const std::string& args, const std::filesystem::path& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = std::string("'") + SPECULUM_BINARY + "' " + args + " >'" + out.string() +
                          "' 2>'" + err.string() + "'";
  const int raw = std::system(cmd.c_str());
  CommandResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

std::size_t lines(const std::string& s) {
  std::size_t n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

TEST(CliScenes, BadInputExitsTwoWithOneLineAndNoOutputFile) {
  const auto dir = scratch();
  const std::string data = SPECULUM_TEST_DATA "/bad/";
  for (const std::string name : {"truncated.glb", "node_cycle.gltf", "missing_bin.gltf",
                                 "nan_position.gltf", "absurd_count.ply", "truncated.stl",
                                 "empty.obj", "unsupported_file_type.xyz"}) {
    SCOPED_TRACE(name);
    const std::string file = data + name;
    const auto output = dir / "out.glb";
    const CommandResult info = run("info '" + file + "'", dir);
    EXPECT_EQ(info.status, 2);
    EXPECT_EQ(lines(info.err), 1u) << info.err;
    EXPECT_NE(info.err.find(file), std::string::npos) << info.err;
    const CommandResult exp = run("scenes export '" + file + "' '" + output.string() + "'", dir);
    EXPECT_EQ(exp.status, 2);
    EXPECT_EQ(lines(exp.err), 1u) << exp.err;
    EXPECT_NE(exp.err.find(file), std::string::npos) << exp.err;
    EXPECT_FALSE(std::filesystem::exists(output));
  }
  const CommandResult missing = run("info /no/such/file.gltf", dir);
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("/no/such/file.gltf"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(CliScenes, ListExportAndInfoAgree) {
  const auto dir = scratch();
  const CommandResult list = run("scenes list", dir);
  EXPECT_EQ(list.status, 0);
  for (const char* name : {"sphere-in-room", "glossy-plane", "mirror-corridor", "living-room",
                           "glass-sphere", "bowl", "bumpy-sphere", "ellipsoid", "caustic-ring", "water-slab"})
    EXPECT_NE(list.out.find(name), std::string::npos) << name;
  const auto glb = dir / "room.glb";
  const CommandResult exp = run("scenes export living-room '" + glb.string() + "' --size 3000", dir);
  ASSERT_EQ(exp.status, 0) << exp.err;
  ASSERT_TRUE(std::filesystem::exists(glb));
  const CommandResult a = run("info living-room --size 3000", dir);
  const CommandResult b = run("info '" + glb.string() + "'", dir);
  ASSERT_EQ(a.status, 0);
  ASSERT_EQ(b.status, 0) << b.err;
  auto field = [](const std::string& text, const std::string& key) {
    const auto at = text.find(key);
    return at == std::string::npos ? std::string("?") : text.substr(at, text.find('\n', at) - at);
  };
  for (const char* key : {"triangles:", "vertices:", "objects:", "materials:", "lights:", "textures:"})
    EXPECT_EQ(field(a.out, key), field(b.out, key));
  EXPECT_EQ(run("info --help", dir).status, 0);
  EXPECT_EQ(run("scenes export --help", dir).status, 0);
  std::filesystem::remove_all(dir);
}

// `--param name=value` (render, inspect, profile): a name the chosen technique does not read,
// or a value that is not a number, is bad input (exit 2, one stderr line naming the
// parameter; for a name, also the technique's known ones), and no image is written.
TEST(CliScenes, BadTechniqueParamExitsTwoNamingIt) {
  const auto dir = scratch();
  const auto output = dir / "out.png";
  const std::string frame = " sphere-in-room --width 16 --height 16 ";
  const std::string out = " -o '" + output.string() + "'";

  const CommandResult unknown = run("render" + frame + "-t distance-map --param nosuch=1" + out, dir);
  EXPECT_EQ(unknown.status, 2) << unknown.err;
  EXPECT_EQ(lines(unknown.err), 1u) << unknown.err;
  EXPECT_NE(unknown.err.find("nosuch"), std::string::npos) << unknown.err;
  EXPECT_NE(unknown.err.find("distance-map"), std::string::npos) << unknown.err;
  for (const char* known : {"linear_steps", "secant_steps", "parallax"})
    EXPECT_NE(unknown.err.find(known), std::string::npos) << known << ": " << unknown.err;
  EXPECT_FALSE(std::filesystem::exists(output));

  // A name is known per technique: multi-reflection's `rounds` is not distance-map's.
  const CommandResult other = run("render" + frame + "-t distance-map --param rounds=2" + out, dir);
  EXPECT_EQ(other.status, 2) << other.err;
  EXPECT_NE(other.err.find("rounds"), std::string::npos) << other.err;
  EXPECT_FALSE(std::filesystem::exists(output));

  // A technique without parameters says so.
  const CommandResult none = run("render" + frame + "-t envmap --param depth=2" + out, dir);
  EXPECT_EQ(none.status, 2) << none.err;
  EXPECT_EQ(lines(none.err), 1u) << none.err;
  EXPECT_NE(none.err.find("depth"), std::string::npos) << none.err;
  EXPECT_FALSE(std::filesystem::exists(output));

  for (const std::string bad : {"linear_steps=abc", "linear_steps=", "linear_steps=4x", "=4",
                                "linear_steps", "linear_steps=nan"}) {
    SCOPED_TRACE(bad);
    const CommandResult r = run("render" + frame + "-t distance-map --param '" + bad + "'" + out, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("--param"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(output));
  }

  // inspect and profile share the check.
  for (const std::string cmd : {"inspect", "profile"}) {
    SCOPED_TRACE(cmd);
    const CommandResult r = run(cmd + frame + "-t multi-reflection --param nosuch=1", dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("nosuch"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("lagged"), std::string::npos) << r.err;
  }
  std::filesystem::remove_all(dir);
}

TEST(CliScenes, KnownTechniqueParamsRender) {
  const auto dir = scratch();
  const auto output = dir / "out.png";
  for (const std::string args : {"-t distance-map --param linear_steps=8 --param secant_steps=2",
                                 "-t multi-reflection --param rounds=2 --param lagged=0"}) {
    SCOPED_TRACE(args);
    std::filesystem::remove(output);
    const CommandResult r = run("--quiet render sphere-in-room --width 16 --height 16 " + args +
                                    " -o '" + output.string() + "'",
                                dir);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(output));
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
