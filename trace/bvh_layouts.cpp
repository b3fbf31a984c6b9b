// Derives the traversal layouts from the binary BVH (bvh.h): the 4-wide collapse (each wide
// node opens its largest-area inner children until it holds 4) and the threaded layout of
// YU §3 / [CHCH06] (depth-first order, hit link = left child, miss link = next subtree).
#include <cstring>

#include "trace/bvh.h"

namespace speculum::trace {

void Bvh::derive_layouts() {
  // Threaded: parents precede children, so a forward pass hands each child its miss link.
  threaded_.assign(binary_.size(), ThreadedNode{});
  if (!binary_.empty()) threaded_[0].miss = kThreadEnd;
  for (std::size_t i = 0; i < binary_.size(); ++i) {
    const BinaryNode& b = binary_[i];
    ThreadedNode& t = threaded_[i];
    t.box = b.box;
    t.first = b.first;
    t.count = b.count;
    if (b.is_leaf()) {
      t.hit = t.miss;
    } else {
      t.hit = static_cast<std::uint32_t>(i + 1);
      threaded_[i + 1].miss = b.right;
      threaded_[b.right].miss = t.miss;
    }
  }

  // Wide: depth-first allocation, so a child's index is always larger than its parent's.
  wide_.clear();
  wide_root_ = kEmptyChild;
  if (binary_.empty()) return;
  auto leaf_ref = [&](const BinaryNode& n) { return kLeafBit | (n.first << 4) | n.count; };
  if (binary_[0].is_leaf()) {
    wide_root_ = leaf_ref(binary_[0]);
    return;
  }
  struct Item {
    std::uint32_t binary;
    std::uint32_t parent;  // wide node to patch (kEmptyChild: root)
    int slot;
  };
  std::vector<Item> stack{{0, kEmptyChild, 0}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const auto me = static_cast<std::uint32_t>(wide_.size());
    if (it.parent == kEmptyChild) wide_root_ = me;
    else wide_[it.parent].child[it.slot] = me;
    std::uint32_t kids[4] = {it.binary + 1, binary_[it.binary].right, 0, 0};
    int count = 2;
    while (count < 4) {
      int best = -1;
      float best_area = -1.0f;
      for (int k = 0; k < count; ++k) {
        const BinaryNode& c = binary_[kids[k]];
        if (!c.is_leaf() && c.box.half_area() > best_area) {
          best_area = c.box.half_area();
          best = k;
        }
      }
      if (best < 0) break;
      const std::uint32_t opened = kids[best];
      kids[best] = opened + 1;
      kids[count++] = binary_[opened].right;
    }
    Wide4Node node;
    std::memset(&node, 0, sizeof(node));
    for (int k = 0; k < 4; ++k) {
      if (k >= count) {
        node.lo_x[k] = node.lo_y[k] = node.lo_z[k] = 3.0e38f;
        node.hi_x[k] = node.hi_y[k] = node.hi_z[k] = -3.0e38f;
        node.child[k] = kEmptyChild;
        continue;
      }
      const BinaryNode& c = binary_[kids[k]];
      node.lo_x[k] = c.box.lo.x; node.lo_y[k] = c.box.lo.y; node.lo_z[k] = c.box.lo.z;
      node.hi_x[k] = c.box.hi.x; node.hi_y[k] = c.box.hi.y; node.hi_z[k] = c.box.hi.z;
      node.child[k] = c.is_leaf() ? leaf_ref(c) : kEmptyChild;  // inner: patched when visited
    }
    wide_.push_back(node);
    for (int k = count - 1; k >= 0; --k)
      if (!binary_[kids[k]].is_leaf()) stack.push_back({kids[k], me, k});
  }
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
  if (!wide_.empty()) mix(wide_.data(), wide_.size() * sizeof(Wide4Node));
  mix(triangle_id_.data(), triangle_id_.size() * sizeof(std::uint32_t));
  return h;
}

}  // namespace speculum::trace
