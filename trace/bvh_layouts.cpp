// Derives the traversal layouts from the binary BVH (bvh.h): the 8-wide collapse (SAH-optimal
// choice of each wide node's up to 8 slots, Ylitie et al. 2017 §3.1) with triangle packs and the threaded layout of
// YU §3 / [CHCH06] (depth-first order, hit link = left child, miss link = next subtree).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>
#include <vector>

#include "trace/bvh.h"

namespace speculum::trace {

namespace {

// The end of binary node i's subtree, whose nodes are the index range [i, end) in
// depth-first order: its last node is reached through right children.
std::size_t subtree_end(const BulkVector<BinaryNode>& binary, std::size_t i) {
  while (!binary[i].is_leaf()) i = binary[i].right;
  return i + 1;
}

// Binary subtrees of at most this many nodes are one task of a parallel sweep.
std::size_t subtree_grain(std::size_t nodes) { return std::max<std::size_t>(nodes / 64, 4096); }

// The binary tree cut for parallel sweeps: the subtrees of at most subtree_grain nodes whose
// parent's subtree is larger (each an index range [begin, end) in depth-first order), and the
// nodes above them, in increasing index order. A node's children lie in its own part, or are
// top nodes or part roots.
struct SubtreeParts {
  std::vector<std::pair<std::size_t, std::size_t>> parts;
  std::vector<std::size_t> top;
};

SubtreeParts cut_subtrees(const BulkVector<BinaryNode>& binary) {
  SubtreeParts cut;
  const std::size_t grain = subtree_grain(binary.size());
  std::vector<std::size_t> stack;
  if (!binary.empty()) stack.push_back(0);
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const std::size_t end = subtree_end(binary, i);
    if (end - i <= grain) {
      cut.parts.emplace_back(i, end);
      continue;
    }
    cut.top.push_back(i);
    stack.push_back(binary[i].right);
    stack.push_back(i + 1);
  }
  std::sort(cut.top.begin(), cut.top.end());
  return cut;
}

// Calls visit(i) for every node, children before parents: each part in parallel from its
// last node down, then the top nodes in decreasing index order. A visit that reads only its
// children's results computes the same values as one serial sweep, for any thread count.
template <class Visit>
void sweep_bottom_up(par::Executor& ex, std::string_view name, const SubtreeParts& cut, Visit&& visit) {
  ex.parallel_for(name, cut.parts.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p)
      for (std::size_t i = cut.parts[p].second; i-- > cut.parts[p].first;) visit(i);
  });
  for (std::size_t k = cut.top.size(); k-- > 0;) visit(cut.top[k]);
}

// The threaded layout: a node's miss link is the node after its subtree (kThreadEnd after the
// last), whose end is its right child's subtree's end; its hit link is its left child (the
// next node), or for a leaf the miss link.
void derive_threaded(const BulkVector<BinaryNode>& binary, const SubtreeParts& cut, par::Executor& ex,
                     BulkVector<ThreadedNode>& threaded) {
  const std::size_t n = binary.size();
  threaded.resize(n);
  const auto link = [n](std::size_t end) { return end < n ? static_cast<std::uint32_t>(end) : kThreadEnd; };
  sweep_bottom_up(ex, "bvh_threaded", cut, [&](std::size_t i) {
    const BinaryNode& b = binary[i];
    ThreadedNode& t = threaded[i];
    t.box = b.box;
    t.first = b.first;
    t.count = b.count;
    if (b.is_leaf()) {
      t.miss = link(i + 1);
      t.hit = t.miss;
    } else {
      t.miss = threaded[b.right].miss;
      t.hit = static_cast<std::uint32_t>(i + 1);
    }
  });
}

// One leaf's triangles as packs of 4 (unused lanes: NaN vertices, id kEmptyChild).
void fill_packs(const BulkVector<LeafTriangle>& tris, const BulkVector<std::uint32_t>& ids, const BinaryNode& leaf,
                TrianglePack* out) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::uint32_t npacks = (leaf.count + 3) / 4;
  for (std::uint32_t p = 0; p < npacks; ++p) {
    TrianglePack& pack = out[p];
    for (int l = 0; l < 4; ++l) {
      const std::uint32_t k = p * 4 + static_cast<std::uint32_t>(l);
      const bool used = k < leaf.count;
      const LeafTriangle t = used ? tris[leaf.first + k] : LeafTriangle{glm::vec3(nan), glm::vec3(nan), glm::vec3(nan)};
      pack.ax[l] = t.a.x; pack.ay[l] = t.a.y; pack.az[l] = t.a.z;
      pack.bx[l] = t.b.x; pack.by[l] = t.b.y; pack.bz[l] = t.b.z;
      pack.cx[l] = t.c.x; pack.cy[l] = t.c.y; pack.cz[l] = t.c.z;
      pack.id[l] = used ? ids[leaf.first + k] : kEmptyChild;
    }
  }
}

// The SAH-optimal collapse of the binary tree into 8-wide nodes (Ylitie et al. 2017,
// "Efficient incoherent ray traversal on GPUs through compressed wide BVHs" §3.1), with
// the binary leaves kept as the leaves: each leaf lands in exactly one slot, so its cost is
// the same for every collapse and only the wide nodes' areas are minimised. cost(n, j) is
// the cheapest way to represent subtree n in at most j slots: n itself as one slot (a wide
// node over its children, area(n) + the children in 8 slots), or n dissolved with its
// children sharing the j slots. Greedy opening by area left many bottom nodes 2-4 full.
struct CollapsePlan {
  BulkVector<std::uint8_t> choice;      // [n * 8 + j - 1]: 0 = n is one slot, else slots of the left child
  BulkVector<std::uint8_t> node_split;  // n as a wide node: slots of its left child (of 8)
};

// A node's plan reads only its two children's costs, and the nodes of a subtree are one
// index range [i, end) in depth-first order: the subtrees below a size are planned in
// parallel (one task each, children before parents), then the few nodes above them in
// decreasing index order. Every cost is computed by the same operations as in one serial
// sweep, so the plan does not depend on the thread count.
CollapsePlan plan_collapse(const BulkVector<BinaryNode>& binary, const SubtreeParts& cut, par::Executor& ex) {
  const std::size_t n = binary.size();
  CollapsePlan plan;
  plan.choice.resize(n * kWideArity);
  plan.node_split.resize(n);
  BulkVector<float> cost(n * kWideArity);  // leaves cost 0 (the same in every collapse)
  auto plan_node = [&](std::size_t i) {
    const BinaryNode& b = binary[i];
    float* out = &cost[i * kWideArity];
    std::uint8_t* choice = &plan.choice[i * kWideArity];
    if (b.is_leaf()) {
      std::fill_n(out, kWideArity, 0.0f);
      std::fill_n(choice, kWideArity, std::uint8_t{0});
      plan.node_split[i] = 0;
      return;
    }
    const float* l = &cost[(i + 1) * kWideArity];
    const float* r = &cost[static_cast<std::size_t>(b.right) * kWideArity];
    float split_cost[kWideArity + 1];
    std::uint8_t split_left[kWideArity + 1];
    for (int j = 2; j <= kWideArity; ++j) {
      float best = l[0] + r[j - 2];
      int best_k = 1;
      for (int k = 2; k < j; ++k) {
        const float c = l[k - 1] + r[j - k - 1];
        if (c < best) {
          best = c;
          best_k = k;
        }
      }
      split_cost[j] = best;
      split_left[j] = static_cast<std::uint8_t>(best_k);
    }
    const float as_node = b.box.half_area() + split_cost[kWideArity];
    plan.node_split[i] = split_left[kWideArity];
    out[0] = as_node;
    choice[0] = 0;
    for (int j = 2; j <= kWideArity; ++j) {
      const bool dissolve = split_cost[j] < as_node;
      out[j - 1] = dissolve ? split_cost[j] : as_node;
      choice[j - 1] = dissolve ? split_left[j] : 0;
    }
  };
  sweep_bottom_up(ex, "bvh_collapse_plan", cut, plan_node);
  return plan;
}

// The children of the wide node over binary inner node b, in slot order: the binary nodes the
// plan keeps as slots.
int wide_children(const BulkVector<BinaryNode>& binary, const CollapsePlan& plan, std::uint32_t b,
                  std::uint32_t kids[kWideArity]) {
  int count = 0;
  auto emit = [&](auto&& self, std::uint32_t c, int slots) -> void {
    const int k = binary[c].is_leaf() ? 0 : plan.choice[c * kWideArity + slots - 1];
    if (k == 0) {
      kids[count++] = c;
      return;
    }
    self(self, c + 1, k);
    self(self, binary[c].right, slots - k);
  };
  const int k = plan.node_split[b];
  emit(emit, b + 1, k);
  emit(emit, binary[b].right, kWideArity - k);
  return count;
}

// A wide node over the given children; an inner child's slot is left kEmptyChild, to be
// set to its wide index when that is known.
WideNode make_wide_node(const BulkVector<BinaryNode>& binary, const std::vector<std::uint32_t>& leaf_ref,
                        const std::uint32_t* kids, int count) {
  WideNode node;
  std::memset(&node, 0, sizeof(node));
  for (int k = 0; k < kWideArity; ++k) {
    if (k >= count) {
      node.lo_x[k] = node.lo_y[k] = node.lo_z[k] = 3.0e38f;
      node.hi_x[k] = node.hi_y[k] = node.hi_z[k] = -3.0e38f;
      node.child[k] = kEmptyChild;
      continue;
    }
    const BinaryNode& c = binary[kids[k]];
    node.lo_x[k] = c.box.lo.x; node.lo_y[k] = c.box.lo.y; node.lo_z[k] = c.box.lo.z;
    node.hi_x[k] = c.box.hi.x; node.hi_y[k] = c.box.hi.y; node.hi_z[k] = c.box.hi.z;
    node.child[k] = c.is_leaf() ? leaf_ref[kids[k]] : kEmptyChild;
  }
  return node;
}

// The wide subtree over binary inner node `root` in preorder (a node, then its children's
// subtrees in slot order): written to out[0, n) with child indices offset by `offset` when
// `out` is given, counted only otherwise. Returns n.
std::uint32_t emit_wide_subtree(const BulkVector<BinaryNode>& binary, const std::vector<std::uint32_t>& leaf_ref,
                                const CollapsePlan& plan, std::uint32_t root, WideNode* out, std::uint32_t offset) {
  struct Item {
    std::uint32_t binary;
    std::uint32_t parent;  // local index of the wide node to patch (kEmptyChild: the root)
    int slot;
  };
  std::vector<Item> stack{{root, kEmptyChild, 0}};
  std::uint32_t n = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const std::uint32_t me = n++;
    std::uint32_t kids[kWideArity];
    const int count = wide_children(binary, plan, it.binary, kids);
    if (out) {
      if (it.parent != kEmptyChild) out[it.parent].child[it.slot] = offset + me;
      out[me] = make_wide_node(binary, leaf_ref, kids, count);
    }
    for (int k = count - 1; k >= 0; --k)
      if (!binary[kids[k]].is_leaf()) stack.push_back({kids[k], me, k});
  }
  return n;
}

// Wide: preorder allocation, so a child's index is always larger than its parent's. The
// wide nodes over binary subtrees below a size are tasks, counted and then written in
// parallel; the few nodes above them are placed in one serial preorder walk, each task's
// nodes at the index its preorder position gives: the same array as one serial walk.
void derive_wide(const BulkVector<BinaryNode>& binary, const std::vector<std::uint32_t>& leaf_ref,
                 const CollapsePlan& plan, par::Executor& ex, BulkVector<WideNode>& wide, std::uint32_t& wide_root) {
  wide.clear();
  wide_root = kEmptyChild;
  if (binary.empty()) return;
  if (binary[0].is_leaf()) {
    wide_root = leaf_ref[0];
    return;
  }
  const std::size_t grain = subtree_grain(binary.size());
  // The top nodes in preorder with their children, and the tasks in preorder.
  struct Top {
    std::uint32_t kids[kWideArity];
    int count;
  };
  struct Task {
    std::uint32_t binary, offset, count;
  };
  std::vector<Top> top;
  std::vector<Task> tasks;
  auto collect = [&](auto&& self, std::uint32_t b) -> void {
    Top t;
    t.count = wide_children(binary, plan, b, t.kids);
    top.push_back(t);
    for (int k = 0; k < t.count; ++k) {
      const std::uint32_t c = t.kids[k];
      if (binary[c].is_leaf()) continue;
      if (subtree_end(binary, c) - c <= grain) tasks.push_back({c, 0, 0});
      else self(self, c);
    }
  };
  if (subtree_end(binary, 0) <= grain) tasks.push_back({0, 0, 0});  // the whole tree is one task
  else collect(collect, 0);
  ex.parallel_for("bvh_wide_count", tasks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t)
      tasks[t].count = emit_wide_subtree(binary, leaf_ref, plan, tasks[t].binary, nullptr, 0);
  });
  // Preorder placement: a top node, then each inner child's subtree (a task's nodes, or the
  // next top node's) in slot order.
  std::uint32_t cursor = 0;
  std::size_t next_top = 0, next_task = 0;
  std::vector<std::uint32_t> top_index(top.size());
  std::vector<WideNode> top_nodes(top.size());
  auto place = [&](auto&& self) -> std::uint32_t {
    const std::size_t me_top = next_top++;
    const std::uint32_t me = cursor++;
    const Top& t = top[me_top];
    WideNode node = make_wide_node(binary, leaf_ref, t.kids, t.count);
    for (int k = 0; k < t.count; ++k) {
      const std::uint32_t c = t.kids[k];
      if (binary[c].is_leaf()) continue;
      if (next_task < tasks.size() && tasks[next_task].binary == c) {
        Task& task = tasks[next_task++];
        task.offset = cursor;
        cursor += task.count;
        node.child[k] = task.offset;
      } else {
        node.child[k] = self(self);
      }
    }
    top_index[me_top] = me;
    top_nodes[me_top] = node;
    return me;
  };
  if (top.empty()) {
    tasks[0].offset = 0;
    cursor = tasks[0].count;
  } else {
    place(place);
  }
  wide.resize(cursor);
  for (std::size_t k = 0; k < top.size(); ++k) wide[top_index[k]] = top_nodes[k];
  ex.parallel_for("bvh_wide_fill", tasks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t)
      emit_wide_subtree(binary, leaf_ref, plan, tasks[t].binary, wide.data() + tasks[t].offset, tasks[t].offset);
  });
  wide_root = 0;
}

}  // namespace

void Bvh::derive_layouts(par::Executor& ex) {
  // Triangle packs: each binary leaf's triangles in groups of 4, in depth-first order. The
  // pack offsets come from one serial pass; the packs (the bulk of the bytes) are written
  // in parallel over fixed chunks of leaves.
  std::vector<std::uint32_t> leaf_ref(binary_.size(), kEmptyChild);
  std::vector<std::uint32_t> leaves;
  leaves.reserve(stats_.leaves);
  std::uint32_t pack_count = 0;
  for (std::size_t i = 0; i < binary_.size(); ++i) {
    const BinaryNode& b = binary_[i];
    if (!b.is_leaf()) continue;
    const std::uint32_t npacks = (b.count + 3) / 4;
    leaf_ref[i] = kLeafBit | (pack_count << 2) | (npacks - 1);
    leaves.push_back(static_cast<std::uint32_t>(i));
    pack_count += npacks;
  }
  packs_.resize(pack_count);
  ex.parallel_for("bvh_triangle_packs", leaves.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) {
      const std::uint32_t ref = leaf_ref[leaves[k]];
      fill_packs(triangles_, triangle_id_, binary_[leaves[k]], &packs_[(ref & ~kLeafBit) >> 2]);
    }
  });
  stats_.triangle_packs = packs_.size();

  const SubtreeParts cut = cut_subtrees(binary_);
  const CollapsePlan plan = plan_collapse(binary_, cut, ex);
  derive_wide(binary_, leaf_ref, plan, ex, wide_, wide_root_);
  derive_threaded(binary_, cut, ex, threaded_);
}

std::uint64_t Bvh::content_hash() const {
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&](const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 1099511628211ull;
    }
  };
  for (const BinaryNode& n : binary_) {
    mix(&n.box, sizeof(n.box));
    mix(&n.right, sizeof(n.right));
    mix(&n.first, sizeof(n.first));
    mix(&n.count, sizeof(n.count));
  }
  if (!wide_.empty()) mix(wide_.data(), wide_.size() * sizeof(WideNode));
  mix(triangle_id_.data(), triangle_id_.size() * sizeof(std::uint32_t));
  return h;
}

}  // namespace speculum::trace
