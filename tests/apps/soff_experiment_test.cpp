// `speculum experiment soff --quick --json`: one row per (scene, path) with the fields the
// SOFF §4 reproduction reports, and values in their valid ranges; a scene without camera
// paths is an input error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "speculum_run.h"

namespace speculum {
namespace {

TEST(SoffExperiment, QuickJsonRowHasTheFields) {
  const auto dir = test::scratch_dir();
  const auto r = test::run_speculum(
      "-q experiment soff --quick --json --scenes bathroom:size=20000 --frames 2 --width 64 --glossy-samples 8 "
      "--reference-spp 2",
      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int rows = 0;
  while (std::getline(lines, line)) {
    if (line.empty()) continue;
    const auto j = nlohmann::json::parse(line);
    ++rows;
    EXPECT_EQ(j.value("scene", ""), "bathroom:size=20000");
    EXPECT_EQ(j.value("path", ""), "walk");
    EXPECT_EQ(j.value("frames", 0), 2);
    for (const char* key : {"mae8_specular", "mae8_frame", "disocclusion_pct_avg", "disocclusion_pct_max",
                            "clusters_avg", "clusters_max", "ms", "ms_trace_rebuild", "ms_trace_prebuilt"})
      ASSERT_TRUE(j.contains(key)) << key;
    EXPECT_GT(j["mae8_specular"].get<double>(), 0.0);
    EXPECT_LT(j["mae8_specular"].get<double>(), 64.0);
    EXPECT_GE(j["disocclusion_pct_max"].get<double>(), j["disocclusion_pct_avg"].get<double>());
    EXPECT_LE(j["disocclusion_pct_max"].get<double>(), 100.0);
    EXPECT_GE(j["clusters_max"].get<double>(), j["clusters_avg"].get<double>());
    EXPECT_GE(j["clusters_avg"].get<double>(), 1.0);
    EXPECT_GE(j["ms_trace_rebuild"].get<double>(), j["ms_trace_prebuilt"].get<double>());
  }
  EXPECT_EQ(rows, 1) << "--quick: one scene, one path";
}

TEST(SoffExperiment, SceneWithoutPathsIsAnInputError) {
  const auto dir = test::scratch_dir();
  const auto r = test::run_speculum("experiment soff --scenes sphere-in-room --quick", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("speculum: --scenes", 0), 0u) << r.err;
}

}  // namespace
}  // namespace speculum
