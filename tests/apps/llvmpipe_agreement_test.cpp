// Our tile rasterizer against an independent one: Mesa's llvmpipe (through OSMesa, the
// raster yardstick speculum_llvmpipe_bench) draws the same triangles from the same camera,
// and both write the visible triangle of every pixel. Both sample pixel centres with a
// top-left fill rule and test depth LESS, so they must agree everywhere but where subpixel
// snapping or depth precision decides a pixel on an edge between neighbouring triangles.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/scene.h"
#include "core/scene_loader.h"
#include "tests/apps/speculum_run.h"
#include "tests/test_dependency.h"

namespace speculum::test {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint32_t> read_ids(const fs::path& path) {
  const std::string bytes = slurp(path);
  std::vector<std::uint32_t> ids(bytes.size() / sizeof(std::uint32_t));
  std::memcpy(ids.data(), bytes.data(), ids.size() * sizeof(std::uint32_t));
  return ids;
}

bool share_a_corner(const TriangleMesh& mesh, std::uint32_t s, std::uint32_t t) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (mesh.positions[mesh.indices[3 * s + i]] == mesh.positions[mesh.indices[3 * t + j]]) return true;
  return false;
}

struct View {
  const char* scene;
  const char* eye;
  const char* target;
  const char* fov;
};

class LlvmpipeAgreement : public ::testing::TestWithParam<View> {};

TEST_P(LlvmpipeAgreement, VisibleTriangleMatchesLlvmpipeExceptOnEdges) {
#ifndef SPECULUM_LLVMPIPE_BENCH
  SPECULUM_REQUIRE(false, "the Debian package libosmesa6-dev (then configure again)");
#else
  const View v = GetParam();
  const fs::path dir = scratch_dir();
  constexpr int kWidth = 320, kHeight = 240;
  const std::string size = " --width " + std::to_string(kWidth) + " --height " + std::to_string(kHeight);
  const std::string camera = std::string(" --eye ") + v.eye + " --target " + v.target + " --fov " + v.fov;
  const std::string mesh = sh_quote((dir / "mesh.ply").string());
  const CommandResult ours = run_speculum(
      std::string("--threads 2 bench raster ") + v.scene + size + camera + " --repeat 1 --write-ply " +
          mesh + " --write-ids " + sh_quote((dir / "ours.u32").string()),
      dir);
  ASSERT_EQ(ours.status, 0) << ours.err;
  // llvmpipe's planes bracket the scene (ours clip at the scene camera's, which these views
  // keep clear of).
  const CommandResult gl = run_shell(
      "LP_NUM_THREADS=2 " + sh_quote(SPECULUM_LLVMPIPE_BENCH) + " " + mesh + size + camera +
          " --near 0.05 --far 100 --repeat 1 --write-ids " + sh_quote((dir / "llvmpipe.u32").string()),
      dir);
  ASSERT_EQ(gl.status, 0) << gl.err;

  const Scene mesh_read = load_scene((dir / "mesh.ply").string());
  const std::vector<std::uint32_t> a = read_ids(dir / "ours.u32"), b = read_ids(dir / "llvmpipe.u32");
  ASSERT_EQ(a.size(), std::size_t(kWidth) * kHeight);
  ASSERT_EQ(b.size(), a.size());
  std::size_t covered_a = 0, covered_b = 0, differ = 0, unexplained = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const std::size_t i = std::size_t(y) * kWidth + x;
      covered_a += a[i] != 0;
      covered_b += b[i] != 0;
      if (a[i] == b[i]) continue;
      ++differ;
      // An edge pixel: one rasterizer's triangle is drawn by the other right beside it (a
      // sliver thinner than a pixel may be drawn by one only, so either way counts).
      const auto drawn_beside = [&](const std::vector<std::uint32_t>& ids, std::uint32_t id) {
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < kWidth && yy < kHeight && ids[std::size_t(yy) * kWidth + xx] == id)
              return true;
          }
        return false;
      };
      // Or the two are mesh neighbours (a shared corner) that both cover less than a pixel.
      const bool beside = drawn_beside(a, b[i]) || drawn_beside(b, a[i]) ||
                          (a[i] != 0 && b[i] != 0 && share_a_corner(mesh_read.mesh, a[i] - 1, b[i] - 1));
      unexplained += !beside;
    }
  EXPECT_GT(covered_b, a.size() / 4) << "the view should show the scene";
  // A silhouette pixel may fall either way, so coverage agrees to the edge pixels.
  EXPECT_LE(covered_a > covered_b ? covered_a - covered_b : covered_b - covered_a, a.size() / 1000);
  EXPECT_LE(differ, a.size() / 1000) << differ << " of " << a.size() << " pixels differ";
  EXPECT_EQ(unexplained, 0u) << "pixels where neither rasterizer draws the other's triangle nearby";
#endif
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, LlvmpipeAgreement,
    ::testing::Values(View{"sphere-in-room", "0.3,1.2,3.1", "0,0.4,0", "50"},
                      View{"glossy-plane", "0.3,1.2,3.1", "0,0.4,0", "50"},
                      View{"bowl", "1.5,2.2,2.5", "0,0.2,0", "40"}),
    [](const ::testing::TestParamInfo<View>& info) {  // gtest names: letters, digits, _
      std::string name = info.param.scene;
      for (char& c : name)
        if (c == '-') c = '_';
      return name;
    });

}  // namespace
}  // namespace speculum::test
