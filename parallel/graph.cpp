// The job graph: validation, culling, topological order and concurrent execution
// (DESIGN.md "The job graph"); see graph.h for the recipe API.
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

NodeBuilder& NodeBuilder::bind(std::string_view port, std::string resource) {
  auto& entry = graph_->nodes_[index_];
  for (auto& d : entry.ports) {
    if (d.port == port) {
      d.resource = std::move(resource);
      graph_->compiled_ = false;
      return *this;
    }
  }
  throw GraphError("node " + quote(entry.name) + " has no port " + quote(port) + " to bind");
}

NodeBuilder Graph::add_node(std::string name, std::unique_ptr<Node> node) {
  if (name.empty()) throw GraphError("a graph node needs a name");
  for (const auto& e : nodes_)
    if (e.name == name) throw GraphError("two graph nodes are named " + quote(name));
  NodeEntry entry{std::move(name), std::move(node), {}, {}, {}};
  Ports ports;
  entry.node->declare(ports);
  entry.ports = std::move(ports.decls());
  entry.params = entry.node->parameters();
  nodes_.push_back(std::move(entry));
  compiled_ = false;
  return NodeBuilder(*this, nodes_.size() - 1);
}

void Graph::set_input(std::string resource, ResourceValue value) {
  inputs_[std::move(resource)] = std::move(value);
  compiled_ = false;
}

void Graph::request(std::string resource) {
  requests_.push_back(std::move(resource));
  compiled_ = false;
}

void Graph::compile() {
  if (compiled_) return;
  const std::size_t n = nodes_.size();
  struct Producer {
    long node;  // -1: graph input
    std::type_index type;
    std::string type_name;
  };
  std::map<std::string, Producer, std::less<>> producers;
  auto producer_label = [&](long p) { return p < 0 ? std::string("the graph input") : "node " + quote(nodes_[p].name); };
  for (const auto& [r, v] : inputs_) producers.emplace(r, Producer{-1, v.type, v.type_name});
  for (std::size_t i = 0; i < n; ++i) {
    const auto& e = nodes_[i];
    for (std::size_t a = 0; a < e.ports.size(); ++a)
      for (std::size_t b = a + 1; b < e.ports.size(); ++b)
        if (e.ports[a].port == e.ports[b].port)
          throw GraphError("node " + quote(e.name) + " declares port " + quote(e.ports[a].port) + " twice");
    for (const auto& d : e.ports) {
      if (!d.output) continue;
      auto [it, fresh] = producers.emplace(d.resource, Producer{long(i), d.type, d.type_name});
      if (!fresh)
        throw GraphError("resource " + quote(d.resource) + " has two producers: " +
                         producer_label(it->second.node) + " and node " + quote(e.name));
    }
  }
  // Edges producer → consumer, within a frame.
  struct Edge { std::size_t from, to; std::string resource; };
  std::vector<Edge> edges;
  std::vector<std::vector<std::size_t>> inputs_of(n);  // producer nodes incl. previous-frame
  for (std::size_t i = 0; i < n; ++i) {
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
                         d.type_name + " but " + producer_label(it->second.node) + " provides " +
                         it->second.type_name);
      if (it->second.node < 0) continue;
      inputs_of[i].push_back(std::size_t(it->second.node));
      if (!d.previous_frame) edges.push_back({std::size_t(it->second.node), i, d.resource});
    }
  }
  // Culling: keep what reaches a requested resource (all nodes without requests).
  std::vector<bool> active(n, requests_.empty());
  {
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
  }
  // Topological order (Kahn, lowest insertion index first so the order is reproducible).
  std::vector<std::set<std::size_t>> succ(n);
  for (const auto& ed : edges) succ[ed.from].insert(ed.to);
  std::vector<std::size_t> indegree(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t s : succ[i]) ++indegree[s];
  std::priority_queue<std::size_t, std::vector<std::size_t>, std::greater<>> ready;
  for (std::size_t i = 0; i < n; ++i)
    if (indegree[i] == 0) ready.push(i);
  std::vector<std::size_t> topo;
  std::vector<std::size_t> remaining = indegree;
  while (!ready.empty()) {
    const std::size_t i = ready.top();
    ready.pop();
    topo.push_back(i);
    for (std::size_t s : succ[i])
      if (--remaining[s] == 0) ready.push(s);
  }
  if (topo.size() != n) {
    // Walk backwards along unresolved edges until a node repeats: that loop is the cycle.
    std::vector<bool> done(n, false);
    for (std::size_t i : topo) done[i] = true;
    std::size_t cur = 0;
    while (done[cur]) ++cur;
    std::vector<std::size_t> path;
    std::vector<const Edge*> via;
    std::map<std::size_t, std::size_t> seen;
    while (!seen.count(cur)) {
      seen[cur] = path.size();
      path.push_back(cur);
      const Edge* back = nullptr;
      for (const auto& ed : edges)
        if (ed.to == cur && !done[ed.from]) { back = &ed; break; }
      via.push_back(back);
      cur = back->from;
    }
    // path[k] is fed by path[k+1] through via[k]; print the cycle in data-flow order.
    std::string msg = "the graph has a cycle: ";
    const std::size_t first = seen[cur];
    msg += quote(nodes_[cur].name);
    for (std::size_t k = path.size(); k-- > first;) {
      msg += " -(" + via[k]->resource + ")-> " + quote(nodes_[path[k]].name);
    }
    throw GraphError(msg);
  }
  order_.clear();
  for (std::size_t i : topo)
    if (active[i]) order_.push_back(i);
  successors_.assign(n, {});
  predecessor_count_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!active[i]) continue;
    for (std::size_t s : succ[i])
      if (active[s]) {
        successors_[i].push_back(s);
        ++predecessor_count_[s];
      }
  }
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
  NodeContext ctx(executor, entry.name, entry.ports, in, out);
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
}

RunReport Graph::run(Executor& executor, const CaptureHook& capture) {
  compile();
  RunReport report;
  report.start_ns = executor.now_ns();
  values_.clear();
  for (const auto& [r, v] : inputs_) values_[r] = v;
  std::vector<NodeRecord> records(nodes_.size());
  if (executor.synchronous() || order_.size() <= 1) {
    for (std::size_t i : order_) run_node(i, executor, capture, records[i]);
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
      // everything its spawner did, and publishes to the final wait through `done`.
      auto body = [&](std::size_t i) {
        ForkJoinSync::LeaveOnExit leave{done};
        run_node(i, executor, capture, records[i]);
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

bool Graph::has(std::string_view resource) const {
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
