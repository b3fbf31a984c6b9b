// `speculum profile`: trace.json is valid Chrome trace-event JSON with one complete event per
// executed node and the kernel launches on their node's track; counters.json has every node
// in execution order with shares that sum to about the frame.
#include <map>

#include <nlohmann/json.hpp>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

TEST(Profile, TraceHasOneEventPerNodeAndCountersCoverEveryNode) {
  const fs::path dir = test::scratch_dir();
  const auto r = test::run_speculum(
      "-q profile sphere-in-room --width 40 --height 30 --cube-size 16 --shadow-size 32 "
      "--repeat 3 -o " + test::sh_quote(dir.string()),
      dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto counters = nlohmann::json::parse(test::slurp(dir / "counters.json"));
  const auto trace = nlohmann::json::parse(test::slurp(dir / "trace.json"));
  EXPECT_EQ(counters["repeat"], 3);
  EXPECT_EQ(counters["frame_ms"].size(), 3u);

  std::map<std::string, int> node_events;
  std::map<std::string, int> track_of_node;
  int launches = 0;
  for (const auto& e : trace["traceEvents"]) {
    if (e["ph"] != "X") continue;
    EXPECT_GE(e["dur"].get<double>(), 0.0);
    if (e["cat"] == "node") {
      ++node_events[e["name"]];
      track_of_node[e["name"]] = e["tid"];
    } else if (e["cat"] == "launch") {
      ++launches;
      EXPECT_NE(e["tid"], 0) << e["name"];  // every launch happens inside some node
    }
  }
  double share_sum = 0;
  ASSERT_FALSE(counters["nodes"].empty());
  for (const auto& n : counters["nodes"]) {
    EXPECT_EQ(node_events[n["name"]], 1) << n["name"];
    share_sum += n["share"].get<double>();
  }
  EXPECT_EQ(node_events.size(), counters["nodes"].size());
  EXPECT_GT(launches, int(counters["nodes"].size()));
  // Medians of parts need not add up exactly; the nodes cover the frame up to graph overhead
  // (and concurrent nodes may overlap).
  EXPECT_GT(share_sum, 0.5);

  // The text table: one row per node plus the frame.
  EXPECT_NE(r.out.find("median_ms"), std::string::npos);
  for (const auto& n : counters["nodes"])
    EXPECT_NE(r.out.find(n["name"].get<std::string>()), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum
