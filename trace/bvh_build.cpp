// Binned-SAH BVH construction (the classic binned SAH sweep), parallel and deterministic:
// large ranges are split one at a time with binning parallelized over fixed chunks (bins
// combine by min/max/count, exact in any order), then the remaining subtrees are built
// independently in a fixed task order and spliced depth-first, so node indices never
// depend on the schedule. Primitive references carry their boxes, so every pass streams
// memory contiguously. See bvh.h.
#include <immintrin.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "trace/bvh.h"

namespace speculum::trace {

float Aabb::half_area() const {
  if (empty()) return 0.0f;
  const glm::vec3 e = hi - lo;
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

namespace {

constexpr int kMaxBins = 32;
constexpr std::size_t kParallelRange = 1u << 15;  // ranges above this are split at top level
constexpr std::size_t kBinChunk = 1u << 14;
constexpr std::size_t kPrimChunk = 1u << 14;

// A triangle's box and id; the centroid is taken as lo + hi (twice the centre: only its
// order along an axis matters, and it saves a multiply).
struct PrimRef {
  glm::vec3 lo;
  std::uint32_t id;
  glm::vec3 hi;
  std::uint32_t pad;
  glm::vec3 centroid2() const { return lo + hi; }
};

struct TempNode {
  Aabb box;
  std::uint32_t first = 0, count = 0;            // leaf range in the ref array (count > 0)
  std::int64_t left = -1, right = -1;            // children within the same node list
  std::int64_t left_task = -1, right_task = -1;  // or the root of a subtree task's list
};

// A bin's box as SSE lanes (x, y, z, unused) so growing it is two vector min/max. SSE
// intrinsics (the build targets x86-64-v3) rather than Lanes<4>, whose min/max are the
// scalar's NaN-exact selects; over fixed_size simd they were also out-of-line calls in these
// loops (perf). Values are never NaN in lanes 0-2.
struct Bin {
  __m128 lo = _mm_set1_ps(3.0e38f);
  __m128 hi = _mm_set1_ps(-3.0e38f);
  std::uint32_t count = 0;
  Aabb box() const {
    float l[4], h[4];
    _mm_storeu_ps(l, lo);
    _mm_storeu_ps(h, hi);
    Aabb b;
    if (count) b = {glm::vec3(l[0], l[1], l[2]), glm::vec3(h[0], h[1], h[2])};
    return b;
  }
};
using Bins = std::array<std::array<Bin, kMaxBins>, 3>;

struct Range {
  std::uint32_t begin, end;
  Aabb box, cbox;  // bounds of the triangles and of their (doubled) centroids
};

// The bin of a (doubled) centroid c on axis a is clamp(int((c[a] − lo[a]) · scale[a]), 0,
// bins − 1), the conversion truncating toward zero: bin_refs computes it in lanes for the
// three axes, partition on the split axis alone, with the same operations.
struct Binner {
  glm::vec3 lo, scale;
  int bins;
  Binner(const Aabb& cbox, int nbins) : lo(cbox.lo), bins(nbins) {
    const glm::vec3 ext = cbox.hi - cbox.lo;
    for (int a = 0; a < 3; ++a) scale[a] = ext[a] > 0.0f ? static_cast<float>(nbins) * (1.0f - 1e-6f) / ext[a] : 0.0f;
  }
};

// Folds `from`'s first nb bins of each axis into `into` (min/max/count: exact in any order).
void merge_bins(Bins& into, const Bins& from, int nb) {
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < nb; ++i) {
      into[a][i].lo = _mm_min_ps(from[a][i].lo, into[a][i].lo);
      into[a][i].hi = _mm_max_ps(from[a][i].hi, into[a][i].hi);
      into[a][i].count += from[a][i].count;
    }
}

// Below this many refs a second set of bins costs more to clear and merge than it saves (a
// second set for every range, down to the smallest, measured 4-10 % more build CPU time on
// 1.02M triangles; from 64 refs on, 19 % less).
constexpr std::size_t kTwoBinSetsFrom = 64;

// Empties the first nb bins of each axis (the only ones a range of nb bins reads).
void clear_bins(Bins& bins, int nb) {
  for (auto& axis : bins) std::fill_n(axis.begin(), nb, Bin{});
}

// Adds refs[0, n) to `out`, whose first b.bins bins of each axis hold a range's bins so far;
// `second` is scratch.
void bin_refs(const PrimRef* refs, std::size_t n, const Binner& b, Bins& out, Bins& second) {
  // Lane 3 of a ref's lo/hi holds the id/pad bits: it is zeroed before the bin index is
  // formed, and ignored in the bin boxes. Lanes 0-2 compute Binner's bin index.
  const __m128 blo = _mm_setr_ps(b.lo.x, b.lo.y, b.lo.z, 0.0f);
  const __m128 scale = _mm_setr_ps(b.scale.x, b.scale.y, b.scale.z, 0.0f);
  const __m128 xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
  const __m128i top = _mm_set1_epi32(b.bins - 1), bottom = _mm_setzero_si128();
  const auto add = [&](const PrimRef& ref, Bins& bins) {
    const __m128 lo = _mm_loadu_ps(&ref.lo.x);
    const __m128 hi = _mm_loadu_ps(&ref.hi.x);
    const __m128 c = _mm_and_ps(xyz, _mm_add_ps(lo, hi));
    // Truncation toward zero (Binner).
    const __m128i idx = _mm_min_epi32(_mm_max_epi32(_mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, blo), scale)), bottom), top);
    alignas(16) std::int32_t k[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(k), idx);
    for (int a = 0; a < 3; ++a) {
      Bin& bin = bins[a][k[a]];
      bin.lo = _mm_min_ps(bin.lo, lo);
      bin.hi = _mm_max_ps(bin.hi, hi);
      ++bin.count;
    }
  };
  if (n < kTwoBinSetsFrom) {
    for (std::size_t i = 0; i < n; ++i) add(refs[i], out);
    return;
  }
  // Neighbouring refs (neighbouring triangles) mostly land in the same bins, and each update
  // of a bin waits for the store of the one before: every other ref goes to a second set,
  // merged at the end (min/max/count: exact in any order), which halves that chain.
  clear_bins(second, b.bins);
  std::size_t i = 0;
  for (; i + 1 < n; i += 2) {
    add(refs[i], out);
    add(refs[i + 1], second);
  }
  if (i < n) add(refs[i], out);
  merge_bins(out, second, b.bins);
}

struct Split {
  int axis = -1;
  int bin = 0;  // left side: bins [0, bin]
  float cost = 3.0e38f;
};

inline float half_area_of(__m128 lo, __m128 hi) {
  float e[4];
  _mm_storeu_ps(e, _mm_sub_ps(hi, lo));
  return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

Split best_split(const Bins& bins, const Aabb& cbox, std::size_t n, int nb) {
  Split best;
  for (int a = 0; a < 3; ++a) {
    if (!(cbox.hi[a] - cbox.lo[a] > 0.0f)) continue;
    float right_cost[kMaxBins];
    __m128 lo = _mm_set1_ps(3.0e38f), hi = _mm_set1_ps(-3.0e38f);
    std::uint32_t cnt = 0;
    float area = 0.0f;
    for (int i = nb - 1; i > 0; --i) {
      if (bins[a][i].count) {  // an empty bin changes neither the box nor the count
        lo = _mm_min_ps(lo, bins[a][i].lo);
        hi = _mm_max_ps(hi, bins[a][i].hi);
        cnt += bins[a][i].count;
        area = half_area_of(lo, hi);
      }
      right_cost[i] = area * static_cast<float>(cnt);
    }
    lo = _mm_set1_ps(3.0e38f);
    hi = _mm_set1_ps(-3.0e38f);
    cnt = 0;
    area = 0.0f;
    for (int i = 0; i < nb - 1; ++i) {
      if (bins[a][i].count) {
        lo = _mm_min_ps(lo, bins[a][i].lo);
        hi = _mm_max_ps(hi, bins[a][i].hi);
        cnt += bins[a][i].count;
        area = half_area_of(lo, hi);
      }
      if (cnt == 0 || cnt == n) continue;
      const float cost = area * static_cast<float>(cnt) + right_cost[i + 1];
      if (cost < best.cost) best = {a, i, cost};
    }
  }
  return best;
}

// Partitions refs[r.begin, r.end) by the split (or halves it when there is none) and
// returns the two child ranges with their bounds, computed in the same pass.
// Box and centroid bounds accumulated in lanes (lane 3 ignored).
struct LaneBounds {
  __m128 lo = _mm_set1_ps(3.0e38f), hi = _mm_set1_ps(-3.0e38f);
  __m128 clo = _mm_set1_ps(3.0e38f), chi = _mm_set1_ps(-3.0e38f);
  void grow(const PrimRef& r) { grow(_mm_loadu_ps(&r.lo.x), _mm_loadu_ps(&r.hi.x)); }
  // A ref's lo and hi rows (lane 3: its id and pad bits, ignored).
  void grow(__m128 l, __m128 h) {
    const __m128 c = _mm_add_ps(l, h);
    lo = _mm_min_ps(lo, l);
    hi = _mm_max_ps(hi, h);
    clo = _mm_min_ps(clo, c);
    chi = _mm_max_ps(chi, c);
  }
  void to(Range& r) const {
    float a[4], b[4], c[4], d[4];
    _mm_storeu_ps(a, lo); _mm_storeu_ps(b, hi); _mm_storeu_ps(c, clo); _mm_storeu_ps(d, chi);
    if (r.end > r.begin) {
      r.box = {glm::vec3(a[0], a[1], a[2]), glm::vec3(b[0], b[1], b[2])};
      r.cbox = {glm::vec3(c[0], c[1], c[2]), glm::vec3(d[0], d[1], d[2])};
    }
  }
};

std::pair<Range, Range> partition(PrimRef* refs, const Range& r, const Split& s, const Binner& b) {
  Range L{r.begin, r.begin, {}, {}}, R{r.end, r.end, {}, {}};
  LaneBounds lb, rb;
  if (s.axis < 0) {
    const std::uint32_t mid = r.begin + (r.end - r.begin) / 2;
    L.end = mid;
    R.begin = mid;
    for (std::uint32_t i = r.begin; i < mid; ++i) lb.grow(refs[i]);
    for (std::uint32_t i = mid; i < r.end; ++i) rb.grow(refs[i]);
  } else {
    // Binner's bin index on the split axis alone.
    const int a = s.axis;
    const float bin_lo = b.lo[a], bin_scale = b.scale[a];
    auto left = [&](const PrimRef& p) {
      const float c = glm::value_ptr(p.lo)[a] + glm::value_ptr(p.hi)[a];
      return std::clamp(static_cast<int>((c - bin_lo) * bin_scale), 0, b.bins - 1) <= s.bin;
    };
    // Hoare-style in place; every element is classified once and grows its side's bounds.
    // A swapped pair moves through registers, which also grow the bounds: reading the refs
    // back right after their stores stalled on store forwarding.
    PrimRef* lo = refs + r.begin;
    PrimRef* hi = refs + r.end;
    while (true) {
      while (lo < hi && left(*lo)) lb.grow(*lo++);
      while (lo < hi && !left(*(hi - 1))) rb.grow(*--hi);
      if (lo >= hi) break;
      --hi;
      const __m256 x = _mm256_loadu_ps(&lo->lo.x), y = _mm256_loadu_ps(&hi->lo.x);
      _mm256_storeu_ps(&lo->lo.x, y);
      _mm256_storeu_ps(&hi->lo.x, x);
      lb.grow(_mm256_castps256_ps128(y), _mm256_extractf128_ps(y, 1));
      rb.grow(_mm256_castps256_ps128(x), _mm256_extractf128_ps(x, 1));
      ++lo;
    }
    L.end = R.begin = static_cast<std::uint32_t>(lo - refs);
  }
  lb.to(L);
  rb.to(R);
  return {L, R};
}

// Bins for a range of n refs: a range's clearing of the bins and its SAH sweep cost the same
// whatever n, and a range of a few dozen refs fills few of 16 bins; there n / 2 bins (at
// least 4) choose nearly the same splits for less (the build's many small ranges near the
// leaves dominate its node count).
int small_range_bins(std::size_t n, int bins) {
  return static_cast<int>(std::clamp<std::size_t>(n / 2, std::min<std::size_t>(4, bins), bins));
}

// Decides leaf or split for a range given its bins: returns the split (axis -1 with
// `leaf` false means "halve by index": all centroids coincide).
bool make_leaf(const Range& r, const Bins& bins, const BvhBuildOptions& opt, int nb, Split& split) {
  const std::size_t n = r.end - r.begin;
  if (n <= static_cast<std::size_t>(opt.max_leaf_size)) return true;
  split = best_split(bins, r.cbox, n, nb);
  return false;
}

// A subtree built by one task: nodes in depth-first order with `right` relative to the
// subtree's root (shifted when spliced), and the counts the stats need.
struct Subtree {
  std::vector<BinaryNode> nodes;
  std::uint32_t max_depth = 0;
  std::uint64_t leaves = 0;
};

// Builds a subtree over one range serially, emitting nodes directly in depth-first order
// (a node's index is taken when it is popped; the left child is popped right after it).
void build_subtree(PrimRef* refs, const Range& root, const BvhBuildOptions& opt, Subtree& out) {
  struct Item {
    Range range;
    std::uint32_t parent;  // node whose `right` is this item (kEmptyChild: none)
    std::uint32_t depth;
  };
  std::vector<Item> stack;
  stack.push_back({root, kEmptyChild, 0});
  std::vector<BinaryNode>& nodes = out.nodes;
  // At most 2n - 1 nodes: reserved address space, so the vector never moves (pages are only
  // touched as nodes are written).
  nodes.reserve(2 * static_cast<std::size_t>(root.end - root.begin));
  Bins bins, scratch;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const auto me = static_cast<std::uint32_t>(nodes.size());
    if (it.parent != kEmptyChild) nodes[it.parent].right = me;
    out.max_depth = std::max(out.max_depth, it.depth);
    BinaryNode node;
    node.box = it.range.box;
    Split split;
    bool leaf = static_cast<int>(it.range.end - it.range.begin) <= opt.max_leaf_size;
    const int nb = small_range_bins(it.range.end - it.range.begin, opt.bins);
    const Binner binner(it.range.cbox, nb);
    if (!leaf) {
      clear_bins(bins, nb);
      bin_refs(refs + it.range.begin, it.range.end - it.range.begin, binner, bins, scratch);
      leaf = make_leaf(it.range, bins, opt, nb, split);
    }
    if (leaf) {
      node.first = it.range.begin;
      node.count = it.range.end - it.range.begin;
      nodes.push_back(node);
      ++out.leaves;
      continue;
    }
    nodes.push_back(node);
    const auto [L, R] = partition(refs, it.range, split, binner);
    stack.push_back({R, me, it.depth + 1});
    stack.push_back({L, kEmptyChild, it.depth + 1});
  }
}

// The triangle of leaf slot `t` as stored for traversal.
LeafTriangle leaf_triangle(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                           std::uint32_t t) {
  return {positions[indices[3 * t]], positions[indices[3 * t + 1]], positions[indices[3 * t + 2]]};
}

// One reference per triangle (its box and id), in triangle order. Throws
// InputError(source, ...) for an index out of range or a non-finite position.
BulkVector<PrimRef> make_prim_refs(const std::vector<glm::vec3>& positions,
                                    const std::vector<std::uint32_t>& indices, par::Executor& ex,
                                    const std::string& source) {
  const std::size_t tri_count = indices.size() / 3;
  BulkVector<PrimRef> refs(tri_count);
  std::vector<std::uint8_t> bad((tri_count + kPrimChunk - 1) / kPrimChunk, 0);
  ex.parallel_for("bvh_prim_refs", tri_count, kPrimChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      PrimRef& r = refs[t];
      r.lo = glm::vec3(3.0e38f);
      r.hi = glm::vec3(-3.0e38f);
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = indices[3 * t + k];
        if (v >= positions.size()) {
          bad[b / kPrimChunk] |= 1;
          continue;
        }
        const glm::vec3& p = positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) bad[b / kPrimChunk] |= 2;
        r.lo = glm::min(r.lo, p);
        r.hi = glm::max(r.hi, p);
      }
      r.id = static_cast<std::uint32_t>(t);
      r.pad = 0;
    }
  });
  std::uint8_t any_bad = 0;
  for (std::uint8_t b : bad) any_bad |= b;
  if (any_bad & 1) throw InputError(source, "triangle index out of range");
  if (any_bad & 2) throw InputError(source, "non-finite vertex position");
  return refs;
}

// The range refs[begin, end) with its box and centroid bounds, reduced over fixed chunks
// in parallel (min/max: exact in any order).
Range range_bounds(par::Executor& ex, const BulkVector<PrimRef>& refs, std::uint32_t begin, std::uint32_t end) {
  const std::size_t n = end - begin;
  const std::size_t chunks = (n + kBinChunk - 1) / kBinChunk;
  std::vector<Aabb> box(chunks), cbox(chunks);
  ex.parallel_for("bvh_range_bounds", n, kBinChunk, [&](std::size_t b, std::size_t e) {
    Aabb bx, cb;
    for (std::size_t i = begin + b; i < begin + e; ++i) {
      bx.lo = glm::min(bx.lo, refs[i].lo);
      bx.hi = glm::max(bx.hi, refs[i].hi);
      cb.grow(refs[i].centroid2());
    }
    box[b / kBinChunk] = bx;
    cbox[b / kBinChunk] = cb;
  });
  Range r{begin, end, {}, {}};
  for (std::size_t c = 0; c < chunks; ++c) {
    r.box.grow(box[c]);
    r.cbox.grow(cbox[c]);
  }
  return r;
}

// The bins of one large range, filled per fixed chunk in parallel and merged in chunk
// order (min/max/count: exact in any order).
Bins bin_range_parallel(par::Executor& ex, const BulkVector<PrimRef>& refs, const Range& range,
                        const Binner& binner, int nbins) {
  const std::size_t n = range.end - range.begin;
  const std::size_t chunks = (n + kBinChunk - 1) / kBinChunk;
  std::vector<Bins> part(chunks);
  ex.parallel_for("bvh_bin", n, kBinChunk, [&](std::size_t b, std::size_t e) {
    Bins& local = part[b / kBinChunk];
    Bins scratch;
    clear_bins(local, nbins);
    bin_refs(refs.data() + range.begin + b, e - b, binner, local, scratch);
  });
  Bins bins;
  for (auto& axis : bins) axis.fill(Bin{});
  for (std::size_t c = 0; c < chunks; ++c) merge_bins(bins, part[c], nbins);
  return bins;
}

// The top of the tree: the nodes above the subtree tasks (node 0 is the root) and the
// ranges left for the tasks, in task order.
struct TopTree {
  std::vector<TempNode> nodes;
  std::vector<Range> tasks;
};

// Top phase: splits ranges above kParallelRange one tree level at a time (the FIFO is
// breadth-first): each range is binned in parallel over chunks, then the level's
// partitions run in parallel, one range per chunk. Nodes and tasks are numbered in FIFO
// order, as a one-at-a-time loop would number them. Reorders `refs`.
TopTree split_top_ranges(par::Executor& ex, BulkVector<PrimRef>& refs, const BvhBuildOptions& opt) {
  TopTree top;
  if (refs.empty()) return top;
  struct Item {
    Range range;
    std::size_t node;
    bool is_left;
    std::size_t parent;
  };
  std::vector<Item> fifo;
  top.nodes.push_back({});
  fifo.push_back({range_bounds(ex, refs, 0, static_cast<std::uint32_t>(refs.size())), 0, false, 0});
  struct Pending {
    Item item;
    Binner binner;
    Split split;
    Range left, right;
  };
  std::size_t head = 0;
  while (head < fifo.size()) {
    const std::size_t level_end = fifo.size();
    std::vector<Pending> splits;
    for (; head < level_end; ++head) {
      const Item it = fifo[head];
      const std::size_t n = it.range.end - it.range.begin;
      if (n <= kParallelRange) {
        const auto task = static_cast<std::int64_t>(top.tasks.size());
        top.tasks.push_back(it.range);
        if (it.node == 0) top.nodes[0].left_task = task;  // the whole tree is one task
        else if (it.is_left) top.nodes[it.parent].left_task = task;
        else top.nodes[it.parent].right_task = task;
        continue;
      }
      const Binner binner(it.range.cbox, opt.bins);
      const Bins bins = bin_range_parallel(ex, refs, it.range, binner, opt.bins);
      top.nodes[it.node].box = it.range.box;
      splits.push_back({it, binner, best_split(bins, it.range.cbox, n, opt.bins), {}, {}});
    }
    ex.parallel_for("bvh_top_partition", splits.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        Pending& p = splits[k];
        std::tie(p.left, p.right) = partition(refs.data(), p.item.range, p.split, p.binner);
      }
    });
    for (const Pending& p : splits) {
      const std::size_t l = top.nodes.size();
      top.nodes.push_back({});
      top.nodes.push_back({});
      top.nodes[p.item.node].left = static_cast<std::int64_t>(l);
      top.nodes[p.item.node].right = static_cast<std::int64_t>(l + 1);
      fifo.push_back({p.left, l, true, p.item.node});
      fifo.push_back({p.right, l + 1, false, p.item.node});
    }
  }
  return top;
}

// Parallel phase: each task builds its subtree alone; chunk = 1 task.
std::vector<Subtree> build_subtrees(par::Executor& ex, BulkVector<PrimRef>& refs,
                                    const std::vector<Range>& tasks, const BvhBuildOptions& opt) {
  std::vector<Subtree> sub(tasks.size());
  ex.parallel_for("bvh_subtrees", tasks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) build_subtree(refs.data(), tasks[t], opt, sub[t]);
  });
  return sub;
}

// Leaf triangles and their ids in ref order.
void gather_leaf_triangles(par::Executor& ex, const BulkVector<PrimRef>& refs,
                           const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                           BulkVector<LeafTriangle>& triangles, BulkVector<std::uint32_t>& triangle_id) {
  triangles.resize(refs.size());
  triangle_id.resize(refs.size());
  ex.parallel_for("bvh_gather_triangles", refs.size(), kPrimChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t t = refs[i].id;
      triangle_id[i] = t;
      triangles[i] = leaf_triangle(positions, indices, t);
    }
  });
}

// Splices the top nodes and subtrees depth-first into the final binary layout: a serial
// walk over the few top nodes places each subtree at its offset, then the subtrees are
// copied (shifting `right`) in parallel, one task per subtree. Fills the depth and leaf
// counts of `stats`. `top` must hold the root (a non-empty build).
void splice_depth_first(par::Executor& ex, const TopTree& top, const std::vector<Subtree>& sub,
                        BulkVector<BinaryNode>& binary, BvhStats& stats) {
  struct Placement {
    std::size_t task;
    std::uint32_t offset, depth;
  };
  std::vector<Placement> placements;
  std::vector<std::pair<std::uint32_t, BinaryNode>> top_out;  // (final index, node)
  std::uint32_t cursor = 0;
  auto place_task = [&](std::int64_t task, std::uint32_t depth) {
    const auto t = static_cast<std::size_t>(task);
    placements.push_back({t, cursor, depth});
    cursor += static_cast<std::uint32_t>(sub[t].nodes.size());
  };
  auto place_top = [&](auto&& self, std::size_t idx, std::uint32_t depth) -> void {
    const TempNode& n = top.nodes[idx];
    const std::uint32_t me = cursor++;
    top_out.push_back({me, BinaryNode{}});
    const std::size_t slot = top_out.size() - 1;
    top_out[slot].second.box = n.box;
    stats.max_depth = std::max(stats.max_depth, depth);
    if (n.left_task >= 0) place_task(n.left_task, depth + 1);
    else self(self, static_cast<std::size_t>(n.left), depth + 1);
    top_out[slot].second.right = cursor;
    if (n.right_task >= 0) place_task(n.right_task, depth + 1);
    else self(self, static_cast<std::size_t>(n.right), depth + 1);
  };
  if (top.nodes[0].left < 0) place_task(top.nodes[0].left_task, 0);  // the whole tree is one task
  else place_top(place_top, 0, 0);
  binary.resize(cursor);
  for (const auto& [index, node] : top_out) binary[index] = node;
  ex.parallel_for("bvh_splice", placements.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      const Placement& pl = placements[p];
      const std::vector<BinaryNode>& nodes = sub[pl.task].nodes;
      BinaryNode* out = binary.data() + pl.offset;
      for (std::size_t i = 0; i < nodes.size(); ++i) {
        out[i] = nodes[i];
        if (!nodes[i].is_leaf()) out[i].right += pl.offset;
      }
    }
  });
  for (const Placement& pl : placements) {
    stats.max_depth = std::max(stats.max_depth, pl.depth + sub[pl.task].max_depth);
    stats.leaves += sub[pl.task].leaves;
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
  if (tri_count >= kMaxTriangles) throw InputError(source, "too many triangles for the BVH (max 2^28)");
  BvhBuildOptions opt = options;
  opt.bins = std::clamp(opt.bins, 2, kMaxBins);
  opt.max_leaf_size = std::clamp(opt.max_leaf_size, 1, 16);
  auto lap = [t = t0]() mutable {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  };

  Bvh bvh;
  BulkVector<PrimRef> refs = make_prim_refs(positions, indices, ex, source);
  bvh.stats_.refs_ms = lap();
  const TopTree top = split_top_ranges(ex, refs, opt);
  bvh.stats_.top_ms = lap();
  const std::vector<Subtree> sub = build_subtrees(ex, refs, top.tasks, opt);
  bvh.stats_.subtrees_ms = lap();
  gather_leaf_triangles(ex, refs, positions, indices, bvh.triangles_, bvh.triangle_id_);
  if (tri_count > 0) splice_depth_first(ex, top, sub, bvh.binary_, bvh.stats_);
  bvh.stats_.binary_nodes = bvh.binary_.size();
  bvh.stats_.splice_ms = lap();
  bvh.derive_layouts(ex);
  bvh.stats_.wide_nodes = bvh.wide_.size();
  bvh.stats_.layouts_ms = lap();
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
      triangles_[i] = leaf_triangle(positions, indices, triangle_id_[i]);
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
  derive_layouts(ex);
}

}  // namespace speculum::trace
