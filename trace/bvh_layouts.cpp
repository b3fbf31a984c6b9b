// Derives the traversal layouts from the binary BVH (bvh.h): the 8-wide collapse (SAH-optimal
// choice of each wide node's up to 8 slots, Ylitie et al. 2017 §3.1) with triangle packs and the threaded layout of
// YU §3 / [CHCH06] (depth-first order, hit link = left child, miss link = next subtree).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "trace/bvh.h"

namespace speculum::trace {

namespace {

// The threaded layout: parents precede children, so a forward pass hands each child its
// miss link.
void derive_threaded(const BulkVector<BinaryNode>& binary, BulkVector<ThreadedNode>& threaded) {
  threaded.resize(binary.size());
  if (!binary.empty()) threaded[0].miss = kThreadEnd;
  for (std::size_t i = 0; i < binary.size(); ++i) {
    const BinaryNode& b = binary[i];
    ThreadedNode& t = threaded[i];
    t.box = b.box;
    t.first = b.first;
    t.count = b.count;
    if (b.is_leaf()) {
      t.hit = t.miss;
    } else {
      t.hit = static_cast<std::uint32_t>(i + 1);
      threaded[i + 1].miss = b.right;
      threaded[b.right].miss = t.miss;
    }
  }
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
CollapsePlan plan_collapse(const BulkVector<BinaryNode>& binary, par::Executor& ex) {
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
  // The end of i's subtree: its last node is reached through right children.
  auto subtree_end = [&](std::size_t i) {
    while (!binary[i].is_leaf()) i = binary[i].right;
    return i + 1;
  };
  const std::size_t grain = std::max<std::size_t>(n / 64, 4096);
  std::vector<std::size_t> top;
  std::vector<std::pair<std::size_t, std::size_t>> parts;
  std::vector<std::size_t> stack;
  if (n > 0) stack.push_back(0);
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const std::size_t end = subtree_end(i);
    if (end - i <= grain) {
      parts.emplace_back(i, end);
      continue;
    }
    top.push_back(i);
    stack.push_back(binary[i].right);
    stack.push_back(i + 1);
  }
  ex.parallel_for("bvh_collapse_plan", parts.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p)
      for (std::size_t i = parts[p].second; i-- > parts[p].first;) plan_node(i);
  });
  std::sort(top.begin(), top.end());
  for (std::size_t k = top.size(); k-- > 0;) plan_node(top[k]);
  return plan;
}

// Wide: depth-first allocation, so a child's index is always larger than its parent's.
void derive_wide(const BulkVector<BinaryNode>& binary, const std::vector<std::uint32_t>& leaf_ref,
                 const CollapsePlan& plan, BulkVector<WideNode>& wide, std::uint32_t& wide_root) {
  wide.clear();
  wide_root = kEmptyChild;
  if (binary.empty()) return;
  if (binary[0].is_leaf()) {
    wide_root = leaf_ref[0];
    return;
  }
  wide.reserve(binary.size() / 2);
  struct Item {
    std::uint32_t binary;
    std::uint32_t parent;  // wide node to patch (kEmptyChild: root)
    int slot;
  };
  std::vector<Item> stack{{0, kEmptyChild, 0}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const auto me = static_cast<std::uint32_t>(wide.size());
    if (it.parent == kEmptyChild) wide_root = me;
    else wide[it.parent].child[it.slot] = me;
    std::uint32_t kids[kWideArity];
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
    const int k = plan.node_split[it.binary];
    emit(emit, it.binary + 1, k);
    emit(emit, binary[it.binary].right, kWideArity - k);
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
      node.child[k] = c.is_leaf() ? leaf_ref[kids[k]] : kEmptyChild;  // inner: patched when visited
    }
    wide.push_back(node);
    for (int k = count - 1; k >= 0; --k)
      if (!binary[kids[k]].is_leaf()) stack.push_back({kids[k], me, k});
  }
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

  // The threaded layout and the wide collapse are independent: one task each.
  const CollapsePlan plan = plan_collapse(binary_, ex);
  ex.parallel_for("bvh_layouts", 2, 1, [&](std::size_t task, std::size_t) {
    if (task == 0) derive_threaded(binary_, threaded_);
    else derive_wide(binary_, leaf_ref, plan, wide_, wide_root_);
  });
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
