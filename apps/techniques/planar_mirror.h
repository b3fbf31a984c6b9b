// --technique planar-mirror (SURVEY §5): the envmap recipe's passes with planar mirrors
// rendered by geometry transformation (raster/planar_mirror.h), recursively to depth k.
#pragma once

#include "apps/techniques/envmap.h"

namespace speculum::pipeline {

// environment → shadow_map → visibility → gbuffer → planar_mirrors → direct_light
// → planar_mirror_reflect → composite → resolve → tonemap.
// Parameters: --param depth=k (default 3): mirror bounces; beyond them (and on every
// non-planar specular surface) the environment map is looked up.
void add_planar_mirror_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

}  // namespace speculum::pipeline
