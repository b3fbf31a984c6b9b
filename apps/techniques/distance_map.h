// Recipes of the sampled-geometry techniques of SURVEY §4 (TECHNIQUES.md §2.2, 2.3, 2.5):
// distance-map, multi-reflection and layered-distance-map, and the passes they share with
// envmap (apps/techniques/envmap.cpp).
#pragma once

#include "apps/techniques/envmap.h"
#include "raster/distance_map_search.h"

namespace speculum::pipeline {

// The search switches and step counts from FrameSettings::param: parallax, linear, secant
// (0/1, default 1) and parallax_steps (1), linear_steps (16), secant_steps (4).
raster::DistanceSearchOptions distance_search_options(const FrameSettings& settings);
// "parallax=1x1 linear=16 secant=4" — what the experiment prints as the steps used.
std::string describe_search(const raster::DistanceSearchOptions& options);

// The envmap frame around a technique's specular layer: environment, shadow_map,
// visibility, gbuffer, direct_light, composite, resolve, tonemap. The technique adds the
// node writing ImageRGBA "specular" (and whatever it needs before it).
void add_frame_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

// --technique distance-map (SURVEY §4.1–4.2): reflector_cube_maps → distance_map_reflect.
void add_distance_map_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// --technique multi-reflection (SURVEY §4.3).
void add_multi_reflection_passes(par::Graph& graph, const Scene* scene,
                                 const FrameSettings& settings);
// --technique layered-distance-map (SURVEY §4.5); describe_layered: its steps column
// ("layers=3 linear=16 secant=4 bounces=2").
std::string describe_layered(const FrameSettings& settings);
void add_layered_distance_map_passes(par::Graph& graph, const Scene* scene,
                                     const FrameSettings& settings);

}  // namespace speculum::pipeline
