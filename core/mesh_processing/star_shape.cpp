// Star-shapedness test and centre choice (see star_shape.h).
#include "core/mesh_processing/star_shape.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace speculum::mesh {

namespace {

struct FaceGeometry {
  glm::dvec3 centroid;
  glm::dvec3 normal;  // unit
  double area;
};

template <class F>
void for_faces(const HalfedgeMesh& m, F&& f) {
  for (const auto fh : m.faces()) {
    glm::dvec3 p[3];
    int k = 0;
    for (const auto vh : m.fv_range(fh)) p[k++] = to_glm(m.point(vh));
    const glm::dvec3 c = glm::cross(p[1] - p[0], p[2] - p[0]);
    const double l = glm::length(c);
    if (!(l > 0.0)) continue;
    f(FaceGeometry{(p[0] + p[1] + p[2]) / 3.0, c / l, 0.5 * l});
  }
}

}  // namespace

StarShape star_shape_about(const HalfedgeMesh& m, const glm::dvec3& centre) {
  StarShape s;
  s.centre = centre;
  std::size_t positive = 0, negative = 0, zero = 0;
  for_faces(m, [&](const FaceGeometry& f) {
    ++s.faces;
    const double d = glm::dot(f.centroid - centre, f.normal);
    if (std::fabs(d) <= 1e-9 * std::sqrt(f.area)) ++zero;
    else if (d > 0.0) ++positive;
    else ++negative;
  });
  s.orientation = positive >= negative ? 1 : -1;
  s.failing_faces = zero + (positive >= negative ? negative : positive);
  s.star_shaped = s.faces > 0 && s.failing_faces == 0;
  if (!s.star_shaped) s.orientation = 0;
  return s;
}

glm::dvec3 area_centroid(const HalfedgeMesh& m) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for_faces(m, [&](const FaceGeometry& f) {
    sum += f.area * f.centroid;
    area += f.area;
  });
  return area > 0.0 ? sum / area : sum;
}

glm::dvec3 normal_focus(const HalfedgeMesh& m) {
  // Minimize Σ a_f |(I − n nᵀ)(x − c_f)|²: (Σ a_f (I − n nᵀ)) x = Σ a_f (I − n nᵀ) c_f.
  glm::dmat3 a(0.0);
  glm::dvec3 b(0.0);
  for_faces(m, [&](const FaceGeometry& f) {
    const glm::dmat3 p = glm::dmat3(1.0) - glm::outerProduct(f.normal, f.normal);
    a += f.area * p;
    b += f.area * (p * f.centroid);
  });
  const double det = glm::determinant(a);
  const double scale = a[0][0] + a[1][1] + a[2][2];
  // Parallel normals (a plane) leave the system singular: no focus, use the centroid.
  if (!(std::fabs(det) > 1e-12 * scale * scale * scale)) return area_centroid(m);
  return glm::inverse(a) * b;
}

StarShape choose_star_centre(const HalfedgeMesh& m) {
  const glm::dvec3 centroid = area_centroid(m);
  Bounds b;
  for (const auto vh : m.vertices()) b.grow(glm::vec3(to_glm(m.point(vh))));
  const double diagonal = glm::length(glm::dvec3(b.extent()));
  // The normal focus first: from the centre of a sphere or bowl every ray meets the surface
  // head-on (r constant, ∇ln r = 0), where from the centroid of a bowl the rim is grazing.
  // Not when it lies farther than the mesh's size (a nearly flat mirror): seen from there the
  // surface spans a narrow cone of directions.
  const glm::dvec3 focus = normal_focus(m);
  if (glm::length(focus - centroid) <= diagonal) {
    StarShape f = star_shape_about(m, focus);
    f.centre_rule = "normal focus";
    if (f.star_shaped) return f;
  }
  StarShape s = star_shape_about(m, centroid);
  s.centre_rule = "area centroid";
  return s;
}

}  // namespace speculum::mesh
