// The job graph: nodes with typed, named resources; validate → cull → topological order →
// run (independent nodes concurrently) with per-node timings, counters and output capture.
// DESIGN.md "The job graph"; compile steps after Falcor's RenderGraphCompiler (STYLE.md).
//
// A recipe reads like a list of passes:
//   par::Graph g;
//   g.input<Scene>("scene", scene);                              // provided by the caller
//   g.add<VisibilityNode>("visibility", vis_params);             // ports declared by the node
//   g.add("shade", [](par::NodeContext& c) {                      // or a function node
//      const auto& vis = c.input<VisBuffer>("vis");
//      c.output<Image>("color") = shade(c.executor(), vis);
//    }).reads<VisBuffer>("vis").writes<Image>("color").param("spp", 4);
//   g.request("color");                                          // cull what "color" doesn't need
//   par::RunReport report = g.run(executor);
//   const Image& color = g.get<Image>("color");
// Port names are resource names unless rebound: `.bind("color", "color_pass2")`.
// Cross-frame edges: `.reads_previous<T>("cube")` gives the node a port "cube@previous" with
// the value "cube" had when the last run() ended (std::shared_ptr handoff, no copy); on the
// first run it is absent unless `seed_previous` set one — nodes test `has_input`. Such an
// edge does not order nodes within a frame (a node may read its own previous output).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <typeindex>
#include <utility>
#include <vector>

#include "parallel/executor.h"
#include "parallel/graph_node.h"

namespace speculum::par {

// Per-node record of one run.
struct NodeRecord {
  std::string name;
  std::int64_t start_ns = 0;  // executor epoch, like LaunchRecord
  std::int64_t duration_ns = 0;
  std::map<std::string, std::uint64_t> counters;
};

struct RunReport {
  std::vector<NodeRecord> nodes;  // in topological order
  std::vector<std::string> culled;
  std::int64_t start_ns = 0;
  std::int64_t duration_ns = 0;
  const NodeRecord* find(std::string_view node) const;
};

// One output as it was produced (the `inspect` hook). Called once per output of every run
// node, serialized by the graph (the hook need not be thread-safe).
struct CapturedOutput {
  std::string node, port, resource, type_name;
  std::type_index type = typeid(void);
  const void* value = nullptr;
  template <class T>
  const T* as() const { return type == typeid(T) ? static_cast<const T*>(value) : nullptr; }
};
using CaptureHook = std::function<void(const CapturedOutput&)>;

class Graph;

// Returned by Graph::add: the recipe's handle to declare or rebind ports and parameters.
class NodeBuilder {
 public:
  NodeBuilder(Graph& graph, std::size_t index) : graph_(&graph), index_(index) {}
  // The port name is the resource name unless given.
  template <class T> NodeBuilder& reads(std::string resource, std::string port = {}) {
    return add_port<T>(std::move(resource), std::move(port), false, false);
  }
  template <class T> NodeBuilder& writes(std::string resource, std::string port = {}) {
    return add_port<T>(std::move(resource), std::move(port), true, false);
  }
  // Cross-frame read; the port defaults to "<resource>@previous".
  template <class T> NodeBuilder& reads_previous(std::string resource, std::string port = {}) {
    if (port.empty()) port = resource + "@previous";
    return add_port<T>(std::move(resource), std::move(port), false, true);
  }
  // Connects a declared port to a differently named resource.
  NodeBuilder& bind(std::string_view port, std::string resource);
  template <class V> NodeBuilder& param(std::string key, const V& value);
  // What the pass does, in one or two sentences with its document section (shown by
  // `inspect`), e.g. "Screen-space quad-tree of cone-spheres over the secondary rays
  // (ROGER §3.2)."
  NodeBuilder& describe(std::string text);

 private:
  template <class T>
  NodeBuilder& add_port(std::string resource, std::string port, bool output, bool previous);
  Graph* graph_;
  std::size_t index_;
};

class Graph {
 public:
  // Adds a node constructed from args; its declare() supplies the ports.
  template <class N, class... Args>
  NodeBuilder add(std::string name, Args&&... args) {
    return add_node(std::move(name), std::make_unique<N>(std::forward<Args>(args)...));
  }
  // Adds a function node; declare its ports with reads/writes.
  NodeBuilder add(std::string name, std::function<void(NodeContext&)> fn) {
    return add_node(std::move(name), std::make_unique<LambdaNode>(std::move(fn)));
  }
  NodeBuilder add_node(std::string name, std::unique_ptr<Node> node);

  // A resource supplied by the caller (it counts as that resource's producer).
  template <class T>
  void input(std::string resource, T value) {
    set_input(std::move(resource), make_value<T>(std::move(value)));
  }
  // The value a reads_previous edge sees on the first run.
  template <class T>
  void seed_previous(std::string resource, T value) {
    previous_[std::move(resource)] = make_value<T>(std::move(value));
  }
  // Outputs the caller wants; nodes that reach none of them are culled. With no request,
  // every node runs.
  void request(std::string resource);

  // Validates and orders (run() does it too). Throws GraphError naming node and resource.
  void compile();
  RunReport run(Executor& executor, const CaptureHook& capture = {});

  template <class T>
  const T& get(std::string_view resource) const {
    const ResourceValue& v = value(resource);
    if (v.type != typeid(T))
      throw GraphError("resource '" + std::string(resource) + "' is " + v.type_name +
                       ", requested as " + type_name<T>());
    return *static_cast<const T*>(v.value.get());
  }
  bool has(std::string_view resource) const;

  // Introspection (after compile): execution order and the culled nodes.
  std::vector<std::string> order() const;
  std::vector<std::string> culled() const;
  // Graphviz: nodes as boxes with parameters, resources as ellipses with their types,
  // dashed edges for cross-frame reads, culled nodes grey.
  std::string to_dot() const;

  struct NodeEntry {
    std::string name;
    std::unique_ptr<Node> node;
    std::vector<PortDecl> ports;
    Params params;
    std::string description;
  };
  const std::vector<NodeEntry>& nodes() const { return nodes_; }

 private:
  friend class NodeBuilder;
  template <class T>
  static ResourceValue make_value(T value) {
    return {std::make_shared<T>(std::move(value)), typeid(T), type_name<T>()};
  }
  void set_input(std::string resource, ResourceValue value);
  const ResourceValue& value(std::string_view resource) const;
  void run_node(std::size_t index, Executor& executor, const CaptureHook& capture,
                NodeRecord& record);

  std::vector<NodeEntry> nodes_;
  std::map<std::string, ResourceValue, std::less<>> inputs_;     // caller-provided
  std::map<std::string, ResourceValue, std::less<>> values_;     // produced this run
  std::map<std::string, ResourceValue, std::less<>> previous_;   // end of the last run
  std::vector<std::string> requests_;
  bool compiled_ = false;
  std::vector<std::size_t> order_;              // active nodes, topological
  std::vector<bool> active_;
  std::vector<std::vector<std::size_t>> successors_;
  std::vector<std::size_t> predecessor_count_;  // within the active set
  std::mutex values_mutex_;
};

template <class T>
NodeBuilder& NodeBuilder::add_port(std::string resource, std::string port_name, bool output,
                                   bool previous) {
  auto& entry = graph_->nodes_[index_];
  if (port_name.empty()) port_name = resource;
  entry.ports.push_back({std::move(port_name), std::move(resource), typeid(T), type_name<T>(),
                         output, previous});
  graph_->compiled_ = false;
  return *this;
}

inline NodeBuilder& NodeBuilder::describe(std::string text) {
  graph_->nodes_[index_].description = std::move(text);
  return *this;
}

template <class V>
NodeBuilder& NodeBuilder::param(std::string key, const V& value) {
  graph_->nodes_[index_].params.set(std::move(key), value);
  return *this;
}

// Chrome trace-event JSON (Perfetto, chrome://tracing): one complete event per node and per
// named kernel launch; a launch sits on its node's track (launches carry LaunchRecord::scope).
std::string chrome_trace_json(const RunReport& report, const std::vector<LaunchRecord>& launches);

}  // namespace speculum::par
