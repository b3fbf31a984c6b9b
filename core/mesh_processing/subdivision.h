// Subdivision of OpenMesh meshes: uniform schemes by OpenMesh's own subdividers (Loop, √3),
// and splitting edges longer than a target length (longest first, as OpenMesh's
// LongestEdgeT) carrying normals and uvs to the new vertices, so rasterizing a projected
// triangle linearly stays accurate (ROGER §2.3.4: a long untessellated bar reflects straight).
#pragma once

#include <cstddef>

#include "core/mesh_processing/halfedge_mesh.h"

namespace speculum::mesh {

enum class Scheme : std::uint8_t { Loop, Sqrt3 };

// `levels` rounds of the scheme (Loop: 4× faces per round; √3: 3×). Moves points (both are
// approximating schemes: the surface shrinks towards the limit surface); normals are
// recomputed, uvs of new vertices are not interpolated (geometry only).
void subdivide_uniform(HalfedgeMesh& m, Scheme scheme, int levels);

struct SplitReport {
  std::size_t splits = 0;
  bool vertex_budget_reached = false;  // stopped at max_vertices with edges still too long
};

// Splits, longest first, every edge longer than `max_edge` at its midpoint until none is or
// the mesh has `max_vertices` vertices. New vertices lie on the original surface (midpoints
// of its edges); their normal is the normalized mean and uv the mean of the edge's ends.
SplitReport split_long_edges(HalfedgeMesh& m, double max_edge, std::size_t max_vertices);

}  // namespace speculum::mesh
