// The two-face refraction method's per-vertex thickness d_N (SURVEY §4.4): for every vertex
// of a refractor, the distance along −N to the refractor's other side, by BVH ray casts over
// the refractor triangles.
#pragma once

#include <vector>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"

namespace speculum::trace {

// Per mesh vertex of a refractor, the distance along −N to the refractor's other side; 0 for
// other vertices and for rays that hit nothing.
std::vector<float> refractor_vertex_thickness(const Scene& scene, par::Executor& executor);

// Pass "refractor_thickness".
struct RefractorThicknessPass {
  static constexpr const char* description =
      "Per-vertex thickness d_N along −N by BVH ray casts (two-face method, SURVEY §4.4).";
  const Scene* scene = nullptr;
  std::vector<float> operator()(par::NodeContext& c) const {
    return refractor_vertex_thickness(*scene, c.executor());
  }
};

}  // namespace speculum::trace
