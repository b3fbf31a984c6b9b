// A job-graph node: its ports, printable parameters, and the context a node runs with
// (executor, counters, timers, resource access by port). The typed recipe API that makes
// the ports is parallel/graph.h.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <typeindex>
#include <utility>
#include <vector>

#include "parallel/executor.h"
#include "parallel/type_name.h"

namespace speculum::par {

// A graph that cannot be built or run as declared; the message names node and resource.
class GraphError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// One port of a node: the resource it reads or writes (a previous-frame read's port is
// "<resource>@previous").
struct PortDecl {
  std::string port;
  std::string resource;
  std::type_index type = typeid(void);
  std::string type_name;
  bool output = false;
  bool previous_frame = false;  // reads the value `resource` had at the end of the last run
};

// Printable parameters, in declaration order (shown in DOT, manifests and `inspect`).
class Params {
 public:
  template <class V>
  Params& set(std::string key, const V& value) {
    std::ostringstream s;
    s << value;
    for (auto& [k, v] : items_)
      if (k == key) return v = s.str(), *this;
    items_.emplace_back(std::move(key), s.str());
    return *this;
  }
  const std::vector<std::pair<std::string, std::string>>& items() const { return items_; }

 private:
  std::vector<std::pair<std::string, std::string>> items_;
};

// A type-erased resource value held by the graph.
struct ResourceValue {
  std::shared_ptr<void> value;
  std::type_index type = typeid(void);
  std::string type_name;
};

class NodeContext;

// What the graph runs; Graph::add wraps a pass in one (graph.h).
class Node {
 public:
  virtual ~Node() = default;
  virtual void execute(NodeContext& ctx) = 0;
};

// What the graph hands a running node. Counters and timers may be used from inside the
// node's parallel_for bodies (they lock). Counters are real numbers; a sum of integral
// deltas is exact (below 2^53) and so independent of the order the bodies add them in.
class NodeContext {
 public:
  NodeContext(Executor& executor, std::string node, const std::vector<PortDecl>& ports,
              std::map<std::string, ResourceValue>& inputs,
              std::map<std::string, ResourceValue>& outputs, bool capturing = false)
      : executor_(executor), node_(std::move(node)), ports_(ports), inputs_(inputs), outputs_(outputs),
        capturing_(capturing) {}

  Executor& executor() { return executor_; }
  const std::string& node_name() const { return node_; }

  template <class T>
  bool has_input(std::string_view port) const {
    check<T>(port, false);
    auto it = inputs_.find(std::string(port));
    return it != inputs_.end() && it->second.value;
  }
  template <class T>
  const T& input(std::string_view port) const {
    const PortDecl& d = check<T>(port, false);
    auto it = inputs_.find(std::string(port));
    if (it == inputs_.end() || !it->second.value)
      throw GraphError("node '" + node_ + "': input '" + d.port + "' (resource '" + d.resource +
                       "') has no value" + (d.previous_frame ? " yet (first frame)" : ""));
    return *static_cast<const T*>(it->second.value.get());
  }
  // The output's value, default-constructed on first access.
  template <class T>
  T& output(std::string_view port) {
    const PortDecl& d = check<T>(port, true);
    auto& slot = outputs_[std::string(port)];
    if (!slot.value) slot = {std::make_shared<T>(), typeid(T), d.type_name};
    return *static_cast<T*>(slot.value.get());
  }
  template <class T>
  T& set_output(std::string_view port, T value) {
    return output<T>(port) = std::move(value);
  }

  void count(std::string_view counter, double delta = 1) {
    std::lock_guard lock(mutex_);
    counters_[std::string(counter)] += delta;
  }
  // Adds the scope's wall time in nanoseconds to counter "<name>_ns".
  class ScopedTimer {
   public:
    ScopedTimer(NodeContext& ctx, std::string name)
        : ctx_(ctx), name_(std::move(name) + "_ns"), start_(ctx.executor_.now_ns()) {}
    ~ScopedTimer() { ctx_.count(name_, double(ctx_.executor_.now_ns() - start_)); }
    ScopedTimer(const ScopedTimer&) = delete;
    ScopedTimer& operator=(const ScopedTimer&) = delete;

   private:
    NodeContext& ctx_;
    std::string name_;
    std::int64_t start_;
  };
  ScopedTimer timer(std::string name) { return ScopedTimer(*this, std::move(name)); }

  std::map<std::string, double> counters() const {
    std::lock_guard lock(mutex_);
    return counters_;
  }

  // Whether the run is being captured (`inspect`). A pass may then publish what it did beyond
  // its output — a per-pixel view such as a fallback mask — under a name of its own; the
  // capture hook sees it after the node's outputs, with port = name and no resource. Outside a
  // capture, passes skip the work of building such views (and publish drops them).
  bool capturing() const { return capturing_; }
  template <class T>
  void publish(std::string name, T value) {
    if (!capturing_) return;
    std::lock_guard lock(mutex_);
    published_.emplace_back(std::move(name), ResourceValue{std::make_shared<T>(std::move(value)), typeid(T), type_name<T>()});
  }
  const std::vector<std::pair<std::string, ResourceValue>>& published() const { return published_; }

 private:
  template <class T>
  const PortDecl& check(std::string_view port, bool output) const {
    for (const auto& d : ports_) {
      if (d.port != port || d.output != output) continue;
      if (d.type != typeid(T))
        throw GraphError("node '" + node_ + "': port '" + d.port + "' is declared as " +
                         d.type_name + " but accessed as " + type_name<T>());
      return d;
    }
    throw GraphError("node '" + node_ + "': no " + (output ? "output" : "input") + " port '" +
                     std::string(port) + "' was declared");
  }

  Executor& executor_;
  std::string node_;
  const std::vector<PortDecl>& ports_;
  std::map<std::string, ResourceValue>& inputs_;
  std::map<std::string, ResourceValue>& outputs_;
  bool capturing_ = false;
  std::vector<std::pair<std::string, ResourceValue>> published_;
  mutable std::mutex mutex_;
  std::map<std::string, double> counters_;
};

}  // namespace speculum::par
