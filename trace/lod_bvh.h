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
// A quad proxy also carries what YU's geometry images give a patch for free: a small
// radiance texture over the quad (kProxyGrid² texels, each the area-weighted mean of the
// triangles over it) and its coverage, so a proxy that stands for half a pot's lit side
// and half its shaded side is not one grey, and a ray through a corner of the quad that the
// surface does not reach passes on (YU §3.2's proxies are the surface's own samples).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "parallel/executor.h"
#include "trace/bvh.h"

namespace speculum::trace {

// |Σ A n| / Σ A at or above: the quad proxy. A cylinder patch spanning 2φ has sin φ / φ:
// 0.8 lets one plane stand for 136° of a pot's side, whose silhouettes it cannot show (in
// yu-fig9 at α = 10 that cost 0.37 dB on top of the textured proxies' radiance); 0.9 stops
// at 90° patches.
constexpr float kPlanarity = 0.9f;
constexpr int kProxyGrid = 8;       // texels per side of a quad proxy's radiance texture
constexpr std::uint32_t kNoTexels = 0xffffffffu;

struct LodNode {
  glm::vec3 origin{0.0f}, edge_u{0.0f}, edge_v{0.0f};  // quad: origin + s edge_u + t edge_v
  glm::vec3 normal{0.0f};     // unit mean normal of a quad proxy (zero without one)
  float area = 0.0f;          // total triangle area of the subtree
  // π |pmax - pmin|² / 4, the numerator of eq.6: the box's solid angle seen from x is
  // k / |(pmax + pmin)/2 - x|².
  float box_solid_angle_k = 0.0f;
  glm::vec3 radiance{0.0f};   // filtered (area-weighted mean) radiance
  std::uint32_t parent = kThreadEnd;
  // Inner quad proxies over at least kProxyGrid² triangles: the first of kProxyGrid² texels
  // in LodBvh::proxy_texels (row-major over (s, t) of origin + s edge_u + t edge_v),
  // kNoTexels otherwise. Every inner quad proxy: bit x + kProxyGrid·y set where triangles
  // cover texel (x, y) (projected along the normal, by their bounds).
  std::uint32_t texels = kNoTexels;
  std::uint64_t coverage = ~std::uint64_t(0);
  bool quad = false;
};
static_assert(kProxyGrid * kProxyGrid <= 64, "coverage is a 64-bit mask");

// Node i corresponds to bvh.threaded_nodes()[i].
struct LodBvh {
  std::vector<LodNode> nodes;
  std::vector<std::uint32_t> triangle_leaf;  // original triangle index → its leaf node
  std::vector<float> triangle_area;          // original triangle index → area
  // The eq.7 operand the traversal reads per inner node, packed apart from the proxies (4
  // bytes per node instead of a LodNode cache line): the node's box_solid_angle_k when it has
  // a quad proxy, NaN otherwise (every comparison with NaN is false: the node never stops).
  std::vector<float> stop_k;
  std::vector<glm::vec3> proxy_texels;  // kProxyGrid² per inner quad proxy (LodNode::texels)

  // Radiance of proxy `node` at quad coordinates (s, t) ∈ [0,1]²: bilinear over the covered
  // texels' centres (weights renormalized over them), the node's mean without a texture.
  glm::vec3 proxy_radiance(std::uint32_t node, float s, float t) const;
  // Whether (s, t) falls in a covered texel of `n` (always for a node without coverage).
  static bool proxy_covers(const LodNode& n, float s, float t);
};

// `triangle_radiance` is indexed by original triangle (size bvh.triangle_count()); throws
// InputError otherwise.
// With an executor the textures are filled in parallel (each node writes only its own texels:
// the same bytes either way).
LodBvh build_lod_bvh(const Bvh& bvh, const std::vector<glm::vec3>& triangle_radiance,
                     par::Executor* executor = nullptr);

}  // namespace speculum::trace
