// Inter-object multiple reflections (SURVEY §4.3): every specular
// object's colour + distance cube map is re-rendered with the reflectors it sees shaded by
// a distance-map search in the *current* maps of the others, so each round adds one
// bounce. Rounds are Jacobi-style (all maps of round k read round k−1's), which makes a
// round exactly one bounce and makes the frame-lagged variant (one round per frame from
// the previous frame's maps) equal to the same number of in-frame rounds.
#pragma once

#include <vector>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/distance_map_reflect.h"
#include "raster/environment.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

// One round: the maps of `current` re-rendered at the same reference points and sizes,
// reflectors in view shaded by direct light + distance_map_reflect(current). With `layers`
// (those render_reflector_maps kept for the maps of `current`, in map order) the faces'
// direct light and specular texels come from there and the distances from `current`: the
// same bytes without rasterizing, resolving and lighting the faces again. With layers,
// `faces_needed` (bit f per map, may be null) limits the faces searched, composited and
// prefiltered to those a reader reaches; the others are black (ReflectorMaps::faces).
ReflectorMaps rerender_reflector_maps(par::Executor& executor, const Scene& scene,
                                      const std::vector<ShadowMap>& shadows,
                                      const EnvironmentMap& env, const ReflectorMaps& current,
                                      const DistanceSearchOptions& options,
                                      DistanceReflectStats* stats = nullptr,
                                      const std::vector<MapFaceLayers>* layers = nullptr,
                                      const std::vector<unsigned>* faces_needed = nullptr);

// `rounds` ≥ 1 rounds: round 1 is render_reflector_maps (direct light only: one bounce
// once looked up from the camera), each further round one rerender.
ReflectorMaps render_multi_reflection_maps(par::Executor& executor, const Scene& scene,
                                           const std::vector<ShadowMap>& shadows,
                                           const EnvironmentMap& env, int size,
                                           const GBuffer* camera_view, int rounds,
                                           const DistanceSearchOptions& options,
                                           DistanceReflectStats* stats = nullptr);

// render_multi_reflection_maps shaded only where read: `distances` (all reflectors' maps,
// rendered with MapSizing::keep_visibility) and the camera's searches in them (`camera`, from
// distance_map_search) give, from the last round back, the tiles each round's maps are read
// on — the camera's, then those the specular texels on round k's read tiles reach with their
// searches in round k − 1 — and each round is shaded and prefiltered on its tiles alone, the
// direct light once on every tile any round reads. distance_map_lookup(camera) on the result
// gives the bytes distance_map_reflect gives on render_multi_reflection_maps(rounds).
// `stats` counts the searches made (those of texels no round reads are not).
ReflectorMaps render_multi_reflection_maps_where_read(par::Executor& executor, const Scene& scene,
                                                      const std::vector<ShadowMap>& shadows,
                                                      const EnvironmentMap& env, const ReflectorMaps& distances,
                                                      const DistanceSearches& camera, int rounds,
                                                      const DistanceSearchOptions& options,
                                                      DistanceReflectStats* stats = nullptr);

// Pass "multi_reflection_maps" after the camera's searches (render_multi_reflection_maps_where_read).
struct MultiReflectionWhereReadPass {
  static constexpr const char* description =
      "Per specular object a colour cube map, re-rendered in rounds with the others' current maps, "
      "one bounce per round, each round shaded only where the next one (or the camera) reads it "
      "(SURVEY §4.3).";
  const Scene* scene = nullptr;
  int rounds = 3;
  DistanceSearchOptions search;
  void parameters(par::Params& p) const { p.set("rounds", rounds).set("tiles", "read by the next round's searches"); }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows, const EnvironmentMap& environment,
                           const ReflectorMaps& distances, const DistanceSearches& camera) const;
};

// Pass "multi_reflection_maps": the reflector maps after `rounds` rounds (SURVEY §4.3); with
// `lagged`, one round per frame on the previous frame's maps (the bounce depth grows by one
// per frame), or a first round when there is no previous frame.
struct MultiReflectionMapsPass {
  static constexpr const char* description =
      "Per specular object a colour + distance cube map, re-rendered in rounds with the others' "
      "current maps, one bounce per round (SURVEY §4.3).";
  const Scene* scene = nullptr;
  int size = 256;
  int rounds = 3;
  bool lagged = false;
  DistanceSearchOptions search;
  void parameters(par::Params& p) const {
    p.set("size", size).set("rounds", lagged ? 1 : rounds).set("lagged", lagged ? 1 : 0);
  }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows,
                           const EnvironmentMap& environment, const GBuffer& gbuffer,
                           const ReflectorMaps* previous) const;
};

}  // namespace speculum::raster
