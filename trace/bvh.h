// The bounding volume hierarchy over the scene's triangle soup: a binned-SAH binary tree
// built in parallel and deterministically (same bytes for any thread count), from which
// two traversal layouts are derived: an 8-wide layout (children tested together in one
// 8-lane AVX2 register, leaves of up to 4 triangles tested together: trace/wide_kernels.h)
// and the threaded layout of YU §3 / [CHCH06] (hit and miss links, stackless traversal in a
// fixed order) that the LOD tracer extends. Refit keeps the topology and
// recomputes the boxes for moved vertices.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "core/bulk_allocator.h"
#include "core/scene.h"
#include "parallel/executor.h"

namespace speculum::trace {

struct Aabb {
  glm::vec3 lo{3.0e38f};
  glm::vec3 hi{-3.0e38f};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return !(lo.x <= hi.x); }
  float half_area() const;  // surface area / 2; 0 for an empty box
  glm::vec3 center() const { return (lo + hi) * 0.5f; }
};

struct BvhBuildOptions {
  int bins = 16;               // SAH bins per axis
  int max_leaf_size = 4;       // ranges this small become leaves (at most 16)
};

// A binary node in depth-first order: an inner node's left child is the next node.
struct BinaryNode {
  Aabb box;
  std::uint32_t right = 0;      // inner: index of the right child
  std::uint32_t first = 0;      // leaf: first triangle slot
  std::uint32_t count = 0;      // leaf: triangle count; 0 for an inner node
  bool is_leaf() const { return count != 0; }
};

// One node of the 8-wide layout: child boxes as structure of arrays, tested in lanes.
// A child reference is an inner node index, a leaf (kLeafBit | first_pack << 2 |
// (pack_count - 1)), or kEmptyChild (its box is inverted, so the sign-selected slab test
// always misses it).
constexpr int kWideArity = 8;
struct alignas(64) WideNode {
  float lo_x[kWideArity], lo_y[kWideArity], lo_z[kWideArity];
  float hi_x[kWideArity], hi_y[kWideArity], hi_z[kWideArity];
  std::uint32_t child[kWideArity];
};
constexpr std::uint32_t kLeafBit = 0x80000000u;
constexpr std::uint32_t kEmptyChild = 0xffffffffu;
constexpr std::uint32_t kMaxTriangles = 1u << 28;  // leaf references keep 29 bits of the pack

// Up to 4 leaf triangles as structure of arrays, intersected together; unused lanes hold
// NaN vertices (never a hit) and id kEmptyChild.
struct alignas(32) TrianglePack {
  float ax[4], ay[4], az[4];
  float bx[4], by[4], bz[4];
  float cx[4], cy[4], cz[4];
  std::uint32_t id[4];
};

// One node of the threaded layout (depth-first order): on a box hit continue at `hit`
// (the left child of an inner node; for a leaf the same as `miss`), on a miss at `miss`
// (the next node after this subtree); kThreadEnd terminates.
struct ThreadedNode {
  Aabb box;
  std::uint32_t hit = 0;
  std::uint32_t miss = 0;
  std::uint32_t first = 0;
  std::uint32_t count = 0;  // 0: inner
};
constexpr std::uint32_t kThreadEnd = 0xffffffffu;

// Triangle vertices in leaf order, so a leaf reads one contiguous range.
struct LeafTriangle {
  glm::vec3 a, b, c;
};

struct BvhStats {
  std::uint64_t binary_nodes = 0, leaves = 0, wide_nodes = 0, triangle_packs = 0;
  std::uint32_t max_depth = 0;
  double build_ms = 0.0;  // everything below: refs, binary tree, both layouts
  // Phases of build_ms (wall clock): primitive refs, top-level splits, parallel subtrees,
  // leaf-triangle gather + depth-first splice, traversal layouts (threaded, packs, wide).
  double refs_ms = 0.0, top_ms = 0.0, subtrees_ms = 0.0, splice_ms = 0.0, layouts_ms = 0.0;
};

class Bvh {
 public:
  Bvh() = default;

  // Builds over triangles (positions, indices). Throws InputError(source, ...) for
  // out-of-range indices, non-finite positions or more than kMaxTriangles triangles.
  // Degenerate (zero-area) triangles are kept: they simply never report a hit.
  static Bvh build(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                   par::Executor& executor, const BvhBuildOptions& options = {},
                   const std::string& source = "bvh");
  static Bvh build(const TriangleMesh& mesh, par::Executor& executor,
                   const BvhBuildOptions& options = {});

  // New positions for the same triangles (same indices as at build): boxes recomputed
  // bottom-up, topology kept; both layouts are re-derived.
  void refit(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
             par::Executor& executor);

  std::size_t triangle_count() const { return triangle_id_.size(); }
  const BulkVector<BinaryNode>& binary_nodes() const { return binary_; }
  const BulkVector<WideNode>& wide_nodes() const { return wide_; }
  const BulkVector<TrianglePack>& triangle_packs() const { return packs_; }
  const BulkVector<ThreadedNode>& threaded_nodes() const { return threaded_; }
  const BulkVector<LeafTriangle>& leaf_triangles() const { return triangles_; }
  // Original triangle index of each leaf slot.
  const BulkVector<std::uint32_t>& triangle_ids() const { return triangle_id_; }
  std::uint32_t wide_root() const { return wide_root_; }
  const BvhStats& stats() const { return stats_; }

  // All the bytes that define the structure, hashed (FNV-1a 64): equal hashes for equal
  // builds; the determinism tests compare it across thread counts.
  std::uint64_t content_hash() const;

 private:
  void derive_layouts(par::Executor& executor);

  // Bulk vectors (core/bulk_allocator.h): filled in parallel, on huge pages where they are big.
  BulkVector<BinaryNode> binary_;
  BulkVector<WideNode> wide_;
  BulkVector<TrianglePack> packs_;
  BulkVector<ThreadedNode> threaded_;
  BulkVector<LeafTriangle> triangles_;
  BulkVector<std::uint32_t> triangle_id_;
  std::uint32_t wide_root_ = kEmptyChild;
  BvhStats stats_;
};

}  // namespace speculum::trace
