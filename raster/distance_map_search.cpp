// The distance-map search on a cube map: see distance_map_search.h.
#include "raster/distance_map_search.h"

namespace speculum::raster {

DistanceSearchResult search_distance_map(const CubeMap& map, const glm::vec3& x_world,
                                         const glm::vec3& r, const DistanceSearchOptions& options) {
  return search_distance([&](const glm::vec3& d) { return map.distance_towards(d); },
                         x_world - map.centre, r, options);
}

std::string describe_search(const DistanceSearchOptions& o) {
  return "parallax=" + (o.parallax ? std::to_string(o.parallax_steps) : std::string("off")) +
         " linear=" + (o.linear ? std::to_string(o.linear_steps) : std::string("off")) +
         " secant=" + (o.secant ? std::to_string(o.secant_steps) : std::string("off")) +
         " lobe=" + std::to_string(o.lobe_directions);
}

}  // namespace speculum::raster
