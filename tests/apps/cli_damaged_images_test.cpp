// Damaged PNGs through the command line: an environment image that libpng cannot decode is
// one line on stderr and exit 2, and a glTF texture that cannot be decoded is one warning —
// libpng's own "libpng error: ..." lines never reach stderr (core/png_check.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Result {
  int status = -1;
  std::string err;
};

Result run(const std::string& args, const fs::path& dir) {
  const std::string cmd = std::string("cd '") + dir.string() + "' && '" + SPECULUM_BINARY + "' " + args +
                          " >/dev/null 2>'" + (dir / "stderr.txt").string() + "'";
  const int raw = std::system(cmd.c_str());
  return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(dir / "stderr.txt")};
}

std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / ("speculum_damaged_png_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(CliDamagedImages, TruncatedPngEnvironmentIsOneLineExitTwo) {
  const fs::path dir = scratch();
  const std::string png = slurp(fs::path(SPECULUM_TEST_DATA) / "good" / "checker.png");
  ASSERT_GT(png.size(), 40u);
  for (const std::size_t cut : {std::size_t{20}, png.size() / 2, png.size() - 13}) {
    SCOPED_TRACE(cut);
    std::ofstream(dir / "env.png", std::ios::binary | std::ios::trunc) << png.substr(0, cut);
    const Result r = run("render sphere-in-room:size=1000 --width 16 --height 12 --env env.png -o out.png", dir);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("speculum: env.png: cannot read image", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
  }
  fs::remove_all(dir);
}

TEST(CliDamagedImages, UndecodableGltfTextureIsAWarningWithoutLibpngLines) {
  const fs::path dir = scratch();
  const std::string png = slurp(fs::path(SPECULUM_TEST_DATA) / "good" / "checker.png");
  std::ofstream(dir / "tex.png", std::ios::binary) << png.substr(0, png.size() / 2);
  std::string gltf = slurp(fs::path(SPECULUM_TEST_DATA) / "good" / "triangle.gltf");
  gltf.replace(gltf.find(R"("roughnessFactor": 0.0)"), 22,
               R"("roughnessFactor": 0.0, "baseColorTexture": {"index": 0})");
  gltf.insert(gltf.find(R"( "buffers")"), R"( "textures": [{"source": 0}], "images": [{"uri": "tex.png"}],)");
  std::ofstream(dir / "scene.gltf") << gltf;
  const Result r = run("render scene.gltf --width 16 --height 12 -o out.png", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("libpng"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("speculum: warning: scene.gltf: texture image 'tex.png' is missing or could not be decoded"),
            std::string::npos)
      << r.err;
  fs::remove_all(dir);
}

}  // namespace
