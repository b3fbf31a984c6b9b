// The LOD data YU §3.3–3.4 attaches to a threaded BVH, for general triangle meshes: every
// node gets approximate geometry and filtered radiance, built bottom-up from the Bvh
// (bvh.h is read, never changed). YU works on geometry images; for general meshes, a node
// whose contents are roughly planar (area-weighted mean normal of length >= kPlanarity) is
// approximated by one quad — the plane through the contents' area centroid perpendicular to
// that mean normal, spanning the projection of the children's proxies (leaves: of their
// triangles); any other node has no approximate geometry (the LOD traversal descends it,
// like YU's geometry-image patches that only stop where two triangles fit the surface).
// Filtered radiance is the area-weighted mean of
// the per-triangle radiance of trace/hit_radiance.h, so the ancestors of a triangle are the
// coarser levels of a mip pyramid whose level-0 texels are the triangles (eq.9).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "trace/bvh.h"

namespace speculum::trace {

constexpr float kPlanarity = 0.8f;  // |Σ A n| / Σ A at or above: the quad proxy

struct LodNode {
  glm::vec3 origin{0.0f}, edge_u{0.0f}, edge_v{0.0f};  // quad: origin + s edge_u + t edge_v
  glm::vec3 normal{0.0f};     // unit mean normal of a quad proxy (zero without one)
  float area = 0.0f;          // total triangle area of the subtree
  // π |pmax - pmin|² / 4, the numerator of eq.6: the box's solid angle seen from x is
  // k / |(pmax + pmin)/2 - x|².
  float box_solid_angle_k = 0.0f;
  glm::vec3 radiance{0.0f};   // filtered (area-weighted mean) radiance
  std::uint32_t parent = kThreadEnd;
  bool quad = false;
};

// Node i corresponds to bvh.threaded_nodes()[i].
struct LodBvh {
  std::vector<LodNode> nodes;
  std::vector<std::uint32_t> triangle_leaf;  // original triangle index → its leaf node
  std::vector<float> triangle_area;          // original triangle index → area
  // The eq.7 operand the traversal reads per inner node, packed apart from the proxies (4
  // bytes per node instead of a LodNode cache line): the node's box_solid_angle_k when it has
  // a quad proxy, NaN otherwise (every comparison with NaN is false: the node never stops).
  std::vector<float> stop_k;
};

// `triangle_radiance` is indexed by original triangle (size bvh.triangle_count()); throws
// InputError otherwise.
LodBvh build_lod_bvh(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance);

}  // namespace speculum::trace
