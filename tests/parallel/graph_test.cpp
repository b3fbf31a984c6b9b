// Job graph: validation errors name node and resource; culling, order, concurrency,
// counters, capture, cross-frame edges, DOT and trace export.
#include "parallel/graph.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace speculum::par {
namespace {

// A node with declared ports: out = in * factor, counts the elements.
class ScaleNode : public Node {
 public:
  explicit ScaleNode(float factor) : factor_(factor) {}
  void declare(Ports& p) override { p.input<std::vector<float>>("in").output<std::vector<float>>("out"); }
  Params parameters() const override { return Params().set("factor", factor_); }
  void execute(NodeContext& c) override {
    const auto& in = c.input<std::vector<float>>("in");
    auto& out = c.output<std::vector<float>>("out");
    out.resize(in.size());
    c.executor().parallel_for("scale", in.size(), 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out[i] = in[i] * factor_;
      c.count("elements", e - b);
    });
  }

 private:
  float factor_;
};

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const GraphError& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(Graph, RecipeRunsInOrderWithCountersAndCapture) {
  for (int threads : {1, 2}) {
    Executor ex(threads);
    ex.clear_launches();
    Graph g;
    g.input("src", std::vector<float>{1, 2, 3});
    g.add<ScaleNode>("double", 2.f).bind("in", "src").bind("out", "doubled");
    g.add<ScaleNode>("triple", 3.f).bind("in", "src").bind("out", "tripled");
    g.add("sum", [](NodeContext& c) {
       const auto& a = c.input<std::vector<float>>("doubled");
       const auto& b = c.input<std::vector<float>>("tripled");
       float s = 0;
       for (std::size_t i = 0; i < a.size(); ++i) s += a[i] + b[i];
       c.output<float>("total") = s;
     }).reads<std::vector<float>>("doubled").reads<std::vector<float>>("tripled").writes<float>("total");
    g.add<ScaleNode>("unused", 5.f).bind("in", "src").bind("out", "never");
    g.request("total");
    std::vector<std::string> captured;
    const auto report = g.run(ex, [&](const CapturedOutput& o) {
      captured.push_back(o.node + ":" + o.resource + ":" + o.type_name);
      if (o.resource == "total") {
        EXPECT_EQ(*o.as<float>(), 30.f);
      }
      EXPECT_EQ(o.as<int>(), nullptr);
    });
    EXPECT_EQ(g.get<float>("total"), 30.f);
    EXPECT_EQ(g.order(), (std::vector<std::string>{"double", "triple", "sum"}));
    EXPECT_EQ(report.culled, (std::vector<std::string>{"unused"}));
    ASSERT_EQ(report.nodes.size(), 3u);
    EXPECT_EQ(report.find("double")->counters.at("elements"), 3u);
    EXPECT_EQ(captured.size(), 3u);
    EXPECT_TRUE(contains(captured.back(), "sum:total:float"));
    // Launches are attributed to their node and exported with it.
    const auto launches = ex.launches();
    ASSERT_EQ(launches.size(), 2u);
    for (const auto& l : launches) EXPECT_TRUE(l.scope == "double" || l.scope == "triple");
    const std::string trace = chrome_trace_json(report, launches);
    EXPECT_TRUE(contains(trace, "\"name\":\"sum\",\"cat\":\"node\""));
    EXPECT_TRUE(contains(trace, "\"name\":\"scale\",\"cat\":\"launch\""));
    const std::string dot = g.to_dot();
    EXPECT_TRUE(contains(dot, "factor = 2"));
    EXPECT_TRUE(contains(dot, "\"n:unused\" [shape=box, color=grey"));
    EXPECT_TRUE(contains(dot, "\"r:doubled\" -> \"n:sum\""));
  }
}

TEST(Graph, IndependentNodesRunConcurrently) {
  // Two nodes wait for each other: only concurrent execution can finish both.
  Executor ex(2);
  std::atomic<int> arrived{0};
  auto rendezvous = [&](NodeContext& c) {
    arrived.fetch_add(1);
    // Sleep rather than spin: the machine is shared and the other worker needs a core.
    for (int ms = 0; arrived.load() < 2 && ms < 30000; ++ms)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    c.output<int>(c.node_name()) = arrived.load();
  };
  Graph g;
  g.add("a", rendezvous).writes<int>("a");
  g.add("b", rendezvous).writes<int>("b");
  g.run(ex);
  EXPECT_EQ(g.get<int>("a"), 2);
  EXPECT_EQ(g.get<int>("b"), 2);
}

// A thread waiting for its launch's stolen chunks must not pick up another node meanwhile:
// that node would then run nested inside the first one's launch, and the first node's launch
// and wall time would last until the other node finished (fork_join.h isolates the wait).
// Many independent nodes with many small chunks on an oversubscribed executor give the
// scheduler every chance to nest them; each node notes whether its thread was already inside
// a node when it started.
TEST(Graph, NodesNeverRunInsideAnotherNodesLaunch) {
  Executor ex(8);
  static thread_local int nodes_on_this_thread = 0;
  std::atomic<int> nested{0};
  Graph g;
  constexpr int kNodes = 24;
  for (int i = 0; i < kNodes; ++i) {
    const std::string name = "node" + std::to_string(i);
    g.add(name, [&nested](NodeContext& c) {
       if (nodes_on_this_thread++ > 0) nested.fetch_add(1);
       std::atomic<std::uint64_t> sum{0};
       c.executor().parallel_for("work", 64, 1, [&](std::size_t b, std::size_t) {
         std::uint64_t x = b;
         for (int k = 0; k < 20000; ++k) x = x * 6364136223846793005ull + 1442695040888963407ull;
         sum.fetch_add(x, std::memory_order_relaxed);
       });
       c.output<std::uint64_t>(c.node_name()) = sum.load();
       --nodes_on_this_thread;
     }).writes<std::uint64_t>(name);
  }
  for (int round = 0; round < 5; ++round) g.run(ex);
  EXPECT_EQ(nested.load(), 0);
}

TEST(Graph, RejectsCycleNamingNodesAndResources) {
  Graph g;
  g.add("a", [](NodeContext&) {}).reads<int>("y").writes<int>("x");
  g.add("b", [](NodeContext&) {}).reads<int>("x").writes<int>("y");
  const auto msg = error_of([&] { g.compile(); });
  EXPECT_TRUE(contains(msg, "cycle")) << msg;
  EXPECT_TRUE(contains(msg, "'a' -(x)-> 'b'")) << msg;
  EXPECT_TRUE(contains(msg, "'b' -(y)-> 'a'")) << msg;
  Graph self;
  self.add("loop", [](NodeContext&) {}).reads<int>("r", "r_in").writes<int>("r");
  EXPECT_TRUE(contains(error_of([&] { self.compile(); }), "'loop' -(r)-> 'loop'"));
}

TEST(Graph, RejectsMissingProducer) {
  Graph g;
  g.add<ScaleNode>("scale", 1.f);
  const auto msg = error_of([&] { g.compile(); });
  EXPECT_TRUE(contains(msg, "node 'scale' reads resource 'in'")) << msg;
  EXPECT_TRUE(contains(msg, "nothing produces it")) << msg;
  Graph r;
  r.request("ghost");
  EXPECT_TRUE(contains(error_of([&] { r.compile(); }), "'ghost' has no producer"));
}

TEST(Graph, RejectsTypeMismatch) {
  Graph g;
  g.input("in", 3);  // an int where ScaleNode wants std::vector<float>
  g.add<ScaleNode>("scale", 1.f);
  const auto msg = error_of([&] { g.compile(); });
  EXPECT_TRUE(contains(msg, "node 'scale' reads resource 'in' as std::vector<float>")) << msg;
  EXPECT_TRUE(contains(msg, "the graph input provides int")) << msg;
  // Accessing a port with the wrong type inside a node is also named.
  Graph h;
  h.add("w", [](NodeContext& c) { c.output<double>("v") = 1; }).writes<float>("v");
  Executor ex(1);
  const auto access = error_of([&] { h.run(ex); });
  EXPECT_TRUE(contains(access, "node 'w': port 'v' is declared as float but accessed as double")) << access;
}

// Node → node: "x" produced as one type and read as another is rejected at compile (and by
// run() before any node executes); the message names the consumer, the resource, the
// producer and both types — whichever node was added first, and for a cross-frame read too.
TEST(Graph, RejectsTypeMismatchBetweenNodes) {
  bool ran = false;
  auto make = [&](NodeContext& c) { ran = true; c.output<std::vector<float>>("x") = {1.f}; };
  auto use = [&](NodeContext& c) { ran = true; c.output<int>("y") = int(c.input<double>("x")); };
  for (bool producer_first : {true, false}) {
    Graph g;
    if (producer_first) g.add("make", make).writes<std::vector<float>>("x");
    g.add("use", use).reads<double>("x").writes<int>("y");
    if (!producer_first) g.add("make", make).writes<std::vector<float>>("x");
    const auto msg = error_of([&] { g.compile(); });
    EXPECT_TRUE(contains(msg, "node 'use' reads resource 'x' as double")) << msg;
    EXPECT_TRUE(contains(msg, "node 'make' provides std::vector<float>")) << msg;
    Executor ex(2);
    EXPECT_EQ(error_of([&] { g.run(ex); }), msg);
    EXPECT_FALSE(ran);
  }
  Graph prev;
  prev.add("make", make).writes<std::vector<float>>("x");
  prev.add("late", [](NodeContext&) {}).reads_previous<float>("x").writes<int>("z");
  const auto msg = error_of([&] { prev.compile(); });
  EXPECT_TRUE(contains(msg, "node 'late' reads resource 'x' as float")) << msg;
  EXPECT_TRUE(contains(msg, "node 'make' provides std::vector<float>")) << msg;
}

std::size_t occurrences(const std::string& s, const std::string& part) {
  std::size_t count = 0;
  for (std::size_t at = s.find(part); at != std::string::npos; at = s.find(part, at + 1)) ++count;
  return count;
}

// Per-node wall time is recorded (a node that sleeps 2 ms reports at least 2 ms, and a
// node starts only after the nodes it reads have ended), and the Chrome trace holds exactly
// one complete event per executed node and one per named kernel launch (culled nodes and
// their launches absent; a launch outside the graph included), for 1, 2 and 8 threads.
TEST(Graph, RecordsNodeTimesAndTraceHasOneEventPerNodeAndLaunch) {
  constexpr std::int64_t kSleepNs = 2'000'000;
  auto launch = [](NodeContext& c, const char* name, std::size_t n) {
    c.executor().parallel_for(name, n, 16, [&](std::size_t b, std::size_t e) { c.count("elements", e - b); });
  };
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    ex.clear_launches();
    ex.parallel_for("outside/k", 40, 16, [](std::size_t, std::size_t) {});
    Graph g;
    g.add("sleep", [&](NodeContext& c) {
       std::this_thread::sleep_for(std::chrono::nanoseconds(kSleepNs));
       launch(c, "sleep/k", 100);
       c.output<int>("a") = 1;
     }).writes<int>("a");
    g.add("work", [&](NodeContext& c) {
       launch(c, "work/k0", 1000);
       launch(c, "work/k1", 0);  // an empty launch is still a named launch
       c.output<int>("w") = c.input<int>("a") + 1;
     }).reads<int>("a").writes<int>("w");
    g.add("side", [&](NodeContext& c) {
       for (const char* k : {"side/k0", "side/k1", "side/k2"}) launch(c, k, 33);
       c.output<int>("b") = 10;
     }).writes<int>("b");
    g.add("join", [](NodeContext& c) { c.output<int>("out") = c.input<int>("w") + c.input<int>("b"); })
        .reads<int>("w").reads<int>("b").writes<int>("out");
    g.add("culled", [&](NodeContext& c) {
       launch(c, "culled/k", 10);
       c.output<int>("unused") = 0;
     }).writes<int>("unused");
    g.request("out");
    const RunReport report = g.run(ex);
    ASSERT_EQ(g.get<int>("out"), 12);
    ASSERT_EQ(report.nodes.size(), 4u) << threads;
    const NodeRecord* sleep = report.find("sleep");
    const NodeRecord* work = report.find("work");
    const NodeRecord* side = report.find("side");
    const NodeRecord* join = report.find("join");
    ASSERT_TRUE(sleep && work && side && join);
    EXPECT_EQ(report.find("culled"), nullptr);
    EXPECT_GE(sleep->duration_ns, kSleepNs) << threads;
    for (const auto& n : report.nodes) {
      EXPECT_GE(n.duration_ns, 0) << n.name;
      EXPECT_GE(n.start_ns, report.start_ns) << n.name;
      EXPECT_LE(n.start_ns + n.duration_ns, report.start_ns + report.duration_ns) << n.name;
    }
    EXPECT_GE(work->start_ns, sleep->start_ns + sleep->duration_ns) << threads;
    EXPECT_GE(join->start_ns, work->start_ns + work->duration_ns) << threads;
    EXPECT_GE(join->start_ns, side->start_ns + side->duration_ns) << threads;
    EXPECT_GE(report.duration_ns, sleep->duration_ns);
    EXPECT_EQ(work->counters.at("elements"), 1000u);
    EXPECT_EQ(side->counters.at("elements"), 99u);

    const auto launches = ex.launches();
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"outside/k", ""},     {"sleep/k", "sleep"},  {"work/k0", "work"}, {"work/k1", "work"},
        {"side/k0", "side"}, {"side/k1", "side"}, {"side/k2", "side"}};
    ASSERT_EQ(launches.size(), expected.size()) << threads;
    for (const auto& [name, scope] : expected) {
      std::size_t found = 0;
      for (const auto& l : launches)
        if (l.name == name) {
          ++found;
          EXPECT_EQ(l.scope, scope) << name;
        }
      EXPECT_EQ(found, 1u) << name;
    }
    const std::string trace = chrome_trace_json(report, launches);
    EXPECT_EQ(occurrences(trace, "\"ph\":\"X\""), report.nodes.size() + launches.size()) << trace;
    EXPECT_EQ(occurrences(trace, "\"cat\":\"node\""), report.nodes.size()) << trace;
    EXPECT_EQ(occurrences(trace, "\"cat\":\"launch\""), launches.size()) << trace;
    for (const char* node : {"sleep", "work", "side", "join"})
      EXPECT_EQ(occurrences(trace, std::string("{\"name\":\"") + node + "\",\"cat\":\"node\""), 1u) << node;
    for (const auto& [name, scope] : expected)
      EXPECT_EQ(occurrences(trace, "{\"name\":\"" + name + "\",\"cat\":\"launch\""), 1u) << name;
    EXPECT_FALSE(contains(trace, "culled")) << trace;
    // The sleeping node's event lasts at least its 2 ms (durations are in µs).
    const std::string sleep_event = "{\"name\":\"sleep\",\"cat\":\"node\"";
    const std::size_t at = trace.find("\"dur\":", trace.find(sleep_event));
    ASSERT_NE(at, std::string::npos);
    EXPECT_GE(std::stod(trace.substr(at + 6)), 2000.0) << trace;
  }
}

TEST(Graph, RejectsTwoProducersAndBadNames) {
  Graph g;
  g.add("a", [](NodeContext&) {}).writes<int>("r");
  g.add("b", [](NodeContext&) {}).writes<int>("r");
  EXPECT_TRUE(contains(error_of([&] { g.compile(); }), "resource 'r' has two producers: node 'a' and node 'b'"));
  EXPECT_TRUE(contains(error_of([&] { g.add("a", [](NodeContext&) {}); }), "two graph nodes are named 'a'"));
  EXPECT_TRUE(contains(error_of([&] { g.add<ScaleNode>("s", 1.f).bind("nope", "x"); }), "node 's' has no port 'nope'"));
  Graph lazy;
  lazy.add("lazy", [](NodeContext&) {}).writes<int>("r");
  Executor ex(1);
  EXPECT_TRUE(contains(error_of([&] { lazy.run(ex); }), "node 'lazy' did not write its output 'r'"));
}

TEST(Graph, PreviousFrameEdge) {
  Executor ex(2);
  auto accumulate = [](NodeContext& c) {
    const int prev = c.has_input<int>("acc@previous") ? c.input<int>("acc@previous") : 100;
    c.output<int>("acc") = prev + 1;
  };
  Graph g;
  g.add("accumulate", accumulate).reads_previous<int>("acc").writes<int>("acc");
  g.add("report", [](NodeContext& c) { c.output<int>("shown") = c.input<int>("acc@previous"); })
      .reads_previous<int>("acc").writes<int>("shown");
  g.seed_previous("acc", 10);
  g.run(ex);
  EXPECT_EQ(g.get<int>("acc"), 11);
  EXPECT_EQ(g.get<int>("shown"), 10);
  g.run(ex);
  EXPECT_EQ(g.get<int>("acc"), 12);
  EXPECT_EQ(g.get<int>("shown"), 11);
  EXPECT_TRUE(contains(g.to_dot(), "style=dashed, label=\"previous frame\""));
  Graph unseeded;
  unseeded.add("accumulate", accumulate).reads_previous<int>("acc").writes<int>("acc");
  unseeded.run(ex);
  EXPECT_EQ(unseeded.get<int>("acc"), 101);
}

}  // namespace
}  // namespace speculum::par
