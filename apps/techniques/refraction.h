// --technique refraction (SURVEY §4.4): the envmap recipe's passes, with refractor samples
// replaced by the refraction node (raster/refraction.h).
#pragma once

#include <vector>

#include "apps/techniques/envmap.h"

namespace speculum::pipeline {

// environment → shadow_map → visibility → gbuffer → reflector_cube_maps → direct_light
// → envmap_reflect → [method 1: back_faces, refractor_thickness | method 2:
// refractor_impostors] → refraction → composite → resolve → tonemap.
// Parameters (--param): method=0 single interface, 1 two-face (default), 2 distance
// impostors; linear_steps=16, secant_steps=4 (both searches); impostor_size=128.
void add_refraction_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

// d_N of the two-face method: per mesh vertex of a refractor, the distance along −N to the
// refractor's other side (BVH ray cast over the refractor triangles; 0 for other vertices
// and for rays that hit nothing).
std::vector<float> refractor_vertex_thickness(const Scene& scene, par::Executor& executor);

}  // namespace speculum::pipeline
