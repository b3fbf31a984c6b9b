// Chrome trace-event JSON export of a graph run and its kernel launches (opens in Perfetto
// and chrome://tracing; format: "Trace Event Format", complete events ph="X", times in µs).
#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "parallel/graph.h"

namespace speculum::par {

namespace {
std::string json_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out;
}

std::string micros(std::int64_t ns) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", double(ns) / 1000.0);
  return buf;
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
  std::ostringstream s;
  s << "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n";
  s << "{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":0,\"args\":{\"name\":\"launches\"}}";
  for (std::size_t t = 0; t < track_end.size(); ++t)
    s << ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":" << t + 1
      << ",\"args\":{\"name\":\"graph " << t + 1 << "\"}}";
  for (const auto* n : nodes) {
    s << ",\n{\"name\":\"" << json_escape(n->name) << "\",\"cat\":\"node\",\"ph\":\"X\",\"pid\":1,\"tid\":"
      << track_of[n->name] << ",\"ts\":" << micros(n->start_ns) << ",\"dur\":" << micros(n->duration_ns)
      << ",\"args\":{";
    bool first = true;
    for (const auto& [k, v] : n->counters) {
      s << (first ? "" : ",") << "\"" << json_escape(k) << "\":" << v;
      first = false;
    }
    s << "}}";
  }
  for (const auto& l : launches) {
    auto it = track_of.find(l.scope);
    const int tid = it == track_of.end() ? 0 : it->second;
    s << ",\n{\"name\":\"" << json_escape(l.name) << "\",\"cat\":\"launch\",\"ph\":\"X\",\"pid\":1,\"tid\":"
      << tid << ",\"ts\":" << micros(l.start_ns) << ",\"dur\":" << micros(l.duration_ns)
      << ",\"args\":{\"elements\":" << l.elements << ",\"chunks\":" << l.chunks << "}}";
  }
  s << "\n]}\n";
  return s.str();
}

}  // namespace speculum::par
