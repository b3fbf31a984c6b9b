// One recipe per technique: the list of passes that make its frame. Each takes the scene
// (which must outlive the graph's runs) and the frame settings with the technique's
// parameters filled in (Technique::add_passes does that), and returns the frame's outputs.
#pragma once

#include <memory>
#include <string>

#include "apps/techniques/frame_settings.h"
#include "raster/distance_map_search.h"
#include "trace/lod_passes.h"

namespace speculum::pipeline {

// envmap (SURVEY §3.1): surface passes → reflector_cube_maps → envmap_reflect → output passes.
FrameOutputs add_envmap_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// reference: reference_trace → tonemap.
FrameOutputs add_reference_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// specular-reference: surface passes → specular_trace (exact specular layer) → output passes.
FrameOutputs add_specular_reference_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// distance-map (SURVEY §4.1–4.2): reflector_distance_maps → distance_map_search →
//   reflector_cube_maps (colour where the searches read) → distance_map_reflect.
FrameOutputs add_distance_map_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// multi-reflection (SURVEY §4.3): reflector_distance_maps → distance_map_search →
//   multi_reflection_maps (each round where the next reads it) → distance_map_reflect;
//   lagged=1: multi_reflection_maps (previous frame's maps) → distance_map_reflect.
FrameOutputs add_multi_reflection_passes(par::Graph& graph, const Scene* scene,
                                         const FrameSettings& settings);
// layered-distance-map (SURVEY §4.5): layered_distance_map → layered_reflect.
FrameOutputs add_layered_distance_map_passes(par::Graph& graph, const Scene* scene,
                                             const FrameSettings& settings);
// refraction (SURVEY §4.4): reflector_cube_maps → envmap_reflect → [back_faces,
// refractor_thickness | refractor_impostors] → refraction.
FrameOutputs add_refraction_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// caustics (SURVEY §6): reflector_cube_maps (distances), refractor_impostors → caustic_photons →
// caustic_map → caustic_gather (direct + caustics); distance_map_search → caustic_reflector_maps
// (colour where read) → distance_map_reflect → refraction.
FrameOutputs add_caustics_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// planar-mirror (SURVEY §5): planar_mirrors, reflector_distance_maps → planar_mirror_views →
//   reflector_cube_maps (colour where the views' searches read) → planar_mirror_reflect.
FrameOutputs add_planar_mirror_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// vertex-projection (ROGER ch.2): reflector_cube_maps → envmap_reflect (fallback); tessellate,
// reflector_param → vertex_project → reflected_triangles → vertex_projection_shade.
FrameOutputs add_vertex_projection_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// soff (SOFF §3): soff_clusters → soff_cameras → soff_depth_images → soff_intersect.
FrameOutputs add_soff_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// yu-lod (YU §3): bvh_build → radiance_bake → lod_build; glossy_rays → lod_trace → hit_radiance.
// One sample per pixel: settings.spp is N, the glossy rays per pixel.
FrameOutputs add_yu_lod_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// The same; bvh_build, radiance_bake and lod_build take what `cache` holds and fill what it
// lacks (the yu-fig9 experiment shares one scene's static data across α values).
FrameOutputs add_yu_lod_passes_cached(par::Graph& graph, const Scene* scene,
                                      const FrameSettings& settings,
                                      std::shared_ptr<trace::LodStaticData> cache);
// ray-hierarchy (ROGER §3.3): secondary_rays, then per bounce b: ray_hierarchy →
// hierarchy_traverse → shadow_rays → shade_hits (→ bounce_rays).
FrameOutputs add_ray_hierarchy_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);
// cone-tracing (ROGER ch.5): pixel_curvature → pixel_cones → cone_hierarchy →
// cone_triangle_coverage → cone_blend / cone_layer_hits, the layers shadowed, shaded and
// bounced by the ray hierarchy's passes, then cone_gather.
FrameOutputs add_cone_tracing_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

// The distance-map search of the parallax, linear, secant (0/1) and *_steps parameters.
raster::DistanceSearchOptions distance_search_options(const FrameSettings& settings);
// "layers=3 linear=16 secant=4 bounces=2": the layered map and tracer as configured.
std::string describe_layered(const FrameSettings& settings);

}  // namespace speculum::pipeline
