// Distance impostors of refractors (SURVEY §4.4): each refractor's own surface rendered
// from its centre into a cube map of outward normal (in the colour faces) and distance, so
// the exit point of a refracted ray is found by the distance-map search
// (distance_map_search.h) from inside, and its normal is looked up in the same direction.
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"
#include "raster/distance_map_search.h"

namespace speculum::raster {



struct RefractorImpostors {
  std::vector<int> impostor_of_object;  // -1: not a refractor
  std::vector<CubeMap> cubes;           // colour rgb = outward unit normal; distance |y − o|
  const CubeMap* for_object(std::uint32_t object) const {
    if (object >= impostor_of_object.size() || impostor_of_object[object] < 0) return nullptr;
    return &cubes[static_cast<std::size_t>(impostor_of_object[object])];
  }
};

// One cube of `size`² per refractor, centred at its bounding-box centre, the refractor
// alone. The method assumes every surface point is visible from the centre (star-shaped).
// `mirrors`: also one per mirror object (a caustic generator's own surface, where a photon
// leaving it may meet it again).
RefractorImpostors render_refractor_impostors(par::Executor& executor, const Scene& scene, int size,
                                              bool mirrors = false);

// The exit of a ray inside the refractor: from world point p1 along unit t1. Returns false
// when the search finds nothing (the ray start is then kept).
bool find_impostor_exit(const CubeMap& impostor, const glm::vec3& p1, const glm::vec3& t1,
                        const DistanceSearchOptions& options, glm::vec3& p2, glm::vec3& n2);

// Pass "refractor_impostors": one normal + distance cube per refractor.
struct RefractorImpostorsPass {
  static constexpr const char* description =
      "Each refractor alone from its centre: normal + distance cube map searched for the exit "
      "point (distance impostors, SURVEY §4.4).";
  const Scene* scene = nullptr;
  int size = 128;
  bool mirrors = false;  // mirror objects too (render_refractor_impostors)
  void parameters(par::Params& p) const { p.set("size", size).set("mirrors", mirrors ? 1 : 0); }
  RefractorImpostors operator()(par::NodeContext& c) const;
};

}  // namespace speculum::raster
