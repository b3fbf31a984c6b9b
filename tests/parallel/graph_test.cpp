// Job graph: validation errors name node and resource; culling, order, concurrency,
// counters, capture, cross-frame edges, DOT and trace export.
#include "parallel/graph.h"

#include <gtest/gtest.h>

#include <atomic>
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
