// The `distance_map_reflect` node: SURVEY §4.2 localized reflections — each specular sample
// of a reflector searches its reflector's colour + distance cube map (distance_map_search.h)
// along R (and T for refractors, single interface) and looks the found hit direction up in
// the map's prefiltered colour (glossy: the level of its Phong lobe), weighted by Schlick's
// Fresnel exactly like envmap_reflect. Samples of objects without a map use the environment.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/vec3.hpp>

#include "core/fallback_mask.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/distance_map_search.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"

namespace speculum::raster {

struct DistanceReflectStats {
  std::uint64_t searches = 0;  // searched rays (R and T)
  std::uint64_t lookups = 0;   // distance-map reads over all searches
  std::uint64_t bracketed = 0; // searches whose linear search found an undershoot/overshoot pair
  std::uint64_t missed = 0;    // searches that found no surface: read along the ray (environment)
  DistanceReflectStats& operator+=(const DistanceReflectStats& o) {
    searches += o.searches, lookups += o.lookups, bracketed += o.bracketed, missed += o.missed;
    return *this;
  }
};

// A glossy lobe is searched along `directions` sub-lobe axes (a fixed Hamersley set of a
// Phong lobe of exponent 4n/3, each read at 4n; see distance_map_reflect.cpp). Their
// directions in the lobe's own frame depend on n alone: kept for the last n asked, as a
// chunk's glossy samples mostly share one material.
class SubLobeAxes {
 public:
  explicit SubLobeAxes(int directions) : local_(static_cast<std::size_t>(std::max(directions, 0))) {}
  int count() const { return static_cast<int>(local_.size()); }
  // count() directions, valid until the next call.
  const glm::vec3* operator()(float exponent);

 private:
  float exponent_ = std::numeric_limits<float>::quiet_NaN();
  std::vector<glm::vec3> local_;
};

// The specular layer (zero on diffuse samples). Works on any G-buffer, including a cube
// face's (eye = the face centre), which is how multi-reflection shades reflectors seen in
// other reflectors' maps. `stats` (may be null) is summed in chunk order; `fallbacks` (may
// be null or empty: nothing is marked) marks the samples with a search that missed.
ImageRGBA distance_map_reflect(par::Executor& executor, const GBuffer& g,
                               const EnvironmentMap& env, const ReflectorMaps& maps,
                               const DistanceSearchOptions& options,
                               DistanceReflectStats* stats = nullptr, FallbackMask* fallbacks = nullptr);

// distance_map_reflect in two halves, so that the maps' colour is shaded only where the
// searches read it: distance_map_search searches the maps' distances (rendered with
// MapSizing::keep_visibility and without colour) and records, per chunk of samples in sample
// order, the direction each search reads colour along, and per map the tiles those reads
// reach; shade_reflector_maps shades those tiles; distance_map_lookup reads the colour along
// the recorded directions. The same bytes as distance_map_reflect on maps shaded whole.
struct DistanceSearches {
  std::vector<std::vector<glm::vec3>> found;  // per chunk of samples: each search's direction
  std::vector<CubeTileMask> tiles;            // per map: the tiles the reads reach
  DistanceReflectStats stats;
};
// `mark_into` (may be null): the reads' tiles are marked there (masks of `maps`, from
// tile_mask_for_reads) instead of in the result's own `tiles`, which then stay empty.
DistanceSearches distance_map_search(par::Executor& executor, const GBuffer& g, const ReflectorMaps& maps,
                                     const DistanceSearchOptions& options, FallbackMask* fallbacks = nullptr,
                                     std::vector<CubeTileMask>* mark_into = nullptr);
// distance_map_search of g taking, for the samples it would also search with the object ids
// `earlier_object` (kNoId: uncovered) in place of its own, the directions `earlier` found
// (distance_map_search of g so changed, in the same maps with the same options): the same
// result, with only the other samples searched (and counted in its stats).
DistanceSearches distance_map_search_reusing(par::Executor& executor, const GBuffer& g, const ReflectorMaps& maps,
                                             const DistanceSearchOptions& options, const IdBuffer& earlier_object,
                                             const DistanceSearches& earlier,
                                             std::vector<CubeTileMask>* mark_into = nullptr);
ImageRGBA distance_map_lookup(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                              const ReflectorMaps& maps, const DistanceSearches& searches,
                              const DistanceSearchOptions& options);

// Pass "distance_map_reflect": the specular layer searched in the reflectors' distance maps.
struct DistanceMapReflectPass {
  static constexpr const char* description =
      "Parallax (eq.4) / linear (§4.1.2) / secant (eq.5) search per specular sample in its "
      "reflector's colour + distance cube map, Fresnel-weighted (SURVEY §4.1).";
  DistanceSearchOptions search;
  void parameters(par::Params& p) const { p.set("search", describe_search(search)); }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const EnvironmentMap& environment,
                       const ReflectorMaps& maps) const;
};

// Pass "distance_map_search": distance_map_search over the reflectors' distances.
struct DistanceMapSearchPass {
  static constexpr const char* description =
      "Parallax (eq.4) / linear (§4.1.2) / secant (eq.5) search per specular sample in its "
      "reflector's distance cube map; records where each search reads colour, and the map tiles "
      "those reads reach (SURVEY §4.1).";
  DistanceSearchOptions search;
  void parameters(par::Params& p) const { p.set("search", describe_search(search)); }
  DistanceSearches operator()(par::NodeContext& c, const GBuffer& gbuffer, const ReflectorMaps& maps) const;
};

// Pass "distance_map_reflect" after distance_map_search: each search's colour read from the
// shaded maps, Fresnel-weighted (distance_map_lookup).
struct DistanceMapLookupPass {
  static constexpr const char* description =
      "Reads each search's hit in its reflector's prefiltered colour cube map, Fresnel-weighted "
      "(SURVEY §4.1–4.2).";
  DistanceSearchOptions search;
  void parameters(par::Params& p) const { p.set("lobe_directions", search.lobe_directions); }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const EnvironmentMap& environment,
                       const ReflectorMaps& maps, const DistanceSearches& searches) const;
};

}  // namespace speculum::raster
