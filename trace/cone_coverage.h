// The cone–triangle intersection of ROGER §5.2.5: the exact area of a triangle ∩ the unit
// disc (the cone's cross-section after projection), the centroid of that region, and the
// 3-D cone–triangle coverage built on it (near-plane clipping, projection onto the plane
// orthogonal to the axis, scaling to the unit disc).
#pragma once

#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace speculum::trace {

// Triangle ∩ unit disc centred at the origin. `inside` (vertices within the disc,
// |v| <= 1) and `crossings` (edge–circle crossings) name the case of ROGER Fig.5.8: (0,0),
// (0,2), (0,4), (0,6), (1,2), (1,4), (2,2), (3,0). The region is split into the convex
// polygon of its boundary points (vertices inside, crossings in boundary order) and one
// circular segment per arc of the circle between an exit and the next entry: segment area
// (θ − sin θ)/2 (eq.5.9), centroid at 4 sin³(θ/2) / (3(θ − sin θ)) from O towards the arc's
// midpoint (eq.5.10 with the exponent 3, not 3/2: the area moment of a segment is
// (2/3) sin³(θ/2)), and the parts combined by area (associativity of the barycentre).
struct DiscCoverage {
  double area = 0.0;              // in [0, π]
  glm::dvec2 centroid{0.0, 0.0};  // meaningful when area > 0
  int inside = 0, crossings = 0;
};
DiscCoverage disc_triangle_coverage(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c);

// One pixel's cone (ROGER §5.2.2): the axis ray from `origin` along unit `axis`, radius
// `radius` at the origin growing by `tan_angle` per unit of axial distance (the cone's apex
// lies `radius / tan_angle` behind the origin), cut by the near plane at axial distance
// `near` and the far plane at `far`.
struct Cone {
  glm::vec3 origin{0.0f}, axis{0.0f, 0.0f, 1.0f};
  float radius = 0.0f, tan_angle = 0.0f;
  float near = 0.0f, far = 3.4e38f;
};

// What one triangle gives one cone: the fraction of the cross-section disc it covers, and the
// point of the triangle seen along the centroid of that region (barycentrics u, v as the
// watertight test returns them, and its distance from the cone's origin).
struct ConeTriangleHit {
  float coverage = 0.0f;
  float distance = 0.0f;
  float u = 0.0f, v = 0.0f;
};

// The triangle (a, b, c) clipped to the slab near <= s <= far (s = axial distance), each
// clipped vertex projected to ρ / (radius + s tan_angle) (ρ its offset from the axis in an
// orthonormal frame of it: the central projection from the apex, scaled so the cone's
// cross-section is the unit disc), the clipped polygon fanned into triangles and each
// intersected with the disc. False when nothing of the triangle is in the cone. Requires
// radius + near · tan_angle > 0 (a cone of zero width is a ray: test it as one).
bool cone_triangle_coverage(const Cone& cone, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                            ConeTriangleHit& hit);

}  // namespace speculum::trace
