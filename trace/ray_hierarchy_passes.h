// The passes of ROGER's ray hierarchy (ROGER §3.3): per bounce, the cone-sphere hierarchy
// over a generation of rays, its traversal to the closest hits, the shadow rays of those
// hits traced the same way, their shading, and the next generation. The first generation
// comes from the G-buffer, so its pass lives where raster/ and trace/ meet (apps/techniques/).
#pragma once

#include <vector>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/graph_node.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"
#include "trace/traversal.h"

namespace speculum::trace {

using ShadowHits = std::vector<HitStream>;  // per scene light

// Pass "ray_hierarchy[_b]": the screen-space quad-tree of cone-spheres over a generation.
struct RayHierarchyPass {
  static constexpr const char* description =
      "Screen-space quad-tree of cone-spheres built bottom-up, one kernel per level (ROGER §3.3.2).";
  int width = 0, height = 0;  // the generation's pixel grid (0: the generation's own size)
  int bounce = 1;
  void parameters(par::Params& p) const { p.set("bounce", bounce); }
  RayHierarchy operator()(par::NodeContext& c, const SecondaryRays& rays) const;
};

// Pass "hierarchy_traverse[_b]": the closest hit of every ray of the generation.
struct HierarchyTraversePass {
  static constexpr const char* description =
      "(node, triangle) pairs refined per level with eq.3.1 and compacted, then exact tests and "
      "the closest hit per ray (ROGER §3.3.3, §4.3).";
  const Scene* scene = nullptr;
  HierarchyTraverseOptions options;
  void parameters(par::Params& p) const {
    p.set("pair_capacity", options.pair_capacity).set("block", options.block_size);
  }
  HitStream operator()(par::NodeContext& c, const SecondaryRays& rays,
                       const RayHierarchy& hierarchy) const;
};

// Pass "shadow_rays[_b]": per light, the generation's hits' shadow rays, reversed to start at
// the light and traced through their own hierarchy.
struct ShadowRaysPass {
  static constexpr const char* description =
      "Shadow rays reversed to start at each point light, traced through their own hierarchy "
      "(ROGER §3.3.5).";
  const Scene* scene = nullptr;
  HierarchyTraverseOptions options;
  int width = 0, height = 0;  // 0: the generation's own size
  ShadowHits operator()(par::NodeContext& c, const SecondaryRays& rays, const HitStream& hits) const;
};

// Pass "shade_hits[_b]": the generation's hits shaded and added to the specular layer of the
// earlier bounces (none for the first).
struct ShadeHitsPass {
  static constexpr const char* description =
      "The hits shaded with the shared model (environment on a miss), weighted and added to the "
      "specular layer (ROGER §3.3.5).";
  const Scene* scene = nullptr;
  int width = 0, height = 0;  // 0: the generation's own size
  int bounce = 1;
  bool last = false;  // the last generation: specular hits end here (counted)
  void parameters(par::Params& p) const { p.set("bounce", bounce); }
  ImageRGBA operator()(par::NodeContext& c, const SecondaryRays& rays, const HitStream& hits,
                       const ShadowHits& shadows, const ImageRGBA* earlier_bounces) const;
};

// Pass "bounce_rays_b": the next generation from the specular hits of the last one.
struct BounceRaysPass {
  static constexpr const char* description =
      "The next generation rebuilt from the specular hits (ROGER §3.3.5).";
  const Scene* scene = nullptr;
  int bounce = 2;
  void parameters(par::Params& p) const { p.set("bounce", bounce); }
  SecondaryRays operator()(par::NodeContext& c, const SecondaryRays& rays, const HitStream& hits) const;
};

}  // namespace speculum::trace
