// chrome_trace_json is valid JSON for any node, counter and launch names, keeps times in µs
// to the nanosecond, and writes integral counters as integers.
#include "parallel/graph.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace speculum::par {
namespace {

TEST(ChromeTraceJson, EscapesNamesAndKeepsNumbers) {
  const std::string node = "mirror \"A\"\\1\n", counter = "rays \"hit\"";
  RunReport report;
  NodeRecord record;
  record.name = node;
  record.start_ns = 1500;
  record.duration_ns = 2001;
  record.counters[counter] = 42;
  report.nodes.push_back(record);
  LaunchRecord launch;
  launch.name = "kernel\t\"x\"";
  launch.scope = node;
  launch.elements = 7;
  launch.chunks = 2;
  launch.start_ns = 1600;
  launch.duration_ns = 10;
  const std::string text = chrome_trace_json(report, {launch});

  nlohmann::json trace;
  ASSERT_NO_THROW(trace = nlohmann::json::parse(text)) << text;
  EXPECT_EQ(trace["displayTimeUnit"], "ms");
  const nlohmann::json* node_event = nullptr;
  const nlohmann::json* launch_event = nullptr;
  for (const auto& e : trace["traceEvents"]) {
    if (e["ph"] != "X") continue;
    (e["cat"] == "node" ? node_event : launch_event) = &e;
  }
  ASSERT_NE(node_event, nullptr) << text;
  ASSERT_NE(launch_event, nullptr) << text;
  EXPECT_EQ((*node_event)["name"], node);
  EXPECT_DOUBLE_EQ((*node_event)["ts"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ((*node_event)["dur"].get<double>(), 2.001);
  ASSERT_TRUE((*node_event)["args"][counter].is_number_integer()) << text;
  EXPECT_EQ((*node_event)["args"][counter].get<int>(), 42);
  EXPECT_EQ((*launch_event)["name"], launch.name);
  EXPECT_EQ((*launch_event)["tid"], (*node_event)["tid"]);  // on its node's track
  EXPECT_EQ((*launch_event)["args"]["elements"], 7);
}

}  // namespace
}  // namespace speculum::par
