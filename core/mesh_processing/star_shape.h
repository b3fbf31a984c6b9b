// Star-shapedness of a reflector about a point O (ROGER §2.2.3: every point of the surface is
// seen directly from O, so the surface is one radius function r(u) over directions u). On a
// mesh: every face f satisfies s · (c_f − O) · n_f > 0 with one sign s for all faces — s = +1
// when O is behind the surface (a convex ball seen from outside), s = −1 when O is on the
// normals' side (the centre of a bowl). The centre is chosen, then checked.
#pragma once

#include <cstddef>
#include <string>

#include <glm/vec3.hpp>

#include "core/mesh_processing/halfedge_mesh.h"

namespace speculum::mesh {

struct StarShape {
  glm::dvec3 centre{0.0};
  bool star_shaped = false;
  int orientation = 0;               // +1: faces face away from O; −1: towards O; 0: mixed
  std::size_t failing_faces = 0;     // faces of the minority sign (or on a ray through O)
  std::size_t faces = 0;
  const char* centre_rule = "";      // which candidate O passed ("area centroid", ...)
};

// Faces violating s (c_f − O)·n_f > 0 for the majority sign s (a face with (c_f − O)·n_f
// within 1e-9 of its size of zero counts as failing: O lies in its plane).
StarShape star_shape_about(const HalfedgeMesh& m, const glm::dvec3& centre);

// The area-weighted centroid of the surface.
glm::dvec3 area_centroid(const HalfedgeMesh& m);

// The point nearest (least squares, area-weighted) to all face normal lines: the centre of a
// sphere or of a spherical bowl exactly, the centre of an ellipsoid by symmetry.
glm::dvec3 normal_focus(const HalfedgeMesh& m);

// Tries the normal focus (when it lies within the mesh's bounding-box diagonal of the area
// centroid), then the area centroid, and returns the first about which the mesh is
// star-shaped (or the area centroid's result, failing, if neither is).
StarShape choose_star_centre(const HalfedgeMesh& m);

}  // namespace speculum::mesh
