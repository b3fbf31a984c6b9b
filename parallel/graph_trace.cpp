// Chrome trace-event JSON export of a graph run and its kernel launches (opens in Perfetto
// and chrome://tracing; format: "Trace Event Format", complete events ph="X", times in µs).
#include <algorithm>
#include <cmath>
#include <map>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "parallel/graph.h"

namespace speculum::par {

namespace {
using Json = nlohmann::ordered_json;  // keys in the order written: "name" first, as viewers list them

// Trace times are µs; three decimals keep the nanoseconds the executor measured.
double micros(std::int64_t ns) { return double(ns) / 1000.0; }

// A counter as an event argument: integral values as integers whatever the counter type.
template <class T>
Json counter_value(T v) {
  if constexpr (std::is_floating_point_v<T>) {
    constexpr double kExactIntegers = 9007199254740992.0;  // 2^53
    if (std::isfinite(v) && v == std::trunc(v) && std::abs(double(v)) < kExactIntegers)
      return static_cast<std::int64_t>(v);
  }
  return v;
}
}  // namespace

std::string chrome_trace_json(const RunReport& report, const std::vector<LaunchRecord>& launches) {
  // Concurrent nodes must not share a track (events on one track have to nest), so assign
  // tracks greedily by start time; track 0 holds launches issued outside any node.
  std::vector<const NodeRecord*> nodes;
  for (const auto& n : report.nodes) nodes.push_back(&n);
  std::stable_sort(nodes.begin(), nodes.end(),
                   [](auto* a, auto* b) { return a->start_ns < b->start_ns; });
  std::vector<std::int64_t> track_end;
  std::map<std::string, int, std::less<>> track_of;
  for (const auto* n : nodes) {
    std::size_t t = 0;
    while (t < track_end.size() && track_end[t] > n->start_ns) ++t;
    if (t == track_end.size()) track_end.push_back(0);
    track_end[t] = n->start_ns + n->duration_ns;
    track_of[n->name] = int(t) + 1;
  }
  Json events = Json::array();
  events.push_back({{"name", "thread_name"}, {"ph", "M"}, {"pid", 1}, {"tid", 0}, {"args", {{"name", "launches"}}}});
  for (std::size_t t = 0; t < track_end.size(); ++t)
    events.push_back({{"name", "thread_name"}, {"ph", "M"}, {"pid", 1}, {"tid", t + 1},
                      {"args", {{"name", "graph " + std::to_string(t + 1)}}}});
  for (const auto* n : nodes) {
    Json args = Json::object();
    for (const auto& [k, v] : n->counters) args[k] = counter_value(v);
    events.push_back({{"name", n->name}, {"cat", "node"}, {"ph", "X"}, {"pid", 1}, {"tid", track_of[n->name]},
                      {"ts", micros(n->start_ns)}, {"dur", micros(n->duration_ns)}, {"args", std::move(args)}});
  }
  for (const auto& l : launches) {
    auto it = track_of.find(l.scope);
    const int tid = it == track_of.end() ? 0 : it->second;
    events.push_back({{"name", l.name}, {"cat", "launch"}, {"ph", "X"}, {"pid", 1}, {"tid", tid},
                      {"ts", micros(l.start_ns)}, {"dur", micros(l.duration_ns)},
                      {"args", {{"elements", l.elements}, {"chunks", l.chunks}}}});
  }
  const Json trace{{"displayTimeUnit", "ms"}, {"traceEvents", std::move(events)}};
  return trace.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace speculum::par
