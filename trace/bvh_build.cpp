// Binned-SAH BVH construction (the classic binned SAH sweep), parallel and deterministic:
// large ranges are split one at a time with binning parallelized over fixed chunks (bins
// combine by min/max/count, which are exact in any order), then the remaining subtrees are
// built independently in a fixed task order and spliced depth-first, so node indices never
// depend on the schedule. See bvh.h.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>

#include "core/error.h"
#include "trace/bvh.h"

namespace speculum::trace {

void Aabb::grow(const glm::vec3& p) {
  lo = glm::min(lo, p);
  hi = glm::max(hi, p);
}
void Aabb::grow(const Aabb& b) {
  lo = glm::min(lo, b.lo);
  hi = glm::max(hi, b.hi);
}
float Aabb::half_area() const {
  if (empty()) return 0.0f;
  const glm::vec3 e = hi - lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

namespace {

constexpr int kMaxBins = 64;
constexpr std::size_t kParallelRange = 1u << 14;  // ranges above this are split at top level
constexpr std::size_t kBinChunk = 1u << 14;
constexpr std::size_t kPrimChunk = 1u << 14;

struct TempNode {
  Aabb box;
  std::uint32_t first = 0, count = 0;      // leaf range in the order array (count > 0)
  std::int64_t left = -1, right = -1;      // children: >= 0 within the same node list;
  std::int64_t left_task = -1, right_task = -1;  // or the root of a subtree task's list
};

struct Bin {
  Aabb box;
  std::uint32_t count = 0;
};

struct BuildInput {
  const std::vector<Aabb>* prim_box;
  const std::vector<glm::vec3>* centroid;
  BvhBuildOptions opt;
};

struct Split {
  int axis = -1;
  int bin = 0;  // left side: bins [0, bin]
  float cost = 0;
};

inline int bin_of(float c, float lo, float scale, int bins) {
  const int i = static_cast<int>((c - lo) * scale);
  return std::clamp(i, 0, bins - 1);
}

// Centroid bounds and box of order[begin, end).
void range_bounds(const BuildInput& in, const std::uint32_t* order, std::size_t n, Aabb& box, Aabb& cbox) {
  for (std::size_t i = 0; i < n; ++i) {
    box.grow((*in.prim_box)[order[i]]);
    cbox.grow((*in.centroid)[order[i]]);
  }
}

void bin_range(const BuildInput& in, const std::uint32_t* order, std::size_t n, const Aabb& cbox,
               int bins, Bin (&out)[3][kMaxBins]) {
  for (int a = 0; a < 3; ++a) {
    const float ext = cbox.hi[a] - cbox.lo[a];
    if (!(ext > 0.0f)) continue;
    const float scale = static_cast<float>(bins) * (1.0f - 1e-6f) / ext;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t p = order[i];
      Bin& b = out[a][bin_of((*in.centroid)[p][a], cbox.lo[a], scale, bins)];
      b.box.grow((*in.prim_box)[p]);
      ++b.count;
    }
  }
}

Split best_split(const Bin (&bins)[3][kMaxBins], const Aabb& cbox, int nbins, std::size_t n,
                 const BvhBuildOptions& opt, float parent_half_area) {
  Split best;
  best.cost = 3.0e38f;
  for (int a = 0; a < 3; ++a) {
    if (!(cbox.hi[a] - cbox.lo[a] > 0.0f)) continue;
    float right_cost[kMaxBins];
    Aabb acc;
    std::uint32_t cnt = 0;
    for (int i = nbins - 1; i > 0; --i) {
      acc.grow(bins[a][i].box);
      cnt += bins[a][i].count;
      right_cost[i] = acc.half_area() * static_cast<float>(cnt);
    }
    acc = Aabb{};
    cnt = 0;
    for (int i = 0; i < nbins - 1; ++i) {
      acc.grow(bins[a][i].box);
      cnt += bins[a][i].count;
      if (cnt == 0 || cnt == n) continue;
      const float cost = acc.half_area() * static_cast<float>(cnt) + right_cost[i + 1];
      if (cost < best.cost) {
        best.cost = cost;
        best.axis = a;
        best.bin = i;
      }
    }
  }
  if (best.axis >= 0)
    best.cost = opt.traversal_cost + opt.triangle_cost * best.cost / std::max(parent_half_area, 1e-30f);
  return best;
}

// Splits order[0, n): returns the size of the left part (0 < k < n), or 0 to make a leaf.
std::size_t split_range(const BuildInput& in, std::uint32_t* order, std::size_t n, const Aabb& box,
                        const Aabb& cbox, const Bin (&bins)[3][kMaxBins]) {
  const BvhBuildOptions& opt = in.opt;
  const std::size_t max_leaf = static_cast<std::size_t>(std::clamp(opt.max_leaf_size, 1, 15));
  if (n <= 1) return 0;
  const Split s = best_split(bins, cbox, opt.bins, n, opt, box.half_area());
  const float leaf_cost = opt.triangle_cost * static_cast<float>(n);
  if (s.axis < 0) {
    // All centroids coincide: no spatial split exists; halve the range by index.
    return n <= max_leaf ? 0 : n / 2;
  }
  if (n <= max_leaf && leaf_cost <= s.cost) return 0;
  const int a = s.axis;
  const float scale = static_cast<float>(opt.bins) * (1.0f - 1e-6f) / (cbox.hi[a] - cbox.lo[a]);
  const float lo = cbox.lo[a];
  const auto mid = std::partition(order, order + n, [&](std::uint32_t p) {
    return bin_of((*in.centroid)[p][a], lo, scale, opt.bins) <= s.bin;
  });
  return static_cast<std::size_t>(mid - order);
}

// Builds a subtree over order[begin, end) serially into `nodes` (root at nodes[0]).
void build_subtree(const BuildInput& in, std::uint32_t* order, std::uint32_t begin, std::uint32_t end,
                   std::vector<TempNode>& nodes) {
  struct Item {
    std::uint32_t begin, end;
    std::size_t node;
  };
  std::vector<Item> stack;
  nodes.push_back({});
  stack.push_back({begin, end, 0});
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const std::size_t n = it.end - it.begin;
    Aabb box, cbox;
    range_bounds(in, order + it.begin, n, box, cbox);
    nodes[it.node].box = box;
    Bin bins[3][kMaxBins] = {};
    bin_range(in, order + it.begin, n, cbox, in.opt.bins, bins);
    const std::size_t k = split_range(in, order + it.begin, n, box, cbox, bins);
    if (k == 0) {
      nodes[it.node].first = it.begin;
      nodes[it.node].count = static_cast<std::uint32_t>(n);
      continue;
    }
    const std::size_t l = nodes.size();
    nodes.push_back({});
    nodes.push_back({});
    nodes[it.node].left = static_cast<std::int64_t>(l);
    nodes[it.node].right = static_cast<std::int64_t>(l + 1);
    stack.push_back({it.begin + static_cast<std::uint32_t>(k), it.end, l + 1});
    stack.push_back({it.begin, it.begin + static_cast<std::uint32_t>(k), l});
  }
}

}  // namespace

Bvh Bvh::build(const TriangleMesh& mesh, par::Executor& executor, const BvhBuildOptions& options) {
  return build(mesh.positions, mesh.indices, executor, options, "scene mesh");
}

Bvh Bvh::build(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
               par::Executor& ex, const BvhBuildOptions& options, const std::string& source) {
  const auto t0 = std::chrono::steady_clock::now();
  if (indices.size() % 3 != 0) throw InputError(source, "index count is not a multiple of 3");
  const std::size_t tri_count = indices.size() / 3;
  if (tri_count >= kMaxTriangles) throw InputError(source, "too many triangles for the BVH (max 2^27)");
  for (std::uint32_t i : indices)
    if (i >= positions.size()) throw InputError(source, "triangle index out of range");
  for (const glm::vec3& p : positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(source, "non-finite vertex position");

  BvhBuildOptions opt = options;
  opt.bins = std::clamp(opt.bins, 2, kMaxBins);
  opt.max_leaf_size = std::clamp(opt.max_leaf_size, 1, 15);

  Bvh bvh;
  std::vector<Aabb> prim_box(tri_count);
  std::vector<glm::vec3> centroid(tri_count);
  std::vector<std::uint32_t> order(tri_count);
  ex.parallel_for("bvh_prim_bounds", tri_count, kPrimChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      Aabb box;
      box.grow(positions[indices[3 * t]]);
      box.grow(positions[indices[3 * t + 1]]);
      box.grow(positions[indices[3 * t + 2]]);
      prim_box[t] = box;
      centroid[t] = box.center();
      order[t] = static_cast<std::uint32_t>(t);
    }
  });
  const BuildInput in{&prim_box, &centroid, opt};

  // Top phase: split large ranges one at a time, binning in parallel over fixed chunks.
  std::vector<TempNode> top;
  struct Task {
    std::uint32_t begin, end;
  };
  std::vector<Task> tasks;            // subtrees left for the parallel phase, in order
  if (tri_count > 0) {
    struct Item {
      std::uint32_t begin, end;
      std::size_t node;
      bool is_left;
      std::size_t parent;
    };
    std::vector<Item> fifo;
    top.push_back({});
    fifo.push_back({0, static_cast<std::uint32_t>(tri_count), 0, false, 0});
    std::size_t head = 0;
    while (head < fifo.size()) {
      const Item it = fifo[head++];
      const std::size_t n = it.end - it.begin;
      if (n <= kParallelRange) {
        // Becomes a task; the node slot is replaced by a task link in its parent.
        const auto task = static_cast<std::int64_t>(tasks.size());
        tasks.push_back({it.begin, it.end});
        if (it.node == 0) top[0].left_task = task;  // the whole tree is one task
        else if (it.is_left) top[it.parent].left_task = task;
        else top[it.parent].right_task = task;
        continue;
      }
      const std::size_t chunks = (n + kBinChunk - 1) / kBinChunk;
      std::vector<Aabb> cbox_part(chunks), box_part(chunks);
      ex.parallel_for("bvh_range_bounds", n, kBinChunk, [&](std::size_t b, std::size_t e) {
        range_bounds(in, order.data() + it.begin + b, e - b, box_part[b / kBinChunk], cbox_part[b / kBinChunk]);
      });
      Aabb box, cbox;
      for (std::size_t c = 0; c < chunks; ++c) {
        box.grow(box_part[c]);
        cbox.grow(cbox_part[c]);
      }
      std::vector<std::array<std::array<Bin, kMaxBins>, 3>> bin_part(chunks);
      ex.parallel_for("bvh_bin", n, kBinChunk, [&](std::size_t b, std::size_t e) {
        Bin local[3][kMaxBins] = {};
        bin_range(in, order.data() + it.begin + b, e - b, cbox, opt.bins, local);
        auto& dst = bin_part[b / kBinChunk];
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < opt.bins; ++i) dst[a][i] = local[a][i];
      });
      Bin bins[3][kMaxBins] = {};
      for (std::size_t c = 0; c < chunks; ++c)
        for (int a = 0; a < 3; ++a)
          for (int i = 0; i < opt.bins; ++i) {
            bins[a][i].box.grow(bin_part[c][a][i].box);
            bins[a][i].count += bin_part[c][a][i].count;
          }
      top[it.node].box = box;
      std::size_t k = split_range(in, order.data() + it.begin, n, box, cbox, bins);
      if (k == 0) k = n / 2;  // a large range always splits
      const std::size_t l = top.size();
      top.push_back({});
      top.push_back({});
      top[it.node].left = static_cast<std::int64_t>(l);
      top[it.node].right = static_cast<std::int64_t>(l + 1);
      const auto mid = it.begin + static_cast<std::uint32_t>(k);
      fifo.push_back({it.begin, mid, l, true, it.node});
      fifo.push_back({mid, it.end, l + 1, false, it.node});
    }
  }

  // Parallel phase: each task builds its subtree alone; chunk = 1 task.
  std::vector<std::vector<TempNode>> sub(tasks.size());
  ex.parallel_for("bvh_subtrees", tasks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) build_subtree(in, order.data(), tasks[t].begin, tasks[t].end, sub[t]);
  });

  // Splice depth-first into the final binary layout and gather leaf triangles in order.
  bvh.triangles_.resize(tri_count);
  bvh.triangle_id_.resize(tri_count);
  ex.parallel_for("bvh_gather_triangles", tri_count, kPrimChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t t = order[i];
      bvh.triangle_id_[i] = t;
      bvh.triangles_[i] = {positions[indices[3 * t]], positions[indices[3 * t + 1]], positions[indices[3 * t + 2]]};
    }
  });
  if (tri_count > 0) {
    struct Ref {
      const std::vector<TempNode>* list;
      std::int64_t index;
      std::uint32_t depth;
      std::int64_t fix_right_of;  // final node whose `right` must point here (-1: none)
    };
    std::vector<Ref> stack;
    auto resolve = [&](const std::vector<TempNode>& list, std::int64_t idx, std::int64_t task) -> Ref {
      if (task >= 0) return {&sub[static_cast<std::size_t>(task)], 0, 0, -1};
      return {&list, idx, 0, -1};
    };
    Ref root = top[0].left_task >= 0 && top[0].left < 0 ? Ref{&sub[static_cast<std::size_t>(top[0].left_task)], 0, 0, -1}
                                                        : Ref{&top, 0, 0, -1};
    stack.push_back(root);
    bvh.binary_.reserve(top.size() + [&] { std::size_t s = 0; for (auto& v : sub) s += v.size(); return s; }());
    while (!stack.empty()) {
      Ref r = stack.back();
      stack.pop_back();
      const TempNode& n = (*r.list)[static_cast<std::size_t>(r.index)];
      const auto me = static_cast<std::uint32_t>(bvh.binary_.size());
      if (r.fix_right_of >= 0) bvh.binary_[static_cast<std::size_t>(r.fix_right_of)].right = me;
      bvh.stats_.max_depth = std::max(bvh.stats_.max_depth, r.depth);
      BinaryNode out;
      out.box = n.box;
      if (n.count > 0) {
        out.first = n.first;
        out.count = n.count;
        ++bvh.stats_.leaves;
        bvh.binary_.push_back(out);
        continue;
      }
      bvh.binary_.push_back(out);
      Ref left = resolve(*r.list, n.left, n.left_task);
      Ref right = resolve(*r.list, n.right, n.right_task);
      left.depth = right.depth = r.depth + 1;
      right.fix_right_of = me;
      stack.push_back(right);
      stack.push_back(left);
    }
  }
  bvh.stats_.binary_nodes = bvh.binary_.size();
  bvh.derive_layouts();
  bvh.stats_.wide_nodes = bvh.wide_.size();
  bvh.stats_.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

void Bvh::refit(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                par::Executor& ex) {
  if (indices.size() / 3 != triangle_id_.size()) throw InputError("bvh refit", "triangle count changed");
  for (std::uint32_t i : indices)
    if (i >= positions.size()) throw InputError("bvh refit", "triangle index out of range");
  ex.parallel_for("bvh_refit_triangles", triangle_id_.size(), kPrimChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t t = triangle_id_[i];
      triangles_[i] = {positions[indices[3 * t]], positions[indices[3 * t + 1]], positions[indices[3 * t + 2]]};
    }
  });
  // Children follow their parent in depth-first order, so a reverse sweep sees them first.
  for (std::size_t i = binary_.size(); i-- > 0;) {
    BinaryNode& n = binary_[i];
    Aabb box;
    if (n.is_leaf()) {
      for (std::uint32_t k = 0; k < n.count; ++k) {
        const LeafTriangle& t = triangles_[n.first + k];
        box.grow(t.a);
        box.grow(t.b);
        box.grow(t.c);
      }
    } else {
      box = binary_[i + 1].box;
      box.grow(binary_[n.right].box);
    }
    n.box = box;
  }
  derive_layouts();
}

}  // namespace speculum::trace
