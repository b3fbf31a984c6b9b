// The prepared ray and the one-box slab test of the threaded layout, shared by the plain
// threaded traversal (trace/traversal.cpp) and YU's LOD traversal (trace/lod_trace.cpp): with
// LOD off the two must return the same hits bit for bit.
#pragma once

#include <utility>

#include "core/camera_rays.h"
#include "trace/bvh.h"
#include "trace/ray_triangle.h"
#include "trace/wide_kernels.h"

namespace speculum::trace::scalar {

constexpr float kFarWiden = 1.0f + 8.0f * 5.96e-8f;   // > 1 + 2 gamma(3)
constexpr float kNearShrink = 1.0f - 8.0f * 5.96e-8f;  // the same margin on the entry side

struct RayPrep {
  glm::vec3 o, d, inv;
  float tmin, tmax;
  RayShear shear;
  bool has_zero;  // some direction component is exactly zero: see box_hit
  explicit RayPrep(const Ray& r)
      : o(r.origin), d(r.direction), inv(wide::safe_inverse(r.direction)), tmin(r.tmin), tmax(r.tmax),
        shear(r.origin, r.direction), has_zero(r.direction.x == 0.0f || r.direction.y == 0.0f || r.direction.z == 0.0f) {}
};

using wide::valid_ray;

// On an axis the ray does not move along (d = 0), the slab is all of t when the origin lies in
// [lo, hi] (faces included) and empty otherwise. The plane distances would get this wrong
// for an origin exactly on a face: (plane - o) * inv = 0 makes the slab end at t = 0, and
// the ray (tmin > 0) missed boxes it grazes at box seams.
inline bool box_hit(const RayPrep& r, const Aabb& b, float tmax, float& tnear) {
  float t0 = r.tmin, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    if (r.has_zero && r.d[a] == 0.0f) {
      if (r.o[a] >= b.lo[a] && r.o[a] <= b.hi[a]) continue;
      tnear = t0;
      return false;
    }
    float lo = (b.lo[a] - r.o[a]) * r.inv[a];
    float hi = (b.hi[a] - r.o[a]) * r.inv[a];
    if (lo > hi) std::swap(lo, hi);
    lo = lo > 0.0f ? lo * kNearShrink : lo * kFarWiden;
    t0 = lo > t0 ? lo : t0;
    t1 = hi * kFarWiden < t1 ? hi * kFarWiden : t1;
  }
  tnear = t0;
  return t0 <= t1 && !b.empty();
}

}  // namespace speculum::trace::scalar
