// Job graph: typed handles checked when the recipe compiles; culling, order, concurrency,
// counters, capture, cross-frame edges, a failing pass, DOT and trace export.
#include "parallel/graph.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace speculum::par {
namespace {

using Floats = std::vector<float>;

// A pass: out = in * factor, counting the elements.
struct Scale {
  static constexpr const char* description = "multiplies by a factor";
  float factor = 1;
  void parameters(Params& p) const { p.set("factor", factor); }
  Floats operator()(NodeContext& c, const Floats& in) const {
    Floats out(in.size());
    c.executor().parallel_for("scale", in.size(), 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) out[i] = in[i] * factor;
      c.count("elements", double(e - b));
    });
    return out;
  }
};

// What g.add accepts is decided when the recipe compiles: a handle of the wrong type, a
// missing or extra input, or a string instead of a handle make the call ill-formed.
auto sum_pass = [](NodeContext&, const Floats& a, const Floats& b) { return a[0] + b[0]; };
auto maybe_pass = [](NodeContext&, const int* previous) { return previous ? *previous : 0; };
static_assert(PassBinds<Scale, Resource<Floats>>);
static_assert(PassBinds<Scale, PassBuilder<Floats>>);
static_assert(!PassBinds<Scale, Resource<int>>);
static_assert(!PassBinds<Scale, Resource<double>>);
static_assert(!PassBinds<Scale>);
static_assert(!PassBinds<Scale, Resource<Floats>, Resource<Floats>>);
static_assert(!PassBinds<Scale, std::string>);
static_assert(!PassBinds<Scale, const char*>);
static_assert(PassBinds<decltype(sum_pass), Resource<Floats>, Resource<Floats>>);
static_assert(!PassBinds<decltype(sum_pass), Resource<Floats>, Resource<float>>);
// Cross-frame reads only bind optional (pointer) inputs of the same type; own_previous only
// the pass's own output type.
static_assert(PassBinds<decltype(maybe_pass), PreviousFrame<int>>);
static_assert(PassBinds<decltype(maybe_pass), OwnPrevious>);
static_assert(PassBinds<decltype(maybe_pass), Resource<int>>);
static_assert(!PassBinds<Scale, PreviousFrame<Floats>>);
static_assert(!PassBinds<decltype(maybe_pass), PreviousFrame<float>>);
static_assert(!PassBinds<decltype(sum_pass), OwnPrevious, OwnPrevious>);

template <class E = GraphError, class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
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
    auto src = g.input("src", Floats{1, 2, 3});
    auto doubled = g.add("double", Scale{2.f}, src);
    auto tripled = g.add("triple", Scale{3.f}, src);
    auto total = g.add("sum", [](NodeContext&, const Floats& a, const Floats& b) {
      float s = 0;
      for (std::size_t i = 0; i < a.size(); ++i) s += a[i] + b[i];
      return s;
    }, doubled, tripled);
    g.add("unused", Scale{5.f}, src);
    g.request(total);
    std::vector<std::string> captured;
    const auto report = g.run(ex, [&](const CapturedOutput& o) {
      captured.push_back(o.node + ":" + o.resource + ":" + o.type_name);
      if (o.resource == "sum") {
        EXPECT_EQ(*o.as<float>(), 30.f);
      }
      EXPECT_EQ(o.as<int>(), nullptr);
    });
    EXPECT_EQ(g.get(total), 30.f);
    EXPECT_EQ(g.get(doubled), (Floats{2, 4, 6}));
    EXPECT_EQ(g.order(), (std::vector<std::string>{"double", "triple", "sum"}));
    EXPECT_EQ(report.culled, (std::vector<std::string>{"unused"}));
    ASSERT_EQ(report.nodes.size(), 3u);
    EXPECT_EQ(report.find("double")->counters.at("elements"), 3.0);
    EXPECT_EQ(captured.size(), 3u);
    EXPECT_TRUE(contains(captured.back(), "sum:sum:float"));
    EXPECT_EQ(g.nodes()[1].description, "multiplies by a factor");
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
    EXPECT_TRUE(contains(dot, "\"r:double\" -> \"n:sum\""));
  }
}

// Counters are real numbers; integral deltas from many chunks sum exactly, the same for
// any thread count.
TEST(Graph, CountersAreRealNumbers) {
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    Graph g;
    auto out = g.add("ratio", [](NodeContext& c) {
      c.executor().parallel_for("count", 1000, 7, [&](std::size_t b, std::size_t e) { c.count("items", double(e - b)); });
      c.count("per_item", 0.25);
      c.count("per_item", 0.5);
      return 1;
    });
    g.request(out);
    const RunReport report = g.run(ex);
    EXPECT_EQ(report.nodes[0].counters.at("items"), 1000.0) << threads;
    EXPECT_EQ(report.nodes[0].counters.at("per_item"), 0.75) << threads;
  }
}

// A pass that throws stops the graph: run() throws NodeError naming the pass with its
// message and carrying the original exception; passes that need its output never start,
// and the graph can run again.
TEST(Graph, FailingPassStopsTheGraphAndIsNamed) {
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    std::atomic<int> downstream_runs{0};
    std::atomic<bool> fail{true};
    Graph g;
    auto a = g.add("source", [](NodeContext&) { return 1; });
    auto bad = g.add("broken", [&](NodeContext&, const int& x) {
      if (fail) throw std::invalid_argument("scene.glb: triangle 7 has a NaN vertex");
      return x + 1;
    }, a);
    auto side = g.add("independent", [](NodeContext& c) {
      c.executor().parallel_for("spin", 64, 1, [](std::size_t, std::size_t) {});
      return 2;
    });
    auto after = g.add("after", [&](NodeContext&, const int& x, const int& y) {
      downstream_runs.fetch_add(1);
      return x + y;
    }, bad, side);
    g.request(after);
    try {
      g.run(ex);
      ADD_FAILURE() << "no error with " << threads << " threads";
    } catch (const NodeError& e) {
      EXPECT_EQ(e.node(), "broken");
      EXPECT_EQ(std::string(e.what()), "node 'broken': scene.glb: triangle 7 has a NaN vertex");
      EXPECT_EQ(error_of<std::invalid_argument>([&] { std::rethrow_exception(e.cause()); }),
                "scene.glb: triangle 7 has a NaN vertex");
    }
    EXPECT_EQ(downstream_runs.load(), 0) << threads;
    EXPECT_FALSE(g.has(after));
    fail = false;
    g.run(ex);
    EXPECT_EQ(g.get(after), 4) << threads;
    EXPECT_EQ(downstream_runs.load(), 1) << threads;
  }
}

TEST(Graph, IndependentNodesRunConcurrently) {
  // Two nodes wait for each other: only concurrent execution can finish both.
  Executor ex(2);
  std::atomic<int> arrived{0};
  auto rendezvous = [&](NodeContext&) {
    arrived.fetch_add(1);
    // Sleep rather than spin: the machine is shared and the other worker needs a core.
    for (int ms = 0; arrived.load() < 2 && ms < 30000; ++ms)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return arrived.load();
  };
  Graph g;
  auto a = g.add("a", rendezvous);
  auto b = g.add("b", rendezvous);
  g.run(ex);
  EXPECT_EQ(g.get(a), 2);
  EXPECT_EQ(g.get(b), 2);
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
    g.add("node" + std::to_string(i), [&nested](NodeContext& c) {
      if (nodes_on_this_thread++ > 0) nested.fetch_add(1);
      std::atomic<std::uint64_t> sum{0};
      c.executor().parallel_for("work", 64, 1, [&](std::size_t b, std::size_t) {
        std::uint64_t x = b;
        for (int k = 0; k < 20000; ++k) x = x * 6364136223846793005ull + 1442695040888963407ull;
        sum.fetch_add(x, std::memory_order_relaxed);
      });
      --nodes_on_this_thread;
      return sum.load();
    });
  }
  for (int round = 0; round < 5; ++round) g.run(ex);
  EXPECT_EQ(nested.load(), 0);
}

TEST(Graph, RejectsMissingRequestAndEmptyRequiredInput) {
  Graph r;
  Resource<int> never;  // an empty handle
  r.request(never);
  EXPECT_TRUE(contains(error_of([&] { r.compile(); }), "'' has no producer"));
  Graph g;
  Resource<Floats> empty;
  EXPECT_TRUE(contains(error_of([&] { g.add("scale", Scale{}, empty); }),
                       "node 'scale': required input of type std::vector<float> bound to an empty handle"));
  // An optional input bound to an empty handle is nullptr.
  Executor ex(1);
  auto v = g.add("maybe", maybe_pass, Resource<int>{});
  g.run(ex);
  EXPECT_EQ(g.get(v), 0);
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
    c.executor().parallel_for(name, n, 16, [&](std::size_t b, std::size_t e) { c.count("elements", double(e - b)); });
  };
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    ex.clear_launches();
    ex.parallel_for("outside/k", 40, 16, [](std::size_t, std::size_t) {});
    Graph g;
    auto a = g.add("sleep", [&](NodeContext& c) {
      std::this_thread::sleep_for(std::chrono::nanoseconds(kSleepNs));
      launch(c, "sleep/k", 100);
      return 1;
    });
    auto w = g.add("work", [&](NodeContext& c, const int& x) {
      launch(c, "work/k0", 1000);
      launch(c, "work/k1", 0);  // an empty launch is still a named launch
      return x + 1;
    }, a);
    auto b = g.add("side", [&](NodeContext& c) {
      for (const char* k : {"side/k0", "side/k1", "side/k2"}) launch(c, k, 33);
      return 10;
    });
    auto out = g.add("join", [](NodeContext&, const int& x, const int& y) { return x + y; }, w, b);
    g.add("culled", [&](NodeContext& c) {
      launch(c, "culled/k", 10);
      return 0;
    });
    g.request(out);
    const RunReport report = g.run(ex);
    ASSERT_EQ(g.get(out), 12);
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
    EXPECT_EQ(work->counters.at("elements"), 1000.0);
    EXPECT_EQ(side->counters.at("elements"), 99.0);

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

TEST(Graph, RejectsTwoNodesWithOneName) {
  Graph g;
  g.add("a", [](NodeContext&) { return 1; });
  EXPECT_TRUE(contains(error_of([&] { g.add("a", [](NodeContext&) { return 2; }); }), "two graph nodes are named 'a'"));
  EXPECT_TRUE(contains(error_of([&] { g.add("", [](NodeContext&) { return 2; }); }), "needs a name"));
  // An input and a pass cannot produce the same resource.
  g.input("b", 1);
  g.add("b", [](NodeContext&) { return 2; });
  EXPECT_TRUE(contains(error_of([&] { g.compile(); }), "resource 'b' has two producers: the graph input and node 'b'"));
}

TEST(Graph, PreviousFrameEdge) {
  Executor ex(2);
  auto accumulate = [](NodeContext&, const int* previous) { return (previous ? *previous : 100) + 1; };
  Graph g;
  auto acc = g.add("accumulate", accumulate, own_previous);
  auto shown = g.add("report", [](NodeContext&, const int* previous) { return previous ? *previous : -1; },
                     previous(acc));
  g.seed_previous(acc, 10);
  g.run(ex);
  EXPECT_EQ(g.get(acc), 11);
  EXPECT_EQ(g.get(shown), 10);
  g.run(ex);
  EXPECT_EQ(g.get(acc), 12);
  EXPECT_EQ(g.get(shown), 11);
  EXPECT_TRUE(contains(g.to_dot(), "style=dashed, label=\"previous frame\""));
  Graph unseeded;
  auto u = unseeded.add("accumulate", accumulate, own_previous);
  unseeded.run(ex);
  EXPECT_EQ(unseeded.get(u), 101);
  unseeded.run(ex);
  EXPECT_EQ(unseeded.get(u), 102);
  // OwnPrevious{false}: the edge is off and the input is always nullptr.
  Graph off;
  auto o = off.add("accumulate", accumulate, OwnPrevious{false});
  off.run(ex);
  off.run(ex);
  EXPECT_EQ(off.get(o), 101);
}

}  // namespace
}  // namespace speculum::par
