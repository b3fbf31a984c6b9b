// The job graph: validation, culling, topological order and concurrent execution; see
// graph.h for the recipe API.
#include "parallel/graph.h"

#include <algorithm>
#include <atomic>
#include <queue>
#include <set>
#include <sstream>

#include <tbb/task_group.h>

namespace speculum::par {

namespace {
std::string quote(std::string_view s) { return "'" + std::string(s) + "'"; }
}  // namespace

const NodeRecord* RunReport::find(std::string_view node) const {
  for (const auto& n : nodes)
    if (n.name == node) return &n;
  return nullptr;
}

std::size_t Graph::add_node(std::string name, std::unique_ptr<Node> node,
                            std::vector<PortDecl> ports) {
  if (name.empty()) throw GraphError("a graph node needs a name");
  for (const auto& e : nodes_)
    if (e.name == name) throw GraphError("two graph nodes are named " + quote(name));
  nodes_.push_back(NodeEntry{std::move(name), std::move(node), std::move(ports), {}, {}});
  compiled_ = false;
  return nodes_.size() - 1;
}

void Graph::set_input(std::string resource, ResourceValue value) {
  inputs_[std::move(resource)] = std::move(value);
  compiled_ = false;
}

void Graph::request_name(std::string resource) {
  requests_.push_back(std::move(resource));
  compiled_ = false;
}

std::map<std::string, Graph::Producer, std::less<>> Graph::find_producers() const {
  std::map<std::string, Producer, std::less<>> producers;
  for (const auto& [r, v] : inputs_) producers.emplace(r, Producer{-1, v.type, v.type_name});
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    for (const auto& d : nodes_[i].ports) {
      if (!d.output) continue;
      auto [it, fresh] = producers.emplace(d.resource, Producer{long(i), d.type, d.type_name});
      if (!fresh)
        throw GraphError("resource " + quote(d.resource) + " has two producers: " +
                         (it->second.node < 0 ? std::string("the graph input")
                                              : "node " + quote(nodes_[it->second.node].name)) +
                         " and node " + quote(nodes_[i].name));
    }
  }
  return producers;
}

// Edges producer → consumer within a frame; inputs_of[i] also lists previous-frame producers
// (they keep their producer alive when culling).
std::vector<Graph::Edge> Graph::connect(const std::map<std::string, Producer, std::less<>>& producers,
                                        std::vector<std::vector<std::size_t>>& inputs_of) const {
  std::vector<Edge> edges;
  inputs_of.assign(nodes_.size(), {});
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const auto& e = nodes_[i];
    for (const auto& d : e.ports) {
      if (d.output) continue;
      auto it = producers.find(d.resource);
      if (it == producers.end()) {
        if (d.previous_frame && previous_.count(d.resource)) continue;  // seeded only
        throw GraphError("node " + quote(e.name) + " reads resource " + quote(d.resource) + " (" +
                         d.type_name + ") but nothing produces it");
      }
      if (it->second.type != d.type)
        throw GraphError("node " + quote(e.name) + " reads resource " + quote(d.resource) + " as " +
                         d.type_name + " but its producer provides " + it->second.type_name);
      if (it->second.node < 0) continue;
      inputs_of[i].push_back(std::size_t(it->second.node));
      if (!d.previous_frame) edges.push_back({std::size_t(it->second.node), i, d.resource});
    }
  }
  return edges;
}

// Keeps what reaches a requested resource (every node when nothing is requested).
std::vector<bool> Graph::reachable_from_requests(
    const std::map<std::string, Producer, std::less<>>& producers,
    const std::vector<std::vector<std::size_t>>& inputs_of) const {
  std::vector<bool> active(nodes_.size(), requests_.empty());
  std::vector<std::size_t> work;
  for (const auto& r : requests_) {
    auto it = producers.find(r);
    if (it == producers.end()) throw GraphError("requested resource " + quote(r) + " has no producer");
    if (it->second.node >= 0) work.push_back(std::size_t(it->second.node));
  }
  while (!work.empty()) {
    const std::size_t i = work.back();
    work.pop_back();
    if (active[i]) continue;
    active[i] = true;
    for (std::size_t p : inputs_of[i]) work.push_back(p);
  }
  return active;
}

// Kahn's algorithm, lowest insertion index first so the order is reproducible. Typed handles
// make a cycle impossible in a recipe (a pass can only read what exists when it is added), but
// the check stays for previous-frame seeds and future APIs.
std::vector<std::size_t> Graph::topological_order(const std::vector<Edge>& edges) const {
  const std::size_t n = nodes_.size();
  std::vector<std::set<std::size_t>> succ(n);
  for (const auto& ed : edges) succ[ed.from].insert(ed.to);
  std::vector<std::size_t> remaining(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t s : succ[i]) ++remaining[s];
  std::priority_queue<std::size_t, std::vector<std::size_t>, std::greater<>> ready;
  for (std::size_t i = 0; i < n; ++i)
    if (remaining[i] == 0) ready.push(i);
  std::vector<std::size_t> topo;
  while (!ready.empty()) {
    const std::size_t i = ready.top();
    ready.pop();
    topo.push_back(i);
    for (std::size_t s : succ[i])
      if (--remaining[s] == 0) ready.push(s);
  }
  if (topo.size() != n) {
    std::string msg = "the graph has a cycle through:";
    for (std::size_t i = 0; i < n; ++i)
      if (remaining[i] != 0) {
        msg += ' ';  // appended in two steps: GCC 12's -Wrestrict misfires on " " + string
        msg += quote(nodes_[i].name);
      }
    throw GraphError(msg);
  }
  return topo;
}

void Graph::compile() {
  if (compiled_) return;
  const auto producers = find_producers();
  std::vector<std::vector<std::size_t>> inputs_of;
  const std::vector<Edge> edges = connect(producers, inputs_of);
  std::vector<bool> active = reachable_from_requests(producers, inputs_of);
  const std::vector<std::size_t> topo = topological_order(edges);
  order_.clear();
  for (std::size_t i : topo)
    if (active[i]) order_.push_back(i);
  successors_.assign(nodes_.size(), {});
  predecessor_count_.assign(nodes_.size(), 0);
  for (const auto& ed : edges) {
    if (!active[ed.from] || !active[ed.to]) continue;
    auto& succ = successors_[ed.from];
    if (std::find(succ.begin(), succ.end(), ed.to) != succ.end()) continue;
    succ.push_back(ed.to);
    ++predecessor_count_[ed.to];
  }
  for (auto& succ : successors_) std::sort(succ.begin(), succ.end());
  active_ = std::move(active);
  compiled_ = true;
}

void Graph::run_node(std::size_t index, Executor& executor, const CaptureHook& capture,
                     NodeRecord& record) {
  auto& entry = nodes_[index];
  std::map<std::string, ResourceValue> in, out;
  {
    std::lock_guard lock(values_mutex_);
    for (const auto& d : entry.ports) {
      if (d.output) continue;
      const auto& source = d.previous_frame ? previous_ : values_;
      auto it = source.find(d.resource);
      if (it != source.end()) in[d.port] = it->second;
    }
  }
  NodeContext ctx(executor, entry.name, entry.ports, in, out, static_cast<bool>(capture));
  record.name = entry.name;
  record.start_ns = executor.now_ns();
  {
    LaunchScope scope(entry.name);
    entry.node->execute(ctx);
  }
  record.duration_ns = executor.now_ns() - record.start_ns;
  record.counters = ctx.counters();
  std::lock_guard lock(values_mutex_);
  for (const auto& d : entry.ports) {
    if (!d.output) continue;
    auto it = out.find(d.port);
    if (it == out.end())
      throw GraphError("node " + quote(entry.name) + " did not write its output " + quote(d.port) +
                       " (resource " + quote(d.resource) + ")");
    if (capture)
      capture({entry.name, d.port, d.resource, d.type_name, d.type, it->second.value.get()});
    values_[d.resource] = std::move(it->second);
  }
  for (const auto& [name, value] : ctx.published())
    capture({entry.name, name, "", value.type_name, value.type, value.value.get()});
}

RunReport Graph::run(Executor& executor, const CaptureHook& capture) {
  compile();
  RunReport report;
  report.start_ns = executor.now_ns();
  values_.clear();
  for (const auto& [r, v] : inputs_) values_[r] = v;
  std::vector<NodeRecord> records(nodes_.size());
  // The first pass to throw (its index and exception); once set, no new pass starts.
  std::mutex failure_mutex;
  std::atomic<bool> failed{false};
  std::size_t failed_node = 0;
  std::exception_ptr failure;
  auto run_guarded = [&](std::size_t i) {
    if (failed.load(std::memory_order_acquire)) return false;
    try {
      run_node(i, executor, capture, records[i]);
      return true;
    } catch (...) {
      std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception(), failed_node = i;
      failed.store(true, std::memory_order_release);
      return false;
    }
  };
  if (executor.synchronous() || order_.size() <= 1) {
    for (std::size_t i : order_)
      if (!run_guarded(i)) break;
  } else {
    executor.run([&] {
      tbb::task_group group;
      std::vector<std::atomic<std::size_t>> pending(nodes_.size());
      for (std::size_t i = 0; i < nodes_.size(); ++i) pending[i].store(predecessor_count_[i]);
      // One fork/join sync per node (TSan annotations; nothing in normal builds): the
      // thread that spawns a node publishes to it, every node publishes to the final wait.
      std::vector<ForkJoinSync> sync(nodes_.size());
      ForkJoinSync done;
      std::function<void(std::size_t)> launch;
      // Node i's task body; it runs after sync[i].enter() (ForkJoinTask), i.e. after
      // everything its spawner did, and publishes to the final wait through `done`. A node
      // that fails (or starts after a failure) launches no successor.
      auto body = [&](std::size_t i) {
        ForkJoinSync::LeaveOnExit leave{done};
        if (!run_guarded(i)) return;
        // acq_rel: the last predecessor to finish publishes every input to the successor.
        for (std::size_t s : successors_[i])
          if (pending[s].fetch_sub(1, std::memory_order_acq_rel) == 1) launch(s);
      };
      launch = [&](std::size_t i) {
        sync[i].fork();
        group.run(ForkJoinTask<decltype(body)>(sync[i], body, i));
      };
      ForkJoinSync::JoinOnExit join{done};
      for (std::size_t i : order_)
        if (predecessor_count_[i] == 0) launch(i);
      group.wait();
    });
  }
  if (failure) {
    std::string message = "unknown exception";
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      message = e.what();
    } catch (...) {
    }
    throw NodeError(nodes_[failed_node].name, failure, message);
  }
  // Cross-frame edges: hand this run's values to the next run (shared, not copied).
  for (std::size_t i : order_)
    for (const auto& d : nodes_[i].ports)
      if (d.previous_frame) {
        auto it = values_.find(d.resource);
        if (it != values_.end()) previous_[d.resource] = it->second;
      }
  for (std::size_t i : order_) report.nodes.push_back(std::move(records[i]));
  report.culled = culled();
  report.duration_ns = executor.now_ns() - report.start_ns;
  return report;
}

bool Graph::has_value(std::string_view resource) const {
  auto it = values_.find(resource);
  return it != values_.end() && it->second.value;
}

const ResourceValue& Graph::value(std::string_view resource) const {
  auto it = values_.find(resource);
  if (it == values_.end() || !it->second.value)
    throw GraphError("resource " + quote(resource) + " has no value (not produced by the last run)");
  return it->second;
}

std::vector<std::string> Graph::order() const {
  std::vector<std::string> names;
  for (std::size_t i : order_) names.push_back(nodes_[i].name);
  return names;
}

std::vector<std::string> Graph::culled() const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < nodes_.size() && i < active_.size(); ++i)
    if (!active_[i]) names.push_back(nodes_[i].name);
  return names;
}

namespace {
std::string dot_escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}
}  // namespace

std::string Graph::to_dot() const {
  std::ostringstream s;
  s << "digraph speculum {\n  rankdir=LR;\n  node [fontname=\"Helvetica\", fontsize=10];\n";
  std::set<std::string> resources;
  for (const auto& [r, v] : inputs_) {
    s << "  \"r:" << dot_escape(r) << "\" [shape=ellipse, style=filled, fillcolor=\"#e8f0ff\", label=\""
      << dot_escape(r) << "\\n" << dot_escape(v.type_name) << "\"];\n";
    resources.insert(r);
  }
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    const auto& e = nodes_[i];
    const bool culled = i < active_.size() && !active_[i];
    s << "  \"n:" << dot_escape(e.name) << "\" [shape=box, " << (culled ? "color=grey, fontcolor=grey, " : "")
      << "label=\"" << dot_escape(e.name);
    for (const auto& [k, v] : e.params.items()) s << "\\n" << dot_escape(k) << " = " << dot_escape(v);
    s << "\"];\n";
    for (const auto& d : e.ports) {
      if (resources.insert(d.resource).second)
        s << "  \"r:" << dot_escape(d.resource) << "\" [shape=ellipse, label=\"" << dot_escape(d.resource)
          << "\\n" << dot_escape(d.type_name) << "\"];\n";
      if (d.output)
        s << "  \"n:" << dot_escape(e.name) << "\" -> \"r:" << dot_escape(d.resource) << "\";\n";
      else
        s << "  \"r:" << dot_escape(d.resource) << "\" -> \"n:" << dot_escape(e.name) << "\""
          << (d.previous_frame ? " [style=dashed, label=\"previous frame\"]" : "") << ";\n";
    }
  }
  s << "}\n";
  return s.str();
}

}  // namespace speculum::par
