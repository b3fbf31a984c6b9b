// Cone–triangle coverage (see cone_coverage.h; ROGER §5.2.5, Fig.5.8–5.9, eq.5.9–5.10).
#include "trace/cone_coverage.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

namespace speculum::trace {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Inside the counter-clockwise triangle (closed, with a relative tolerance).
bool in_triangle(const glm::dvec2 p[3], const glm::dvec2& q, double tol) {
  for (int k = 0; k < 3; ++k)
    if (cross2(p[(k + 1) % 3] - p[k], q - p[k]) < -tol) return false;
  return true;
}

struct BoundaryPoint {
  glm::dvec2 p;
  bool exit = false;  // an exit crossing: the boundary continues along the arc from here
};

}  // namespace

DiscCoverage disc_triangle_coverage(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  DiscCoverage out;
  glm::dvec2 p[3] = {a, b, c};
  const double twice_area = cross2(b - a, c - a);
  if (!(std::fabs(twice_area) > 0.0)) return out;
  if (twice_area < 0.0) std::swap(p[1], p[2]);  // counter-clockwise from here on
  const double scale = std::max({glm::length(p[0]), glm::length(p[1]), glm::length(p[2]), 1.0});
  const double tol = 1e-12 * scale * scale;
  bool in[3];
  for (int k = 0; k < 3; ++k) in[k] = glm::dot(p[k], p[k]) <= 1.0;

  // The boundary of triangle ∩ disc in counter-clockwise order: vertices inside, and the
  // crossings of each edge with the circle (an inside→outside edge exits once, an outside→
  // inside edge enters once, an outside→outside edge enters and exits or misses).
  std::array<BoundaryPoint, 9> pts;
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec2 s = p[k], e = p[(k + 1) % 3], d = e - s;
    if (in[k]) {
      pts[n++] = {s, false};
      ++out.inside;
    }
    const bool in_e = in[(k + 1) % 3];
    if (in[k] && in_e) continue;
    const double A = glm::dot(d, d), B = glm::dot(s, d), C = glm::dot(s, s) - 1.0;
    const double disc = B * B - A * C;
    const double sq = std::sqrt(std::max(disc, 0.0));
    // The two roots by the stable formula (no cancellation between −B and ±sq).
    const double q = B >= 0.0 ? -(B + sq) : -(B - sq);
    double t1 = q / A, t2 = q != 0.0 ? C / q : t1;
    if (t1 > t2) std::swap(t1, t2);
    if (in[k]) {  // exits
      pts[n++] = {s + std::clamp(t2, 0.0, 1.0) * d, true};
      ++out.crossings;
    } else if (in_e) {  // enters
      pts[n++] = {s + std::clamp(t1, 0.0, 1.0) * d, false};
      ++out.crossings;
    } else if (disc > 0.0 && t1 > 0.0 && t2 < 1.0) {  // passes through
      pts[n++] = {s + t1 * d, false};
      pts[n++] = {s + t2 * d, true};
      out.crossings += 2;
    }
  }

  if (n == 0) {  // no vertex inside, no crossing: the disc is inside the triangle, or apart
    if (in_triangle(p, glm::dvec2(0.0), tol)) out.area = kPi;
    return out;
  }
  // The polygon of boundary points (shoelace area and first moments).
  double area = 0.0;
  glm::dvec2 moment(0.0);
  for (int k = 0; k < n; ++k) {
    const glm::dvec2 u = pts[k].p, v = pts[(k + 1) % n].p;
    const double w = cross2(u, v);
    area += 0.5 * w;
    moment += (w / 6.0) * (u + v);
  }
  // A circular segment on every exit → next-entry chord: the arc runs counter-clockwise from
  // the exit to the entry, inside the triangle.
  for (int k = 0; k < n; ++k) {
    if (!pts[k].exit) continue;
    const glm::dvec2 e0 = pts[k].p, e1 = pts[(k + 1) % n].p;
    const double a0 = std::atan2(e0.y, e0.x);
    double theta = std::atan2(cross2(e0, e1), glm::dot(e0, e1));
    if (theta < 0.0) theta += kTwoPi;
    // Near 0 and 2π rounding decides between an empty and a full arc: the full arc's middle
    // (opposite the exit) is inside the triangle only if the arc really goes round.
    if (theta < 1e-6 || theta > kTwoPi - 1e-6)
      theta = in_triangle(p, -e0 / std::max(glm::length(e0), 1e-300), tol) ? kTwoPi - std::min(theta, kTwoPi - theta)
                                                                          : std::min(theta, kTwoPi - theta);
    const double seg = 0.5 * (theta - std::sin(theta));
    if (!(seg > 0.0)) continue;
    const double h = std::sin(0.5 * theta);
    const double dist = (2.0 / 3.0) * h * h * h / seg;  // eq.5.10 with sin³
    const double mid = a0 + 0.5 * theta;
    area += seg;
    moment += seg * dist * glm::dvec2(std::cos(mid), std::sin(mid));
  }
  out.area = std::clamp(area, 0.0, kPi);
  out.centroid = area > 0.0 ? moment / area : glm::dvec2(0.0);
  return out;
}

namespace {

// Sutherland–Hodgman against s >= lo (sign +1) or s <= hi (sign −1) on 3-D points with their
// axial distance.
struct ClipPoint {
  glm::dvec3 x;
  double s;
};

int clip_polygon(const ClipPoint* in, int n, double bound, double sign, ClipPoint* out) {
  int m = 0;
  for (int k = 0; k < n; ++k) {
    const ClipPoint& a = in[k];
    const ClipPoint& b = in[(k + 1) % n];
    const double da = sign * (a.s - bound), db = sign * (b.s - bound);
    if (da >= 0.0) out[m++] = a;
    if ((da >= 0.0) != (db >= 0.0)) {
      const double t = da / (da - db);
      out[m++] = {a.x + t * (b.x - a.x), bound};
    }
  }
  return m;
}

}  // namespace

bool cone_triangle_coverage(const Cone& cone, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                            ConeTriangleHit& hit) {
  const glm::dvec3 o(cone.origin), d(cone.axis);
  // An orthonormal frame of the axis (Duff et al. 2017's branchless basis).
  const double sgn = std::copysign(1.0, d.z);
  const double ka = -1.0 / (sgn + d.z), kb = d.x * d.y * ka;
  const glm::dvec3 e1(1.0 + sgn * d.x * d.x * ka, sgn * kb, -sgn * d.x);
  const glm::dvec3 e2(kb, sgn + d.y * d.y * ka, -d.y);
  const glm::dvec3 v[3] = {glm::dvec3(a) - o, glm::dvec3(b) - o, glm::dvec3(c) - o};
  ClipPoint poly[3], near_clip[4], both[5];
  for (int k = 0; k < 3; ++k) poly[k] = {v[k], glm::dot(v[k], d)};
  const double near = cone.near, far = cone.far;
  if (std::max({poly[0].s, poly[1].s, poly[2].s}) < near) return false;
  if (std::min({poly[0].s, poly[1].s, poly[2].s}) > far) return false;
  const int n1 = clip_polygon(poly, 3, near, 1.0, near_clip);
  const int n2 = clip_polygon(near_clip, n1, far, -1.0, both);
  if (n2 < 3) return false;
  const double w = cone.radius, ta = cone.tan_angle;
  glm::dvec2 q[5];
  for (int k = 0; k < n2; ++k) {
    const double R = w + both[k].s * ta;
    if (!(R > 0.0)) return false;
    q[k] = glm::dvec2(glm::dot(both[k].x, e1), glm::dot(both[k].x, e2)) / R;
  }
  double area = 0.0;
  glm::dvec2 moment(0.0);
  for (int k = 1; k + 1 < n2; ++k) {
    const DiscCoverage part = disc_triangle_coverage(q[0], q[k], q[k + 1]);
    area += part.area;
    moment += part.area * part.centroid;
  }
  if (!(area > 0.0)) return false;
  const glm::dvec2 cen = moment / area;
  // The point of the triangle's plane on the line through the centroid: X(s) = o + s d +
  // (w + s tan) (x e1 + y e2), solved for n·(X − a) = 0.
  const glm::dvec3 qd = cen.x * e1 + cen.y * e2;
  const glm::dvec3 nrm = glm::cross(v[1] - v[0], v[2] - v[0]);
  const double den = glm::dot(nrm, d) + ta * glm::dot(nrm, qd);
  double s = both[0].s;
  if (std::fabs(den) > 1e-300) s = (glm::dot(nrm, v[0]) - w * glm::dot(nrm, qd)) / den;
  const glm::dvec3 x = s * d + (w + s * ta) * qd;
  // Barycentrics of x (clamped into the triangle: the centroid of a convex part of it lies
  // inside it, up to rounding).
  const glm::dvec3 e01 = v[1] - v[0], e02 = v[2] - v[0], px = x - v[0];
  const double d00 = glm::dot(e01, e01), d01 = glm::dot(e01, e02), d11 = glm::dot(e02, e02);
  const double d20 = glm::dot(px, e01), d21 = glm::dot(px, e02);
  const double det = d00 * d11 - d01 * d01;
  double bu = 1.0 / 3.0, bv = 1.0 / 3.0;
  if (det > 0.0) {
    bu = (d11 * d20 - d01 * d21) / det;
    bv = (d00 * d21 - d01 * d20) / det;
  }
  bu = std::clamp(bu, 0.0, 1.0);
  bv = std::clamp(bv, 0.0, 1.0 - bu);
  const glm::dvec3 xb = v[0] + bu * e01 + bv * e02;
  hit.coverage = float(std::min(area / kPi, 1.0));
  hit.distance = float(glm::length(xb));
  hit.u = float(bu);
  hit.v = float(bv);
  return hit.coverage > 0.0f;
}

}  // namespace speculum::trace
