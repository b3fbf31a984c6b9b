// Per-vertex mean curvature by the cotangent Laplace–Beltrami operator with mixed Voronoi
// areas (Meyer, Desbrun, Schröder, Barr 2003, "Discrete differential-geometry operators"):
// Δx_i = 1/(2 A_i) Σ_j (cot α_ij + cot β_ij)(x_j − x_i) = −2 H_i n_i. The sign follows the
// vertex normal: H > 0 where the surface bends away from its normal (the outside of a
// sphere, 1/r), H < 0 on the inside of a bowl seen along its normals.
#pragma once

#include <vector>

#include "core/mesh_processing/halfedge_mesh.h"
#include "core/scene.h"

namespace speculum::mesh {

// One value per mesh vertex. Boundary vertices (an open surface's rim, where the operator
// sees only half a ring) take the mean of their interior neighbours' values, or 0 if none.
std::vector<double> mean_curvature(const HalfedgeMesh& m);

// True for vertices on a boundary (no value of their own in mean_curvature).
std::vector<bool> boundary_vertices(const HalfedgeMesh& m);

// Mean curvature per soup vertex of `scene` (every object welded by position, so uv and
// normal seams do not open the ring): what a G-buffer interpolates per pixel with the
// triangle's barycentrics, as it does normals. Objects with non-manifold faces still get
// values from the faces that could be added; unused vertices get 0.
std::vector<float> scene_mean_curvature(const Scene& scene);

// The value at a point of soup triangle `triangle` with barycentrics (b1, b2) (b0 = 1 − b1 −
// b2, as a visibility buffer stores them): how a G-buffer reads `per_vertex` per pixel.
inline float interpolate_at(const TriangleMesh& soup, const std::vector<float>& per_vertex,
                            std::uint32_t triangle, float b1, float b2) {
  const std::uint32_t* i = &soup.indices[3 * std::size_t(triangle)];
  return (1.0f - b1 - b2) * per_vertex[i[0]] + b1 * per_vertex[i[1]] + b2 * per_vertex[i[2]];
}

}  // namespace speculum::mesh
