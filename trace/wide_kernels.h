// The hot kernels of 8-wide BVH traversal (bvh.h) written with AVX2 intrinsics (the build
// targets x86-64-v3): 8 child boxes against one ray, the order of the entered children, and
// the watertight triangle test (ray_triangle.h) on a 4-triangle pack. Why not Lanes<W>:
// these loops need shuffles, blends on sign bits and masks as integers, which the lanes do
// not offer (over fixed_size simd they also emitted out-of-line min/max calls, ~1/3 of
// traversal time). The two tests keep the exact operation sequence of their scalar
// definitions (slab test widened as in Ize 2013; watertight test of Woop et al. 2013), so
// results are bit-identical.
#pragma once

#include <immintrin.h>

#if !defined(__AVX2__) || !defined(__FMA__)
#error "trace/wide_kernels.h needs AVX2: configure with SPECULUM_ISA=x86-64-v3 (default), x86-64-v4 or native"
#endif

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "core/camera_rays.h"
#include "trace/bvh.h"
#include "trace/ray_triangle.h"

namespace speculum::trace::wide {

constexpr float kWiden = 8.0f * 5.96e-8f;  // relative margin (> 2 gamma(3)) on entry and exit

// A ray every traversal accepts: non-zero finite direction, finite origin, tmin <= tmax.
inline bool valid_ray(const Ray& r) {
  const glm::vec3& d = r.direction;
  return (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && std::isfinite(d.x) && std::isfinite(d.y) &&
         std::isfinite(d.z) && std::isfinite(r.origin.x) && std::isfinite(r.origin.y) &&
         std::isfinite(r.origin.z) && !(r.tmin > r.tmax);
}

// 1/d per component; a zero component becomes a huge reciprocal instead of inf, so
// (lo-o)*inv is never 0*inf = NaN: the slab then spans everything or nothing.
inline glm::vec3 safe_inverse(const glm::vec3& d) {
  glm::vec3 inv;
  for (int a = 0; a < 3; ++a) {
    const float c = std::fabs(d[a]) < 1e-30f ? std::copysign(1e-30f, d[a]) : d[a];
    inv[a] = 1.0f / c;
  }
  return inv;
}

// True when some direction component is so small that safe_inverse clamps it.
inline bool has_clamped_axis(const glm::vec3& d) {
  return std::fabs(d.x) < 1e-30f || std::fabs(d.y) < 1e-30f || std::fabs(d.z) < 1e-30f;
}

// A ray prepared for the box kernel: broadcast origin and reciprocal direction, and the
// byte offsets of the near/far planes in a WideNode picked by the direction's signs.
// On an axis the ray does not move along (clamped reciprocal), an origin exactly on a box
// plane would give (plane - o) * inv = 0 and cull the box; there the near and far planes
// see the origin moved outward by a relative 2^-20 (at least 2^-60), so the slab spans
// everything (or nothing) as it should. Other axes use the origin unchanged.
struct BoxRay {
  __m256 onx, ony, onz, ofx, ofy, ofz, ix, iy, iz, tmin;
  std::uint32_t near_x, near_y, near_z, far_x, far_y, far_z;

  BoxRay(const glm::vec3& o, const glm::vec3& d, const glm::vec3& inv, float t0) {
    glm::vec3 on = o, of = o, slope = inv;
    for (int a = 0; a < 3; ++a) {
      if (!(std::fabs(d[a]) < 1e-30f)) continue;
      const float delta = std::copysign(std::max(std::fabs(o[a]) * 0x1p-20f, 0x1p-60f), inv[a]);
      on[a] = o[a] + delta;
      of[a] = o[a] - delta;
      // The largest finite slope, not the clamped 1e30: the slab then reaches past any
      // distance a ray can have (a plane 0.15 away gave an end at 1.5e29 with 1e30; now it
      // overflows to inf, which box_hits clamps), and (plane - o') * slope is never 0 · inf.
      slope[a] = std::copysign(std::numeric_limits<float>::max(), inv[a]);
    }
    onx = _mm256_set1_ps(on.x); ony = _mm256_set1_ps(on.y); onz = _mm256_set1_ps(on.z);
    ofx = _mm256_set1_ps(of.x); ofy = _mm256_set1_ps(of.y); ofz = _mm256_set1_ps(of.z);
    ix = _mm256_set1_ps(slope.x); iy = _mm256_set1_ps(slope.y); iz = _mm256_set1_ps(slope.z);
    tmin = _mm256_set1_ps(t0);
    constexpr std::uint32_t row = kWideArity * sizeof(float), hi = 3 * row;
    const bool nx = std::signbit(inv.x), ny = std::signbit(inv.y), nz = std::signbit(inv.z);
    near_x = nx ? hi : 0;
    far_x = nx ? 0 : hi;
    near_y = row + (ny ? hi : 0);
    far_y = row + (ny ? 0 : hi);
    near_z = 2 * row + (nz ? hi : 0);
    far_z = 2 * row + (nz ? 0 : hi);
  }
};

// Bit k set when child k's box is entered within [tmin, tmax]; tnear gets the (widened)
// entry distances. An empty child's inverted box yields entry > exit (finite after the
// clamp, so the widening never forms inf - inf).
[[gnu::always_inline]] inline unsigned box_hits(const WideNode& n, const BoxRay& r, float tmax, __m256& tnear) {
  const char* base = reinterpret_cast<const char*>(&n);
  auto plane = [base](std::uint32_t off) { return _mm256_load_ps(reinterpret_cast<const float*>(base + off)); };
  const __m256 nx = _mm256_mul_ps(_mm256_sub_ps(plane(r.near_x), r.onx), r.ix);
  const __m256 ny = _mm256_mul_ps(_mm256_sub_ps(plane(r.near_y), r.ony), r.iy);
  const __m256 nz = _mm256_mul_ps(_mm256_sub_ps(plane(r.near_z), r.onz), r.iz);
  const __m256 fx = _mm256_mul_ps(_mm256_sub_ps(plane(r.far_x), r.ofx), r.ix);
  const __m256 fy = _mm256_mul_ps(_mm256_sub_ps(plane(r.far_y), r.ofy), r.iy);
  const __m256 fz = _mm256_mul_ps(_mm256_sub_ps(plane(r.far_z), r.ofz), r.iz);
  const __m256 big = _mm256_set1_ps(3.0e38f), eps = _mm256_set1_ps(kWiden);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 entry = _mm256_min_ps(_mm256_max_ps(_mm256_max_ps(nx, ny), nz), big);
  const __m256 exit = _mm256_max_ps(_mm256_min_ps(_mm256_min_ps(fx, fy), fz), _mm256_sub_ps(_mm256_setzero_ps(), big));
  const __m256 near = _mm256_max_ps(_mm256_sub_ps(entry, _mm256_mul_ps(_mm256_and_ps(entry, abs_mask), eps)), r.tmin);
  const __m256 far = _mm256_min_ps(_mm256_add_ps(exit, _mm256_mul_ps(_mm256_and_ps(exit, abs_mask), eps)),
                                   _mm256_set1_ps(tmax));
  tnear = near;
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ)));
}

// One compare-exchange step of a sorting network on 8 unsigned lanes: each lane meets
// its partner; the lanes in kMinLanes keep the smaller key, the others the larger.
template <int kMinLanes>
[[gnu::always_inline]] inline __m256i compare_exchange(__m256i x, __m256i partner) {
  return _mm256_blend_epi32(_mm256_max_epu32(x, partner), _mm256_min_epu32(x, partner), kMinLanes);
}

// A node's entered children sorted far to near in one register, for a traversal that
// pushes them onto a stack in one store: each key is the child's entry distance made an
// order-preserving unsigned integer (sign flipped for positive floats, all bits for
// negative ones) with its lane in the low 3 bits; children not entered get key 0 and sort
// last. Dropping 3 mantissa bits only reorders children whose entries differ by less
// than 2^-20 relative: the order is a heuristic, the closest hit does not depend on it.
// Lanes 0..hits-1 of the result hold the entered children's lanes, farthest first.
[[gnu::always_inline]] inline __m256i order_far_to_near(unsigned bits, __m256 tnear) {
  const __m256i b = _mm256_castps_si256(tnear);
  const __m256i flip = _mm256_or_si256(_mm256_srai_epi32(b, 31), _mm256_set1_epi32(INT32_MIN));
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i key = _mm256_or_si256(_mm256_andnot_si256(_mm256_set1_epi32(7), _mm256_xor_si256(b, flip)), lane);
  const __m256i entered = _mm256_cmpgt_epi32(
      _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128)),
      _mm256_setzero_si256());
  __m256i x = _mm256_and_si256(key, entered);
  // Bitonic network of 8 (6 compare-exchange steps), larger keys to lower lanes.
  x = compare_exchange<0xaa>(x, _mm256_shuffle_epi32(x, _MM_SHUFFLE(2, 3, 0, 1)));
  x = compare_exchange<0xcc>(x, _mm256_shuffle_epi32(x, _MM_SHUFFLE(0, 1, 2, 3)));
  x = compare_exchange<0xaa>(x, _mm256_shuffle_epi32(x, _MM_SHUFFLE(2, 3, 0, 1)));
  x = compare_exchange<0xf0>(x, _mm256_permutevar8x32_epi32(x, _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0)));
  x = compare_exchange<0xcc>(x, _mm256_shuffle_epi32(x, _MM_SHUFFLE(1, 0, 3, 2)));
  x = compare_exchange<0xaa>(x, _mm256_shuffle_epi32(x, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm256_and_si256(x, _mm256_set1_epi32(7));
}

// Byte offsets into a TrianglePack: the block of vertex v (a, b, c: 0, 1, 2) and, within it,
// the row of axis a (x, y, z: 0, 1, 2); lane l is 4 l bytes further.
constexpr std::uint32_t pack_vertex_offset(std::uint32_t v) { return v * 3u * sizeof(float[4]); }
constexpr std::uint32_t pack_axis_offset(int a) { return static_cast<std::uint32_t>(a) * sizeof(float[4]); }
static_assert(offsetof(TrianglePack, by) == pack_vertex_offset(1) + pack_axis_offset(1));
static_assert(offsetof(TrianglePack, cz) == pack_vertex_offset(2) + pack_axis_offset(2));

// A ray prepared for the pack kernel: the watertight shear (axis permutation as byte
// offsets into a TrianglePack, shear factors and origin broadcast).
struct PackRay {
  const RayShear* shear;
  __m128 okx, oky, okz, sx, sy, sz;
  std::uint32_t offx, offy, offz;  // byte offset of the kx/ky/kz row within a vertex block

  explicit PackRay(const RayShear& s) : shear(&s) {
    okx = _mm_set1_ps(s.origin[s.kx]); oky = _mm_set1_ps(s.origin[s.ky]); okz = _mm_set1_ps(s.origin[s.kz]);
    sx = _mm_set1_ps(s.sx); sy = _mm_set1_ps(s.sy); sz = _mm_set1_ps(s.sz);
    offx = pack_axis_offset(s.kx);
    offy = pack_axis_offset(s.ky);
    offz = pack_axis_offset(s.kz);
  }
};

// Lanes of pack p hit in [tmin, tmax] (bit mask) with their t, u, v. Same operation
// sequence as intersect_triangle_watertight; a lane whose edge function is exactly zero
// (or a product that underflows: a harmless false alarm) is redone by the scalar test,
// which owns the double-precision fallback.
[[gnu::always_inline]] inline unsigned intersect_pack(const TrianglePack& p, const PackRay& r, float tmin, float tmax,
                                                      float (&t)[4], float (&u)[4], float (&v)[4]) {
  const char* base = reinterpret_cast<const char*>(&p);
  auto row = [base](std::uint32_t vertex, std::uint32_t off) {
    return _mm_load_ps(reinterpret_cast<const float*>(base + pack_vertex_offset(vertex) + off));
  };
  const __m128 Akx = _mm_sub_ps(row(0, r.offx), r.okx), Aky = _mm_sub_ps(row(0, r.offy), r.oky),
               Akz = _mm_sub_ps(row(0, r.offz), r.okz);
  const __m128 Bkx = _mm_sub_ps(row(1, r.offx), r.okx), Bky = _mm_sub_ps(row(1, r.offy), r.oky),
               Bkz = _mm_sub_ps(row(1, r.offz), r.okz);
  const __m128 Ckx = _mm_sub_ps(row(2, r.offx), r.okx), Cky = _mm_sub_ps(row(2, r.offy), r.oky),
               Ckz = _mm_sub_ps(row(2, r.offz), r.okz);
  const __m128 ax = _mm_sub_ps(Akx, _mm_mul_ps(r.sx, Akz)), ay = _mm_sub_ps(Aky, _mm_mul_ps(r.sy, Akz));
  const __m128 bx = _mm_sub_ps(Bkx, _mm_mul_ps(r.sx, Bkz)), by = _mm_sub_ps(Bky, _mm_mul_ps(r.sy, Bkz));
  const __m128 cx = _mm_sub_ps(Ckx, _mm_mul_ps(r.sx, Ckz)), cy = _mm_sub_ps(Cky, _mm_mul_ps(r.sy, Ckz));
  const __m128 U = _mm_sub_ps(_mm_mul_ps(cx, by), _mm_mul_ps(cy, bx));
  const __m128 V = _mm_sub_ps(_mm_mul_ps(ax, cy), _mm_mul_ps(ay, cx));
  const __m128 W = _mm_sub_ps(_mm_mul_ps(bx, ay), _mm_mul_ps(by, ax));
  const __m128 zero = _mm_setzero_ps();
  const __m128 mn = _mm_min_ps(_mm_min_ps(U, V), W), mx = _mm_max_ps(_mm_max_ps(U, V), W);
  // Same-sign edge functions (NaN lanes of unused slots fail both compares).
  const __m128 inside = _mm_or_ps(_mm_cmp_ps(mn, zero, _CMP_GE_OQ), _mm_cmp_ps(mx, zero, _CMP_LE_OQ));
  if (_mm_movemask_ps(inside) == 0) return 0;
  const int zero_edge = _mm_movemask_ps(_mm_cmp_ps(_mm_mul_ps(_mm_mul_ps(U, V), W), zero, _CMP_EQ_OQ));
  const __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
  const __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, _mm_mul_ps(r.sz, Akz)), _mm_mul_ps(V, _mm_mul_ps(r.sz, Bkz))),
                              _mm_mul_ps(W, _mm_mul_ps(r.sz, Ckz)));
  const __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
  const __m128 tt = _mm_mul_ps(T, inv);
  if (!zero_edge) {
    // det == 0 needs no test: with mixed signs excluded it gives t = ±inf or NaN, which
    // fails the range test.
    const __m128 ok = _mm_and_ps(inside, _mm_and_ps(_mm_cmp_ps(tt, _mm_set1_ps(tmin), _CMP_GE_OQ),
                                                    _mm_cmp_ps(tt, _mm_set1_ps(tmax), _CMP_LE_OQ)));
    const unsigned bits = static_cast<unsigned>(_mm_movemask_ps(ok));
    if (bits) {
      _mm_storeu_ps(t, tt);
      _mm_storeu_ps(u, _mm_mul_ps(V, inv));
      _mm_storeu_ps(v, _mm_mul_ps(W, inv));
    }
    return bits;
  }
  alignas(16) float Us[4], Vs[4], Ws[4], dets[4], ts[4], invs[4];
  _mm_store_ps(Us, U); _mm_store_ps(Vs, V); _mm_store_ps(Ws, W);
  _mm_store_ps(dets, det); _mm_store_ps(ts, tt); _mm_store_ps(invs, inv);
  unsigned bits = 0;
  for (int l = 0; l < 4; ++l) {
    if (p.id[l] == kEmptyChild) continue;
    if (Us[l] == 0.0f || Vs[l] == 0.0f || Ws[l] == 0.0f) {
      TriangleHit h;
      const glm::vec3 A(p.ax[l], p.ay[l], p.az[l]), B(p.bx[l], p.by[l], p.bz[l]), C(p.cx[l], p.cy[l], p.cz[l]);
      if (intersect_triangle_watertight(*r.shear, A, B, C, tmin, tmax, h)) {
        t[l] = h.t; u[l] = h.u; v[l] = h.v;
        bits |= 1u << l;
      }
      continue;
    }
    const bool neg = Us[l] < 0.0f || Vs[l] < 0.0f || Ws[l] < 0.0f;
    const bool pos = Us[l] > 0.0f || Vs[l] > 0.0f || Ws[l] > 0.0f;
    if ((neg && pos) || dets[l] == 0.0f) continue;
    if (!(ts[l] >= tmin && ts[l] <= tmax)) continue;
    t[l] = ts[l];
    u[l] = Vs[l] * invs[l];
    v[l] = Ws[l] * invs[l];
    bits |= 1u << l;
  }
  return bits;
}

}  // namespace speculum::trace::wide
