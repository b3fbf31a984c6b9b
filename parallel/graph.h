// The job graph: passes joined by typed resource handles; validate → cull → topological
// order → run (independent passes concurrently) with per-pass timings, counters and output
// capture (docs/architecture.md, "The job graph").
//
// A recipe reads as a list of passes. A pass is a callable object living beside its kernel
// (raster/, trace/): its settings are members, its operator() takes the NodeContext and its
// inputs and returns its one output:
//   struct Shade {
//     static constexpr const char* description = "...";          // shown by `inspect`
//     int spp = 4;
//     void parameters(par::Params& p) const { p.set("spp", spp); } // optional
//     Image operator()(par::NodeContext& c, const VisBuffer& vis) const;
//   };
//   par::Graph g;
//   par::Resource<VisBuffer> vis = g.input("vis", make_vis());     // a caller-provided value
//   par::Resource<Image> color = g.add("shade", Shade{8}, vis);    // checked at compile time
//   g.request(color);                                              // cull what color doesn't need
//   par::RunReport report = g.run(executor);
//   const Image& image = g.get(color);
// g.add checks, when the recipe compiles, that every handle's type is the type of the pass
// parameter it binds, and returns the handle of the pass's output (a resource named after
// the node). A `const T*` parameter is an optional input: an empty handle binds nullptr.
// Cross-frame edges: `par::previous(handle)` binds the value the resource had when the last
// run() ended and `par::own_previous` the pass's own output of the last run (shared, not
// copied; nullptr on the first run unless seed_previous set one). Such an edge does not
// order passes within a frame.
// A pass that throws stops the run: passes already running finish, no new one starts, and
// run() throws NodeError naming the pass and carrying the original exception.
#pragma once

#include <cstdint>
#include <exception>
#include <stdexcept>
#include <tuple>
#include <type_traits>
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
  std::map<std::string, double> counters;
};

struct RunReport {
  std::vector<NodeRecord> nodes;  // in topological order
  std::vector<std::string> culled;
  std::int64_t start_ns = 0;
  std::int64_t duration_ns = 0;
  const NodeRecord* find(std::string_view node) const;
};

// One output as it was produced (the `inspect` hook). Called once per output of every run
// node, then once per value the node published (NodeContext::publish; resource empty),
// serialized by the graph (the hook need not be thread-safe).
struct CapturedOutput {
  std::string node, port, resource, type_name;
  std::type_index type = typeid(void);
  const void* value = nullptr;
  template <class T>
  const T* as() const { return type == typeid(T) ? static_cast<const T*>(value) : nullptr; }
};
using CaptureHook = std::function<void(const CapturedOutput&)>;

// Thrown by Graph::run when a pass throws: what() is "node 'name': <the pass's message>",
// cause() the original exception (rethrow it to tell bad input from a failure).
class NodeError : public std::runtime_error {
 public:
  NodeError(std::string node, std::exception_ptr cause, const std::string& message)
      : std::runtime_error("node '" + node + "': " + message), node_(std::move(node)),
        cause_(std::move(cause)) {}
  const std::string& node() const { return node_; }
  const std::exception_ptr& cause() const { return cause_; }

 private:
  std::string node_;
  std::exception_ptr cause_;
};

class Graph;

// A typed handle to a graph resource. Only the graph makes non-empty ones (Graph::input,
// Graph::add), so a handle always names a resource of type T.
template <class T>
class Resource {
 public:
  using value_type = T;
  Resource() = default;
  const std::string& name() const { return name_; }
  explicit operator bool() const { return !name_.empty(); }

 private:
  friend class Graph;
  explicit Resource(std::string name) : name_(std::move(name)) {}
  std::string name_;
};

// Binds an optional (`const T*`) pass input to the value `resource` had at the end of the
// last run.
template <class T>
struct PreviousFrame {
  Resource<T> resource;
};
template <class T>
PreviousFrame<T> previous(const Resource<T>& resource) { return {resource}; }

// Binds an optional (`const Out*`) pass input to the pass's own output of the last run;
// `OwnPrevious{false}` binds nullptr (the recipe's switch for a lagged variant).
struct OwnPrevious {
  bool enabled = true;
};
inline constexpr OwnPrevious own_previous{};

namespace detail {

// A pass's signature: Out operator()(NodeContext&, Inputs...) [const].
template <class>
struct PassCall;
template <class C, class R, class... A>
struct PassCall<R (C::*)(NodeContext&, A...) const> {
  using Out = R;
  using Inputs = std::tuple<A...>;
};
template <class C, class R, class... A>
struct PassCall<R (C::*)(NodeContext&, A...)> : PassCall<R (C::*)(NodeContext&, A...) const> {};
template <class P>
using PassOut = typename PassCall<decltype(&P::operator())>::Out;
template <class P>
using PassInputs = typename PassCall<decltype(&P::operator())>::Inputs;

// The resource type a pass parameter reads (`const T&` required, `const T*` optional).
template <class A>
struct InputParam {
  static constexpr bool valid = false;
};
template <class T>
struct InputParam<const T&> {
  static constexpr bool valid = true, optional = false;
  using type = T;
};
template <class T>
struct InputParam<const T*> {
  static constexpr bool valid = true, optional = true;
  using type = T;
};

template <class T>
T resource_type_of(const Resource<T>*);
template <class B>
concept IsResource = requires(const B* b) { resource_type_of(b); };

// Whether binding B may feed parameter A of a pass whose output is Out.
template <class A, class B, class Out>
constexpr bool binds() {
  using P = InputParam<A>;
  if constexpr (!P::valid) {
    return false;
  } else if constexpr (IsResource<B>) {
    return std::is_same_v<decltype(resource_type_of(std::declval<const B*>())), typename P::type>;
  } else if constexpr (std::is_same_v<B, PreviousFrame<typename P::type>>) {
    return P::optional;
  } else if constexpr (std::is_same_v<B, OwnPrevious>) {
    return P::optional && std::is_same_v<typename P::type, Out>;
  } else {
    return false;
  }
}

template <class Pass, class Inputs, class... Bindings>
struct BindsAll : std::false_type {};
template <class Pass, class... A, class... Bindings>
  requires(sizeof...(A) == sizeof...(Bindings))
struct BindsAll<Pass, std::tuple<A...>, Bindings...>
    : std::bool_constant<(binds<A, Bindings, PassOut<Pass>>() && ...)> {};

}  // namespace detail

// A pass whose inputs the bindings feed, in order and with matching types. A wrong type, a
// wrong count or a binding that is not a handle makes Graph::add ill-formed.
template <class Pass, class... Bindings>
concept PassBinds = requires { &Pass::operator(); } &&
                    !std::is_void_v<detail::PassOut<Pass>> &&
                    detail::BindsAll<Pass, detail::PassInputs<Pass>, std::decay_t<Bindings>...>::value;

// Returned by Graph::add: the handle of the pass's output, and the recipe's way to add
// shown parameters or replace the pass's description.
template <class T>
class PassBuilder : public Resource<T> {
 public:
  PassBuilder& describe(std::string text);
  template <class V> PassBuilder& param(std::string key, const V& value);

 private:
  friend class Graph;
  PassBuilder(Resource<T> output, Graph& graph, std::size_t index)
      : Resource<T>(std::move(output)), graph_(&graph), index_(index) {}
  Graph* graph_;
  std::size_t index_;
};

class Graph {
 public:
  // Adds a pass; `inputs` bind its parameters after the NodeContext, in order.
  template <class Pass, class... Bindings>
    requires PassBinds<Pass, Bindings...>
  PassBuilder<detail::PassOut<Pass>> add(std::string name, Pass pass, const Bindings&... inputs);

  // A resource supplied by the caller (it counts as that resource's producer).
  template <class T>
  Resource<T> input(std::string resource, T value) {
    set_input(resource, make_value<T>(std::move(value)));
    return Resource<T>(std::move(resource));
  }
  // The value a previous-frame edge on `resource` sees on the first run.
  template <class T>
  void seed_previous(const Resource<T>& resource, T value) {
    previous_[resource.name()] = make_value<T>(std::move(value));
  }
  // Outputs the caller wants; nodes that reach none of them are culled. With no request,
  // every node runs.
  template <class T>
  void request(const Resource<T>& resource) { request_name(resource.name()); }

  // Validates and orders (run() does it too). Throws GraphError naming node and resource.
  void compile();
  RunReport run(Executor& executor, const CaptureHook& capture = {});

  template <class T>
  const T& get(const Resource<T>& resource) const {
    return *static_cast<const T*>(value(resource.name()).value.get());
  }
  template <class T>
  bool has(const Resource<T>& resource) const { return has_value(resource.name()); }

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
  template <class T> friend class PassBuilder;
  template <class T>
  static ResourceValue make_value(T value) {
    return {std::make_shared<T>(std::move(value)), typeid(T), type_name<T>()};
  }
  std::size_t add_node(std::string name, std::unique_ptr<Node> node, std::vector<PortDecl> ports);
  void set_input(std::string resource, ResourceValue value);
  void request_name(std::string resource);
  bool has_value(std::string_view resource) const;
  const ResourceValue& value(std::string_view resource) const;
  void run_node(std::size_t index, Executor& executor, const CaptureHook& capture,
                NodeRecord& record);
  // compile()'s steps.
  struct Producer {
    long node;  // -1: graph input
    std::type_index type;
    std::string type_name;
  };
  struct Edge {
    std::size_t from, to;
    std::string resource;
  };
  std::map<std::string, Producer, std::less<>> find_producers() const;
  std::vector<Edge> connect(const std::map<std::string, Producer, std::less<>>& producers,
                            std::vector<std::vector<std::size_t>>& inputs_of) const;
  std::vector<bool> reachable_from_requests(const std::map<std::string, Producer, std::less<>>& producers,
                                            const std::vector<std::vector<std::size_t>>& inputs_of) const;
  std::vector<std::size_t> topological_order(const std::vector<Edge>& edges) const;

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

namespace detail {

// The node that runs a pass: fetches each bound input by its port, calls the pass, stores
// its return value as the one output.
template <class Pass, class Out, class Inputs>
class PassNode;
template <class Pass, class Out, class... A>
class PassNode<Pass, Out, std::tuple<A...>> final : public Node {
 public:
  PassNode(Pass pass, std::vector<std::string> ports, std::string output)
      : pass_(std::move(pass)), ports_(std::move(ports)), output_(std::move(output)) {}
  void execute(NodeContext& c) override { run(c, std::index_sequence_for<A...>{}); }

 private:
  template <std::size_t... I>
  void run(NodeContext& c, std::index_sequence<I...>) {
    c.set_output<Out>(output_, pass_(c, fetch<A>(c, ports_[I])...));
  }
  template <class Param>
  static Param fetch(NodeContext& c, const std::string& port) {
    using T = typename InputParam<Param>::type;
    if constexpr (InputParam<Param>::optional)
      return !port.empty() && c.has_input<T>(port) ? &c.input<T>(port) : nullptr;
    else
      return c.input<T>(port);
  }
  Pass pass_;
  std::vector<std::string> ports_;  // per parameter; empty: an unbound optional input
  std::string output_;
};

// The port a binding declares for parameter A ("" when it binds nothing).
template <class A, class B>
std::string bind_port(const B& binding, const std::string& node, std::vector<PortDecl>& ports) {
  using T = typename InputParam<A>::type;
  std::string resource;
  bool previous = false;
  if constexpr (IsResource<B>) {
    resource = static_cast<const Resource<T>&>(binding).name();
    if (resource.empty()) {
      if constexpr (!InputParam<A>::optional)
        throw GraphError("node '" + node + "': required input of type " + type_name<T>() +
                         " bound to an empty handle");
      return {};
    }
  } else if constexpr (std::is_same_v<B, PreviousFrame<T>>) {
    if (!binding.resource) return {};
    resource = binding.resource.name();
    previous = true;
  } else {  // OwnPrevious
    if (!binding.enabled) return {};
    resource = node;
    previous = true;
  }
  std::string port = previous ? resource + "@previous" : resource;
  for (const PortDecl& d : ports)
    if (d.port == port) return port;  // the same resource twice: one port
  ports.push_back({port, resource, typeid(T), type_name<T>(), false, previous});
  return port;
}

template <class P>
concept HasDescription = requires { std::string(P::description); };
template <class P>
concept HasParameters = requires(const P& p, Params& params) { p.parameters(params); };

template <class Pass, class... A, class... Bindings>
std::vector<std::string> bind_ports(std::tuple<A...>*, const std::string& node,
                                    std::vector<PortDecl>& ports, const Bindings&... inputs) {
  return {bind_port<A>(inputs, node, ports)...};
}

}  // namespace detail

template <class Pass, class... Bindings>
  requires PassBinds<Pass, Bindings...>
PassBuilder<detail::PassOut<Pass>> Graph::add(std::string name, Pass pass,
                                               const Bindings&... inputs) {
  using Out = detail::PassOut<Pass>;
  using Inputs = detail::PassInputs<Pass>;
  std::vector<PortDecl> ports;
  std::vector<std::string> input_ports = detail::bind_ports<Pass>(
      static_cast<Inputs*>(nullptr), name, ports, inputs...);
  ports.push_back({name, name, typeid(Out), type_name<Out>(), true, false});
  Params params;
  if constexpr (detail::HasParameters<Pass>) pass.parameters(params);
  std::string description;
  if constexpr (detail::HasDescription<Pass>) description = Pass::description;
  auto node = std::make_unique<detail::PassNode<Pass, Out, Inputs>>(std::move(pass),
                                                                    std::move(input_ports), name);
  const std::size_t index = add_node(name, std::move(node), std::move(ports));
  nodes_[index].params = std::move(params);
  nodes_[index].description = std::move(description);
  return PassBuilder<Out>(Resource<Out>(std::move(name)), *this, index);
}

template <class T>
PassBuilder<T>& PassBuilder<T>::describe(std::string text) {
  graph_->nodes_[index_].description = std::move(text);
  return *this;
}

template <class T>
template <class V>
PassBuilder<T>& PassBuilder<T>::param(std::string key, const V& value) {
  graph_->nodes_[index_].params.set(std::move(key), value);
  return *this;
}

// Chrome trace-event JSON (Perfetto, chrome://tracing): one complete event per node and per
// named kernel launch; a launch sits on its node's track (launches carry LaunchRecord::scope).
std::string chrome_trace_json(const RunReport& report, const std::vector<LaunchRecord>& launches);

}  // namespace speculum::par
