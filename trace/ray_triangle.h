// Watertight ray–triangle intersection (Woop, Benthin, Wald, "Watertight Ray/Triangle
// Intersection", JCGT 2013): shear the triangle into ray space so the 2-D edge tests are
// evaluated identically for the two triangles sharing an edge, and fall back to double
// precision when an edge function is exactly zero. No ray slips through a shared edge or
// vertex (SURVEY §2 "ray tracing in original geometry" needs this of every structure).
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>

#include <glm/vec3.hpp>

namespace speculum::trace {

// The per-ray precomputation of the watertight test.
struct RayShear {
  glm::vec3 origin;
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;

  RayShear() = default;
  RayShear(const glm::vec3& o, const glm::vec3& d) : origin(o) {
    const glm::vec3 ad(std::fabs(d.x), std::fabs(d.y), std::fabs(d.z));
    kz = (ad.x > ad.y) ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) std::swap(kx, ky);  // keep the winding so the signs mean the same
    // One division: the shear only has to be the same for every triangle a ray meets
    // (that is what makes the test watertight), not the correctly rounded quotient.
    sz = 1.0f / d[kz];
    sx = d[kx] * sz;
    sy = d[ky] * sz;
  }
};

// A candidate hit: distance along the (unnormalized) direction and barycentrics of b, c.
struct TriangleHit {
  float t, u, v;
};

// Intersects triangle (a, b, c), both faces; accepts t in [tmin, tmax]. Returns true and
// fills `hit` when hit.
inline bool intersect_triangle_watertight(const RayShear& r, const glm::vec3& a, const glm::vec3& b,
                                          const glm::vec3& c, float tmin, float tmax,
                                          TriangleHit& hit) {
  const glm::vec3 A = a - r.origin, B = b - r.origin, C = c - r.origin;
  const float ax = A[r.kx] - r.sx * A[r.kz], ay = A[r.ky] - r.sy * A[r.kz];
  const float bx = B[r.kx] - r.sx * B[r.kz], by = B[r.ky] - r.sy * B[r.kz];
  const float cx = C[r.kx] - r.sx * C[r.kz], cy = C[r.ky] - r.sy * C[r.kz];
  float U = cx * by - cy * bx;
  float V = ax * cy - ay * cx;
  float W = bx * ay - by * ax;
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    // An edge function rounded to exactly zero: its sign is decided in double, where the
    // products of floats are exact.
    U = static_cast<float>(double(cx) * double(by) - double(cy) * double(bx));
    V = static_cast<float>(double(ax) * double(cy) - double(ay) * double(cx));
    W = static_cast<float>(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  const float az = r.sz * A[r.kz], bz = r.sz * B[r.kz], cz = r.sz * C[r.kz];
  const float T = U * az + V * bz + W * cz;
  // The range test uses the divided t (not T against t*det): rounding then cannot make the
  // accept decision differ from the t that is reported and compared across structures.
  const float inv = 1.0f / det;
  const float t = T * inv;
  if (!(t >= tmin && t <= tmax)) return false;
  hit.t = t;
  hit.u = V * inv;
  hit.v = W * inv;
  return true;
}

}  // namespace speculum::trace
