// The passes of YU's glossy reflections (YU §3): the scene's static data (BVH, baked
// triangle lighting, LOD proxies), which YU precomputes once and a LodStaticData cache keeps
// across frames, then the LOD traversal of the glossy rays and the radiance at their hits.
// The glossy rays themselves come from the G-buffer, so their pass lives where raster/ and
// trace/ meet (apps/techniques/).
#pragma once

#include <memory>
#include <vector>

#include "core/scene.h"
#include "parallel/graph_node.h"
#include "trace/bvh.h"
#include "trace/glossy_rays.h"
#include "trace/hit_radiance.h"
#include "trace/lod_bvh.h"
#include "trace/lod_trace.h"

namespace speculum::trace {

// Graph resources: shared pointers, so a cache can hand the same data to many frames.
using BvhPtr = std::shared_ptr<const Bvh>;
using TriangleLightingPtr = std::shared_ptr<const TriangleLighting>;
using LodBvhPtr = std::shared_ptr<const LodBvh>;
using LodHits = std::vector<LodHit>;

// A static scene's precomputed data; empty members are built by the passes and stored.
struct LodStaticData {
  BvhPtr bvh;
  TriangleLightingPtr lighting;
  LodBvhPtr lod;
};

// Pass "bvh_build": the binned-SAH BVH with its threaded (hit/miss link) layout.
struct BvhBuildPass {
  static constexpr const char* description =
      "Binned-SAH BVH with its threaded layout: hit and miss links (YU §3.3).";
  const Scene* scene = nullptr;
  std::shared_ptr<LodStaticData> cache;  // may be null
  BvhPtr operator()(par::NodeContext& c) const;
};

// Pass "radiance_bake": per-triangle direct light and occluded sky.
struct RadianceBakePass {
  static constexpr const char* description =
      "Per-triangle light visibility and occluded sky irradiance: the level-0 texels of the "
      "radiance pyramid (YU §3.4).";
  const Scene* scene = nullptr;
  RadianceBakeOptions options;
  std::shared_ptr<LodStaticData> cache;
  void parameters(par::Params& p) const { p.set("env_samples", options.environment_samples); }
  TriangleLightingPtr operator()(par::NodeContext& c, const BvhPtr& bvh) const;
};

// Pass "lod_build": per-node proxy geometry and filtered radiance.
struct LodBuildPass {
  static constexpr const char* description =
      "Per-node approximate geometry (quad or box) and filtered radiance (YU §3.3).";
  std::shared_ptr<LodStaticData> cache;
  LodBvhPtr operator()(par::NodeContext& c, const BvhPtr& bvh, const TriangleLightingPtr& lighting) const;
};

// Pass "lod_trace": closest hits of the glossy rays with the eq.7 LOD test.
struct LodTracePass {
  static constexpr const char* description =
      "Stackless threaded-BVH traversal with the LOD test Ω_box ≤ α² Ω_s (YU §3.3, eq.6-7).";
  LodOptions options;
  void parameters(par::Params& p) const { p.set("alpha", options.alpha).set("lod", options.enabled ? 1 : 0); }
  LodHits operator()(par::NodeContext& c, const BvhPtr& bvh, const LodBvhPtr& lod,
                     const GlossyRays& rays) const;
};

// Pass "hit_radiance": the glossy specular layer from the hits.
struct HitRadiancePass {
  static constexpr const char* description =
      "Radiance at each hit at the eq.8-9 level, environment on a miss; F × the mean of the N "
      "samples (YU §3.4-3.5).";
  const Scene* scene = nullptr;
  ImageRGBA operator()(par::NodeContext& c, const LodBvhPtr& lod, const TriangleLightingPtr& lighting,
                       const GlossyRays& rays, const LodHits& hits) const;
};

}  // namespace speculum::trace
