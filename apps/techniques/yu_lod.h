// --technique yu-lod (YU §3.5, TECHNIQUES.md §1): glossy reflections by Phong-sampled rays
// traced through a threaded BVH with adaptive LOD.
#pragma once

#include <memory>

#include "apps/techniques/envmap.h"
#include "trace/bvh.h"
#include "trace/hit_radiance.h"
#include "trace/lod_bvh.h"

namespace speculum::pipeline {

// environment → shadow_map → visibility → gbuffer → direct_light; bvh_build →
// radiance_bake → lod_build; gbuffer → glossy_rays → lod_trace → hit_radiance → composite
// → resolve → tonemap. settings.spp = N rays per glossy pixel; settings.alpha = α of eq.7
// (0: LOD off); params: env_samples (sky rays per triangle in the bake, default 8).
// Always one sample per pixel (settings.supersample is ignored).
void add_yu_lod_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

// The static part of the technique (a static scene's BVH, baked lighting and LOD data: YU
// precomputes them once). Graph resources "bvh", "triangle_lighting", "lod_bvh" hold these
// shared pointers.
struct YuLodStatic {
  std::shared_ptr<const trace::Bvh> bvh;
  std::shared_ptr<const trace::TriangleLighting> lighting;
  std::shared_ptr<const trace::LodBvh> lod;
};
// The same recipe; when `prebuilt` is set (e.g. by the yu-fig9 experiment, across α values)
// bvh_build, radiance_bake and lod_build hand out its data instead of rebuilding it, and
// fill it when empty.
void add_yu_lod_passes_prebuilt(par::Graph& graph, const Scene* scene,
                                const FrameSettings& settings,
                                std::shared_ptr<YuLodStatic> prebuilt);

}  // namespace speculum::pipeline
