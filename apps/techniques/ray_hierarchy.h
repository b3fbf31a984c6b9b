// --technique ray-hierarchy (ROGER ch.3, TECHNIQUES.md §4.2): secondary rays from the
// G-buffer traced through a screen-space cone-sphere hierarchy over stream compaction.
#pragma once

#include "apps/techniques/envmap.h"

namespace speculum::pipeline {

// environment → shadow_map → visibility → gbuffer → direct_light; gbuffer →
// secondary_rays → per bounce b: ray_hierarchy → hierarchy_traverse → shadow_rays
// (reversed from each point light, traced the same way) → shade_hits → bounce_rays; then
// composite → resolve → tonemap. settings.bounces = B generations (>= 1); params:
// pair_capacity (default 2048² pairs), block (compaction block size s, default 64).
void add_ray_hierarchy_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

}  // namespace speculum::pipeline
