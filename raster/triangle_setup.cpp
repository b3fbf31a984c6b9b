// Triangle setup: see triangle_setup.h. Clipping is Sutherland–Hodgman in homogeneous clip
// space against near, far and the four guard-band planes; every intersection is computed
// from the inside vertex towards the outside one, so two triangles sharing an edge produce
// bit-identical clip points (no cracks along clipped shared edges).
#include "raster/triangle_setup.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>

#include <immintrin.h>

#include "raster/transpose8.h"

namespace speculum::raster {
namespace {

struct GuardBand {
  float gx, gy;  // guard band as a multiple of w in clip x / y
};

GuardBand guard_band(const Viewport& vp) {
  return {1.0f + 2.0f * kGuardBandPixels / static_cast<float>(vp.width),
          1.0f + 2.0f * kGuardBandPixels / static_cast<float>(vp.height)};
}

// Signed distances to the six clip planes (inside when >= 0).
inline float plane_distance(int plane, const glm::vec4& p, const GuardBand& g) {
  switch (plane) {
    case 0: return p.z + p.w;          // near
    case 1: return p.w - p.z;          // far
    case 2: return p.x + g.gx * p.w;   // guard band left
    case 3: return g.gx * p.w - p.x;   // guard band right
    case 4: return p.y + g.gy * p.w;   // guard band bottom (NDC y up)
    default: return g.gy * p.w - p.y;  // guard band top
  }
}
constexpr int kClipPlanes = 6;

// The one projection used for every vertex (shared or produced by clipping), so equal
// clip positions always snap to equal fixed-point positions.
// Returns false for a position that cannot be snapped (non-finite or far outside the guard
// band: only reachable from overflowing input coordinates), which the caller drops.
inline bool project_and_snap(const glm::vec4& clip, const Viewport& vp, std::int32_t& x,
                             std::int32_t& y, float& inv_w) {
  inv_w = 1.0f / clip.w;
  const float sx = (clip.x * inv_w * 0.5f + 0.5f) * static_cast<float>(vp.width);
  const float sy = (0.5f - clip.y * inv_w * 0.5f) * static_cast<float>(vp.height);
  constexpr float kLimit = 4.0f * kGuardBandPixels + 65536.0f;
  if (!(std::abs(sx) < kLimit && std::abs(sy) < kLimit && inv_w > 0.0f && std::isfinite(inv_w)))
    return false;
  x = static_cast<std::int32_t>(std::nearbyint(sx * static_cast<float>(kSubpixelOne)));
  y = static_cast<std::int32_t>(std::nearbyint(sy * static_cast<float>(kSubpixelOne)));
  return true;
}

// The inclusive box of pixels whose centres a triangle with these fixed-point bounds may
// cover, clamped to the viewport (empty when x0 > x1 or y0 > y1).
struct PixelBox {
  std::int32_t x0, y0, x1, y1;
  bool empty() const { return x0 > x1 || y0 > y1; }
};
inline PixelBox sample_centre_box(std::int32_t minx, std::int32_t miny, std::int32_t maxx,
                                  std::int32_t maxy, const Viewport& vp) {
  const int half = kSubpixelOne / 2;
  return {std::max<std::int32_t>(0, (minx - half + kSubpixelOne - 1) >> kSubpixelBits),
          std::max<std::int32_t>(0, (miny - half + kSubpixelOne - 1) >> kSubpixelBits),
          std::min<std::int32_t>(vp.width - 1, (maxx - half) >> kSubpixelBits),
          std::min<std::int32_t>(vp.height - 1, (maxy - half) >> kSubpixelBits)};
}

// False when the pixel box holds at most 2×2 sample centres and the triangle (vertices in
// positive-area order) covers none of them, by the rasterizer's own exact edge test and
// top-left rule (tile_rasterizer.cpp): such a triangle changes no sample, and binning and
// rasterizing it would only cost memory traffic. On the 1.02M-triangle yardstick view a quarter
// of the triangles that reach setup are such slivers between sample centres. Larger
// boxes are kept untested (true). Branch-free: the four candidate centres are always
// evaluated and masked by the box.
inline bool may_cover_a_sample(const std::int32_t (&x)[3], const std::int32_t (&y)[3],
                               const PixelBox& box) {
  const std::int64_t cx = std::int64_t(box.x0) * kSubpixelOne + kSubpixelOne / 2;
  const std::int64_t cy = std::int64_t(box.y0) * kSubpixelOne + kSubpixelOne / 2;
  const bool wide = box.x1 > box.x0, tall = box.y1 > box.y0;
  bool c00 = true, c10 = wide, c01 = tall, c11 = wide & tall;
  for (int i = 0; i < 3; ++i) {
    const int p = (i + 1) % 3, q = (i + 2) % 3;
    const std::int64_t a = std::int64_t(y[p]) - y[q], b = std::int64_t(x[q]) - x[p];
    const std::int64_t threshold = (a > 0 || (a == 0 && b > 0)) ? 0 : 1;
    // E(c) = A·c.x + B·c.y + (x_p·y_q − y_p·x_q), the same integer written about vertex p.
    const std::int64_t e00 = a * (cx - x[p]) + b * (cy - y[p]);
    const std::int64_t e10 = e00 + a * kSubpixelOne, e01 = e00 + b * kSubpixelOne;
    const std::int64_t e11 = e10 + b * kSubpixelOne;
    c00 &= e00 >= threshold, c10 &= e10 >= threshold;
    c01 &= e01 >= threshold, c11 &= e11 >= threshold;
  }
  const bool small = box.x1 - box.x0 < 2 && box.y1 - box.y0 < 2;
  return !small | c00 | c10 | c01 | c11;
}

// Emits a snapped triangle if it has area, faces the right way and covers a sample centre.
void emit(std::int32_t x0, std::int32_t y0, float w0, std::int32_t x1, std::int32_t y1, float w1,
          std::int32_t x2, std::int32_t y2, float w2, std::uint32_t triangle, std::uint32_t object,
          const Viewport& vp, int cull_sign, const ClipMap* map, std::vector<SetupTriangle>& out,
          std::vector<ClipMap>& clip_maps) {
  // area = E_01(v2); screen y points down, so OpenGL front faces (CCW in NDC) are negative.
  const std::int64_t area = (std::int64_t(y0) - y1) * x2 + (std::int64_t(x1) - x0) * y2 +
                            (std::int64_t(x0) * y1 - std::int64_t(y0) * x1);
  if (area == 0) return;
  if ((cull_sign > 0 && area > 0) || (cull_sign < 0 && area < 0)) return;
  // Pixel px is a candidate when its centre px*256+128 lies in [min, max].
  const std::int32_t minx = std::min({x0, x1, x2}), maxx = std::max({x0, x1, x2});
  const std::int32_t miny = std::min({y0, y1, y2}), maxy = std::max({y0, y1, y2});
  SetupTriangle t;
  const PixelBox box = sample_centre_box(minx, miny, maxx, maxy, vp);
  if (box.empty()) return;  // covers no sample centre
  t.px0 = std::int16_t(box.x0), t.py0 = std::int16_t(box.y0), t.px1 = std::int16_t(box.x1), t.py1 = std::int16_t(box.y1);
  t.triangle = triangle;
  t.object = object;
  const bool swap = area < 0;  // make E_i >= 0 inside
  t.x[0] = x0, t.y[0] = y0, t.inv_w[0] = w0;
  t.x[1] = swap ? x2 : x1, t.y[1] = swap ? y2 : y1, t.inv_w[1] = swap ? w2 : w1;
  t.x[2] = swap ? x1 : x2, t.y[2] = swap ? y1 : y2, t.inv_w[2] = swap ? w1 : w2;
  if (!may_cover_a_sample(t.x, t.y, box)) return;
  if (map) {
    ClipMap m = *map;
    if (swap) std::swap(m.bary[1], m.bary[2]);
    t.clip_map = static_cast<std::int32_t>(clip_maps.size());
    clip_maps.push_back(m);
    t.swapped = 0;
  } else {
    t.swapped = swap ? 1u : 0u;
  }
  out.push_back(t);
}

struct ClipVertex {
  glm::vec4 p;
  glm::vec3 b;  // barycentrics in the original triangle
};

void clip_and_emit(const ScreenVertex& v0, const ScreenVertex& v1, const ScreenVertex& v2,
                   std::uint32_t triangle, std::uint32_t object, const Viewport& vp, int cull_sign,
                   std::vector<SetupTriangle>& out, std::vector<ClipMap>& clip_maps) {
  const GuardBand g = guard_band(vp);
  // A triangle clipped by 6 planes has at most 9 vertices.
  ClipVertex poly[12], next[12];
  int n = 3;
  poly[0] = {v0.clip, {1, 0, 0}};
  poly[1] = {v1.clip, {0, 1, 0}};
  poly[2] = {v2.clip, {0, 0, 1}};
  for (int plane = 0; plane < kClipPlanes && n > 0; ++plane) {
    float d[12];
    bool any_out = false;
    for (int i = 0; i < n; ++i) {
      d[i] = plane_distance(plane, poly[i].p, g);
      any_out |= !(d[i] >= 0.0f);
    }
    if (!any_out) continue;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const int j = (i + 1) % n;
      const bool in_i = d[i] >= 0.0f, in_j = d[j] >= 0.0f;
      if (in_i) next[m++] = poly[i];
      if (in_i != in_j) {
        // Always from the inside vertex towards the outside one (canonical, see header).
        const ClipVertex& a = in_i ? poly[i] : poly[j];
        const ClipVertex& b = in_i ? poly[j] : poly[i];
        const float da = in_i ? d[i] : d[j], db = in_i ? d[j] : d[i];
        const float t = da / (da - db);
        next[m++] = {a.p + t * (b.p - a.p), a.b + t * (b.b - a.b)};
      }
    }
    n = m;
    std::copy(next, next + n, poly);
  }
  if (n < 3) return;
  std::int32_t xs[12], ys[12];
  float ws[12];
  for (int i = 0; i < n; ++i)
    if (!project_and_snap(poly[i].p, vp, xs[i], ys[i], ws[i])) return;
  for (int i = 1; i + 1 < n; ++i) {
    const ClipMap map{{poly[0].b, poly[i].b, poly[i + 1].b}};
    emit(xs[0], ys[0], ws[0], xs[i], ys[i], ws[i], xs[i + 1], ys[i + 1], ws[i + 1], triangle,
         object, vp, cull_sign, &map, out, clip_maps);
  }
}

}  // namespace

namespace {

inline ScreenVertex screen_vertex(const glm::vec4& clip, const Viewport& vp, const GuardBand& g) {
  ScreenVertex v;
  v.clip = clip;
  const float w = clip.w;
  v.outcode = (clip.x < -w ? 1u : 0u) | (clip.x > w ? 2u : 0u) | (clip.y < -w ? 4u : 0u) |
              (clip.y > w ? 8u : 0u) | (clip.z < -w ? 16u : 0u) | (clip.z > w ? 32u : 0u);
  bool inside = w > 0.0f;
  for (int plane = 0; plane < kClipPlanes && inside; ++plane)
    inside = plane_distance(plane, clip, g) >= 0.0f;
  if (!inside) {
    v.outcode |= kNeedsClip;
    return v;
  }
  if (!project_and_snap(clip, vp, v.x, v.y, v.inv_w)) v.outcode |= kNeedsClip;
  return v;
}

// 8 vertices of the vertex stage at a time: the same IEEE operations as
// `view_projection * vec4(p, 1)` (glm sums (m0·x + m1·y) + (m2·z + m3·1)), screen_vertex and
// project_and_snap, in the same order, so every field has the same bits.
inline void screen_vertices_avx2(const glm::mat4& m, const glm::vec3* p, const Viewport& vp,
                                 const GuardBand& g, ScreenVertex* out) {
  static_assert(sizeof(ScreenVertex) == 32, "8 fields of 4 bytes, transposed below");
  const float* base = &p[0].x;
  const __m256i stride = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
  const __m256 px = _mm256_i32gather_ps(base, stride, 4);
  const __m256 py = _mm256_i32gather_ps(base + 1, stride, 4);
  const __m256 pz = _mm256_i32gather_ps(base + 2, stride, 4);
  __m256 c[4];
  for (int r = 0; r < 4; ++r) {
    const __m256 xy = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(m[0][r]), px),
                                    _mm256_mul_ps(_mm256_set1_ps(m[1][r]), py));
    const __m256 zw = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(m[2][r]), pz),
                                    _mm256_mul_ps(_mm256_set1_ps(m[3][r]), _mm256_set1_ps(1.0f)));
    c[r] = _mm256_add_ps(xy, zw);
  }
  const __m256 x = c[0], y = c[1], z = c[2], w = c[3];
  const __m256 zero = _mm256_setzero_ps();
  const __m256 neg_w = _mm256_sub_ps(zero, w);
  auto bit = [](__m256 m, int b) {
    return _mm256_and_si256(_mm256_castps_si256(m), _mm256_set1_epi32(b));
  };
  __m256i outcode = _mm256_or_si256(
      _mm256_or_si256(bit(_mm256_cmp_ps(x, neg_w, _CMP_LT_OQ), 1), bit(_mm256_cmp_ps(x, w, _CMP_GT_OQ), 2)),
      _mm256_or_si256(bit(_mm256_cmp_ps(y, neg_w, _CMP_LT_OQ), 4), bit(_mm256_cmp_ps(y, w, _CMP_GT_OQ), 8)));
  outcode = _mm256_or_si256(
      outcode, _mm256_or_si256(bit(_mm256_cmp_ps(z, neg_w, _CMP_LT_OQ), 16),
                               bit(_mm256_cmp_ps(z, w, _CMP_GT_OQ), 32)));
  // Inside: w > 0 and every plane distance of plane_distance() >= 0 (false on NaN).
  const __m256 gx = _mm256_set1_ps(g.gx), gy = _mm256_set1_ps(g.gy);
  auto ge0 = [&](__m256 d) { return _mm256_cmp_ps(d, zero, _CMP_GE_OQ); };
  __m256 inside = _mm256_and_ps(_mm256_cmp_ps(w, zero, _CMP_GT_OQ),
                                _mm256_and_ps(ge0(_mm256_add_ps(z, w)), ge0(_mm256_sub_ps(w, z))));
  inside = _mm256_and_ps(inside, _mm256_and_ps(ge0(_mm256_add_ps(x, _mm256_mul_ps(gx, w))),
                                               ge0(_mm256_sub_ps(_mm256_mul_ps(gx, w), x))));
  inside = _mm256_and_ps(inside, _mm256_and_ps(ge0(_mm256_add_ps(y, _mm256_mul_ps(gy, w))),
                                               ge0(_mm256_sub_ps(_mm256_mul_ps(gy, w), y))));
  // project_and_snap.
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 inv_w = _mm256_div_ps(_mm256_set1_ps(1.0f), w);
  const __m256 sx = _mm256_mul_ps(
      _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(x, inv_w), half), half),
      _mm256_set1_ps(static_cast<float>(vp.width)));
  const __m256 sy = _mm256_mul_ps(
      _mm256_sub_ps(half, _mm256_mul_ps(_mm256_mul_ps(y, inv_w), half)),
      _mm256_set1_ps(static_cast<float>(vp.height)));
  constexpr float kLimit = 4.0f * kGuardBandPixels + 65536.0f;
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  const __m256 limit = _mm256_set1_ps(kLimit);
  const __m256 finite_inv_w = _mm256_cmp_ps(_mm256_and_ps(inv_w, abs_mask),
                                            _mm256_set1_ps(std::numeric_limits<float>::infinity()),
                                            _CMP_LT_OQ);
  const __m256 snappable = _mm256_and_ps(
      _mm256_and_ps(_mm256_cmp_ps(_mm256_and_ps(sx, abs_mask), limit, _CMP_LT_OQ),
                    _mm256_cmp_ps(_mm256_and_ps(sy, abs_mask), limit, _CMP_LT_OQ)),
      _mm256_and_ps(_mm256_cmp_ps(inv_w, zero, _CMP_GT_OQ), finite_inv_w));
  const __m256 one_sub = _mm256_set1_ps(static_cast<float>(kSubpixelOne));
  constexpr int kNearest = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;
  const __m256i fx = _mm256_cvttps_epi32(_mm256_round_ps(_mm256_mul_ps(sx, one_sub), kNearest));
  const __m256i fy = _mm256_cvttps_epi32(_mm256_round_ps(_mm256_mul_ps(sy, one_sub), kNearest));
  const __m256 snapped = _mm256_and_ps(inside, snappable);
  const __m256i snapped_i = _mm256_castps_si256(snapped);
  // Not inside: x, y, inv_w stay 0; inside but not snappable: inv_w was already written.
  const __m256 out_x = _mm256_and_ps(_mm256_castsi256_ps(fx), snapped);
  const __m256 out_y = _mm256_and_ps(_mm256_castsi256_ps(fy), snapped);
  const __m256 out_w = _mm256_and_ps(inv_w, inside);
  outcode = _mm256_or_si256(outcode,
                            _mm256_andnot_si256(snapped_i, _mm256_set1_epi32(int(kNeedsClip))));
  // 8×8 transpose: row k = the 8 fields of vertex k.
  __m256 r0 = x, r1 = y, r2 = z, r3 = w, r4 = out_x, r5 = out_y, r6 = out_w,
         r7 = _mm256_castsi256_ps(outcode);
  const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
  const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
  const __m256 t4 = _mm256_unpacklo_ps(r4, r5), t5 = _mm256_unpackhi_ps(r4, r5);
  const __m256 t6 = _mm256_unpacklo_ps(r6, r7), t7 = _mm256_unpackhi_ps(r6, r7);
  const __m256 u0 = _mm256_shuffle_ps(t0, t2, 0x44), u1 = _mm256_shuffle_ps(t0, t2, 0xee);
  const __m256 u2 = _mm256_shuffle_ps(t1, t3, 0x44), u3 = _mm256_shuffle_ps(t1, t3, 0xee);
  const __m256 u4 = _mm256_shuffle_ps(t4, t6, 0x44), u5 = _mm256_shuffle_ps(t4, t6, 0xee);
  const __m256 u6 = _mm256_shuffle_ps(t5, t7, 0x44), u7 = _mm256_shuffle_ps(t5, t7, 0xee);
  float* o = reinterpret_cast<float*>(out);
  _mm256_storeu_ps(o + 0, _mm256_permute2f128_ps(u0, u4, 0x20));
  _mm256_storeu_ps(o + 8, _mm256_permute2f128_ps(u1, u5, 0x20));
  _mm256_storeu_ps(o + 16, _mm256_permute2f128_ps(u2, u6, 0x20));
  _mm256_storeu_ps(o + 24, _mm256_permute2f128_ps(u3, u7, 0x20));
  _mm256_storeu_ps(o + 32, _mm256_permute2f128_ps(u0, u4, 0x31));
  _mm256_storeu_ps(o + 40, _mm256_permute2f128_ps(u1, u5, 0x31));
  _mm256_storeu_ps(o + 48, _mm256_permute2f128_ps(u2, u6, 0x31));
  _mm256_storeu_ps(o + 56, _mm256_permute2f128_ps(u3, u7, 0x31));
}

}  // namespace

ScreenVertex make_screen_vertex(const glm::vec4& clip, const Viewport& vp) {
  return screen_vertex(clip, vp, guard_band(vp));
}

void make_screen_vertices(const glm::mat4& view_projection, const glm::vec3* positions,
                          std::size_t count, const Viewport& vp, ScreenVertex* out) {
  const GuardBand g = guard_band(vp);
  const std::size_t wide = count / 8 * 8;
  for (std::size_t i = 0; i < wide; i += 8)
    screen_vertices_avx2(view_projection, positions + i, vp, g, out + i);
  for (std::size_t i = wide; i < count; ++i)
    out[i] = screen_vertex(view_projection * glm::vec4(positions[i], 1.0f), vp, g);
}

void setup_triangle(const ScreenVertex& v0, const ScreenVertex& v1, const ScreenVertex& v2,
                    std::uint32_t triangle, std::uint32_t object, const Viewport& vp, int cull_sign,
                    std::vector<SetupTriangle>& out, std::vector<ClipMap>& clip_maps) {
  // Trivial reject: all three vertices outside one viewport plane.
  if ((v0.outcode & v1.outcode & v2.outcode) & 0x3fu) return;
  if ((v0.outcode | v1.outcode | v2.outcode) & kNeedsClip) {
    clip_and_emit(v0, v1, v2, triangle, object, vp, cull_sign, out, clip_maps);
    return;
  }
  emit(v0.x, v0.y, v0.inv_w, v1.x, v1.y, v1.inv_w, v2.x, v2.y, v2.inv_w, triangle, object, vp,
       cull_sign, nullptr, out, clip_maps);
}

namespace {

// Helpers of setup_group8: 32-bit lanes widened to two halves of four 64-bit lanes, and
// 64-bit lane masks folded back to one bit per triangle.
inline __m256i lo64(__m256i v) { return _mm256_cvtepi32_epi64(_mm256_castsi256_si128(v)); }
inline __m256i hi64(__m256i v) { return _mm256_cvtepi32_epi64(_mm256_extracti128_si256(v, 1)); }
inline int bits64(__m256i lo, __m256i hi) {
  return _mm256_movemask_pd(_mm256_castsi256_pd(lo)) |
         _mm256_movemask_pd(_mm256_castsi256_pd(hi)) << 4;
}
inline int bits32(__m256i m) { return _mm256_movemask_ps(_mm256_castsi256_ps(m)); }
// Products of two int32 lanes (each |v| < 2^26, see setup_group8) exactly, as int64 halves.
struct Wide {
  __m256i lo, hi;
};
inline Wide mul_wide(__m256i a, __m256i b) {
  return {_mm256_mul_epi32(lo64(a), lo64(b)), _mm256_mul_epi32(hi64(a), hi64(b))};
}
inline Wide add(Wide a, Wide b) {
  return {_mm256_add_epi64(a.lo, b.lo), _mm256_add_epi64(a.hi, b.hi)};
}
inline Wide sub(Wide a, Wide b) {
  return {_mm256_sub_epi64(a.lo, b.lo), _mm256_sub_epi64(a.hi, b.hi)};
}
inline Wide widen(__m256i a) { return {lo64(a), hi64(a)}; }
inline Wide shl8(__m256i a) { return {_mm256_slli_epi64(lo64(a), 8), _mm256_slli_epi64(hi64(a), 8)}; }
// Bit l set where lane l of a > b (signed 64-bit).
inline int greater(Wide a, Wide b) {
  return bits64(_mm256_cmpgt_epi64(a.lo, b.lo), _mm256_cmpgt_epi64(a.hi, b.hi));
}

static_assert(offsetof(ScreenVertex, y) == offsetof(ScreenVertex, x) + 4 &&
              offsetof(ScreenVertex, inv_w) == offsetof(ScreenVertex, x) + 8 &&
              offsetof(ScreenVertex, outcode) == offsetof(ScreenVertex, x) + 12,
              "x, y, inv_w, outcode are loaded as one 16-byte row");
static_assert(offsetof(SetupTriangle, y) == 12 && offsetof(SetupTriangle, inv_w) == 24 &&
              offsetof(SetupTriangle, px0) == 36 && offsetof(SetupTriangle, triangle) == 44 &&
              offsetof(SetupTriangle, object) == 48 && offsetof(SetupTriangle, clip_map) == 52 &&
              offsetof(SetupTriangle, swapped) == 56 && offsetof(SetupTriangle, reserved) == 60,
              "setup_group8 assembles records as 16 dwords in this order");

// The setup of triangles t .. t+7 in 8 lanes (AVX2): the same tests and the same record bytes
// as the scalar loop of setup_triangles, with the edge and area arithmetic in exact 64-bit
// integer lanes. Every vertex of a group that reaches the arithmetic is snapped (no lane needs
// clipping), so |x|, |y| < 2^25 (project_and_snap's limit) and every difference below fits
// int32 and every product int64 exactly, as in the scalar code. Returns false, writing
// nothing, when a lane needs the scalar path (clipping or an excluded object); otherwise
// writes the 8 records to dst[n], dst[n+1], ... advancing n past the kept ones only (dst
// must have room for 8).
inline bool setup_group8(const ScreenVertex* vertices, const std::uint32_t* indices,
                         std::size_t t, const std::uint32_t* triangle_object,
                         const std::vector<std::uint8_t>& excluded, const Viewport& vp,
                         int cull_sign, SetupTriangle* dst, std::size_t& n) {
  const __m256i object = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(triangle_object + t));
  if (!excluded.empty())
    for (int l = 0; l < 8; ++l)
      if (const std::uint32_t o = triangle_object[t + l]; o < excluded.size() && excluded[o])
        return false;
  // Corner k of the 8 triangles as four 8-lane rows (x, y, inv_w, outcode).
  const std::uint32_t* idx = indices + 3 * t;
  __m256i X[3], Y[3], W[3], oc[3];
  for (int k = 0; k < 3; ++k) {
    auto row = [&](int l) {
      return _mm_loadu_ps(reinterpret_cast<const float*>(&vertices[idx[3 * l + k]].x));
    };
    const __m256 m0 = _mm256_set_m128(row(4), row(0)), m1 = _mm256_set_m128(row(5), row(1));
    const __m256 m2 = _mm256_set_m128(row(6), row(2)), m3 = _mm256_set_m128(row(7), row(3));
    const __m256 t0 = _mm256_unpacklo_ps(m0, m1), t1 = _mm256_unpackhi_ps(m0, m1);
    const __m256 t2 = _mm256_unpacklo_ps(m2, m3), t3 = _mm256_unpackhi_ps(m2, m3);
    X[k] = _mm256_castps_si256(_mm256_shuffle_ps(t0, t2, 0x44));
    Y[k] = _mm256_castps_si256(_mm256_shuffle_ps(t0, t2, 0xee));
    W[k] = _mm256_castps_si256(_mm256_shuffle_ps(t1, t3, 0x44));
    oc[k] = _mm256_castps_si256(_mm256_shuffle_ps(t1, t3, 0xee));
  }
  const __m256i zero = _mm256_setzero_si256();
  // Trivial reject (all three outside one viewport plane) comes first, as in the scalar loop.
  const int rejected =
      ~bits32(_mm256_cmpeq_epi32(
          _mm256_and_si256(_mm256_and_si256(_mm256_and_si256(oc[0], oc[1]), oc[2]),
                           _mm256_set1_epi32(0x3f)),
          zero)) & 0xff;
  const int needs_clip =
      ~bits32(_mm256_cmpeq_epi32(
          _mm256_and_si256(_mm256_or_si256(_mm256_or_si256(oc[0], oc[1]), oc[2]),
                           _mm256_set1_epi32(int(kNeedsClip))),
          zero)) & 0xff;
  if (needs_clip & ~rejected) return false;

  const __m256i minx = _mm256_min_epi32(_mm256_min_epi32(X[0], X[1]), X[2]);
  const __m256i maxx = _mm256_max_epi32(_mm256_max_epi32(X[0], X[1]), X[2]);
  const __m256i miny = _mm256_min_epi32(_mm256_min_epi32(Y[0], Y[1]), Y[2]);
  const __m256i maxy = _mm256_max_epi32(_mm256_max_epi32(Y[0], Y[1]), Y[2]);
  // Narrow group: every triangle spans at most 2^13 sub-pixels (32 pixels) a side. Then the
  // area (written about vertex 0, the same integer) is below 2^27, and the edge values at
  // the centres of a non-empty box, which lies within a pixel of the triangle's vertex box,
  // below 2^28 (|A|, |B| ≤ 2^13, |c − x_p| ≤ 2^13 + 2^8): exact in 32-bit lanes.
  const __m256i limit13 = _mm256_set1_epi32(1 << 13);
  const __m256i too_wide =
      _mm256_or_si256(_mm256_cmpgt_epi32(_mm256_sub_epi32(maxx, minx), limit13),
                      _mm256_cmpgt_epi32(_mm256_sub_epi32(maxy, miny), limit13));
  const bool narrow = _mm256_testz_si256(too_wide, too_wide);
  int positive, negative;
  if (narrow) {
    // (x1 − x0)(y2 − y0) − (y1 − y0)(x2 − x0) = E_01(v2) − E_01(v0) = E_01(v2).
    const __m256i area = _mm256_sub_epi32(
        _mm256_mullo_epi32(_mm256_sub_epi32(X[1], X[0]), _mm256_sub_epi32(Y[2], Y[0])),
        _mm256_mullo_epi32(_mm256_sub_epi32(Y[1], Y[0]), _mm256_sub_epi32(X[2], X[0])));
    positive = bits32(_mm256_cmpgt_epi32(area, zero));
    negative = bits32(_mm256_cmpgt_epi32(zero, area));
  } else {
    // area = E_01(v2) = (y0 − y1)·x2 + (x1 − x0)·y2 + (x0·y1 − y0·x1), exactly.
    const Wide area = add(add(mul_wide(_mm256_sub_epi32(Y[0], Y[1]), X[2]),
                              mul_wide(_mm256_sub_epi32(X[1], X[0]), Y[2])),
                          sub(mul_wide(X[0], Y[1]), mul_wide(Y[0], X[1])));
    const Wide zero64{zero, zero};
    positive = greater(area, zero64), negative = greater(zero64, area);
  }
  const int culled = cull_sign > 0 ? positive : cull_sign < 0 ? negative : 0;

  // The pixel box of sample_centre_box.
  const int half = kSubpixelOne / 2;
  const __m256i up = _mm256_set1_epi32(kSubpixelOne - 1 - half), down = _mm256_set1_epi32(half);
  const __m256i bx0 = _mm256_max_epi32(zero, _mm256_srai_epi32(_mm256_add_epi32(minx, up), kSubpixelBits));
  const __m256i by0 = _mm256_max_epi32(zero, _mm256_srai_epi32(_mm256_add_epi32(miny, up), kSubpixelBits));
  const __m256i bx1 = _mm256_min_epi32(_mm256_set1_epi32(vp.width - 1),
                                       _mm256_srai_epi32(_mm256_sub_epi32(maxx, down), kSubpixelBits));
  const __m256i by1 = _mm256_min_epi32(_mm256_set1_epi32(vp.height - 1),
                                       _mm256_srai_epi32(_mm256_sub_epi32(maxy, down), kSubpixelBits));
  const int empty = bits32(_mm256_or_si256(_mm256_cmpgt_epi32(bx0, bx1), _mm256_cmpgt_epi32(by0, by1)));

  // Vertices 1 and 2 exchanged where the area is negative (E_i ≥ 0 inside).
  const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  const __m256i swap = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(negative), lane_bit), lane_bit);
  auto pick = [&](__m256i a, __m256i b) { return _mm256_blendv_epi8(a, b, swap); };
  const __m256i x[3] = {X[0], pick(X[1], X[2]), pick(X[2], X[1])};
  const __m256i y[3] = {Y[0], pick(Y[1], Y[2]), pick(Y[2], Y[1])};
  const __m256i w[3] = {W[0], pick(W[1], W[2]), pick(W[2], W[1])};

  // may_cover_a_sample: the box's (up to) four centres against the exact edge test.
  const __m256i one = _mm256_set1_epi32(kSubpixelOne);
  const __m256i cx = _mm256_add_epi32(_mm256_mullo_epi32(bx0, one), down);
  const __m256i cy = _mm256_add_epi32(_mm256_mullo_epi32(by0, one), down);
  const int wide = bits32(_mm256_cmpgt_epi32(bx1, bx0)), tall = bits32(_mm256_cmpgt_epi32(by1, by0));
  const __m256i two = _mm256_set1_epi32(2);
  const int small = bits32(_mm256_and_si256(_mm256_cmpgt_epi32(two, _mm256_sub_epi32(bx1, bx0)),
                                            _mm256_cmpgt_epi32(two, _mm256_sub_epi32(by1, by0))));
  int c00 = 0xff, c10 = wide, c01 = tall, c11 = wide & tall;
  for (int i = 0; i < 3; ++i) {
    const int p = (i + 1) % 3, q = (i + 2) % 3;
    const __m256i a = _mm256_sub_epi32(y[p], y[q]), b = _mm256_sub_epi32(x[q], x[p]);
    // E ≥ threshold ⟺ E > threshold − 1, which is −1 (all ones) on a top or left edge, else 0.
    const __m256i top_left = _mm256_or_si256(
        _mm256_cmpgt_epi32(a, zero),
        _mm256_and_si256(_mm256_cmpeq_epi32(a, zero), _mm256_cmpgt_epi32(b, zero)));
    if (narrow) {  // lanes with an empty box may wrap around: they are dropped below
      const __m256i e00 = _mm256_add_epi32(_mm256_mullo_epi32(a, _mm256_sub_epi32(cx, x[p])),
                                           _mm256_mullo_epi32(b, _mm256_sub_epi32(cy, y[p])));
      const __m256i a8 = _mm256_slli_epi32(a, kSubpixelBits), b8 = _mm256_slli_epi32(b, kSubpixelBits);
      const __m256i e10 = _mm256_add_epi32(e00, a8), e01 = _mm256_add_epi32(e00, b8);
      const __m256i e11 = _mm256_add_epi32(e10, b8);
      c00 &= bits32(_mm256_cmpgt_epi32(e00, top_left)), c10 &= bits32(_mm256_cmpgt_epi32(e10, top_left));
      c01 &= bits32(_mm256_cmpgt_epi32(e01, top_left)), c11 &= bits32(_mm256_cmpgt_epi32(e11, top_left));
      continue;
    }
    const Wide limit = widen(top_left);
    const Wide e00 = add(mul_wide(a, _mm256_sub_epi32(cx, x[p])), mul_wide(b, _mm256_sub_epi32(cy, y[p])));
    const Wide a8 = shl8(a), b8 = shl8(b);
    const Wide e10 = add(e00, a8), e01 = add(e00, b8), e11 = add(e10, b8);
    c00 &= greater(e00, limit), c10 &= greater(e10, limit);
    c01 &= greater(e01, limit), c11 &= greater(e11, limit);
  }
  const int may_cover = ~small | c00 | c10 | c01 | c11;
  const int keep = ~rejected & (positive | negative) & ~culled & ~empty & may_cover & 0xff;

  // The records, 16 dwords each (layout asserted above), transposed out of the lanes.
  const __m256i mask16 = _mm256_set1_epi32(0xffff);
  const __m256i box_lo = _mm256_or_si256(_mm256_and_si256(bx0, mask16), _mm256_slli_epi32(by0, 16));
  const __m256i box_hi = _mm256_or_si256(_mm256_and_si256(bx1, mask16), _mm256_slli_epi32(by1, 16));
  const __m256i tri = _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(t)),
                                       _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  const __m256i first[8] = {x[0], x[1], x[2], y[0], y[1], y[2], w[0], w[1]};
  const __m256i second[8] = {w[2],   box_lo, box_hi, tri, object, _mm256_set1_epi32(-1),
                             _mm256_srli_epi32(swap, 31), zero};
  __m256i a[8], b[8];
  detail::transpose8(first, a);
  detail::transpose8(second, b);
  for (int l = 0; l < 8; ++l) {
    __m256i* r = reinterpret_cast<__m256i*>(dst + n);
    _mm256_store_si256(r, a[l]);
    _mm256_store_si256(r + 1, b[l]);
    n += (keep >> l) & 1;
  }
  return true;
}

}  // namespace

std::size_t setup_triangles(const ScreenVertex* vertices, const std::uint32_t* indices,
                            std::size_t begin, std::size_t end,
                            const std::uint32_t* triangle_object,
                            const std::vector<std::uint8_t>& excluded, const Viewport& vp,
                            int cull_sign, std::size_t first, std::vector<SetupTriangle>& out,
                            std::vector<ClipMap>& clip_maps) {
  // Room for one triangle per remaining input; only clipping can emit more.
  std::size_t n = first;
  if (out.size() < n + (end - begin)) out.resize(n + (end - begin));
  SetupTriangle* dst = out.data();
  // One triangle in scalar code: the reference for setup_group8, and the path of groups with
  // a clipped or excluded triangle and of the last few triangles.
  auto one = [&](std::size_t t) {
    const std::uint32_t object = triangle_object[t];
    if (!excluded.empty() && object < excluded.size() && excluded[object]) return;
    const std::uint32_t* idx = &indices[3 * t];
    const ScreenVertex& v0 = vertices[idx[0]];
    const ScreenVertex& v1 = vertices[idx[1]];
    const ScreenVertex& v2 = vertices[idx[2]];
    if ((v0.outcode & v1.outcode & v2.outcode) & 0x3fu) return;
    if ((v0.outcode | v1.outcode | v2.outcode) & kNeedsClip) {
      // Clipped pieces go through a small side buffer, so `out` only grows (never shrinks
      // and re-initializes its tail) and only when a triangle yields more than one piece.
      thread_local std::vector<SetupTriangle> pieces;
      pieces.clear();
      clip_and_emit(v0, v1, v2, static_cast<std::uint32_t>(t), object, vp, cull_sign, pieces,
                    clip_maps);
      const std::size_t need = n + pieces.size() + (end - t - 1);
      if (need > out.size()) {
        out.resize(need);
        dst = out.data();
      }
      std::copy(pieces.begin(), pieces.end(), dst + n);
      n += pieces.size();
      return;
    }
    // emit() without branches on the outcome: the record is always written at dst[n] and
    // kept by advancing n (random small triangles made those branches unpredictable).
    const std::int32_t x0 = v0.x, y0 = v0.y, x1 = v1.x, y1 = v1.y, x2 = v2.x, y2 = v2.y;
    const std::int64_t area = (std::int64_t(y0) - y1) * x2 + (std::int64_t(x1) - x0) * y2 +
                              (std::int64_t(x0) * y1 - std::int64_t(y0) * x1);
    const std::int32_t minx = std::min({x0, x1, x2}), maxx = std::max({x0, x1, x2});
    const std::int32_t miny = std::min({y0, y1, y2}), maxy = std::max({y0, y1, y2});
    SetupTriangle& r = dst[n];
    const PixelBox box = sample_centre_box(minx, miny, maxx, maxy, vp);
    r.px0 = std::int16_t(box.x0), r.py0 = std::int16_t(box.y0), r.px1 = std::int16_t(box.x1), r.py1 = std::int16_t(box.y1);
    const bool swap = area < 0;
    r.x[0] = x0, r.y[0] = y0, r.inv_w[0] = v0.inv_w;
    r.x[1] = swap ? x2 : x1, r.y[1] = swap ? y2 : y1, r.inv_w[1] = swap ? v2.inv_w : v1.inv_w;
    r.x[2] = swap ? x1 : x2, r.y[2] = swap ? y1 : y2, r.inv_w[2] = swap ? v1.inv_w : v2.inv_w;
    r.triangle = static_cast<std::uint32_t>(t);
    r.object = object;
    r.clip_map = -1;
    r.swapped = swap ? 1u : 0u;
    r.reserved = 0;
    const bool culled = (cull_sign > 0 && area > 0) || (cull_sign < 0 && area < 0);
    const bool keep = (area != 0) & !culled & (box.x0 <= box.x1) & (box.y0 <= box.y1) &
                      may_cover_a_sample(r.x, r.y, box);
    n += keep ? 1 : 0;
  };
  std::size_t t = begin;
  for (; t + 8 <= end; t += 8)
    if (!setup_group8(vertices, indices, t, triangle_object, excluded, vp, cull_sign, dst, n))
      for (std::size_t k = t; k < t + 8; ++k) one(k);
  for (; t < end; ++t) one(t);
  return n;
}

}  // namespace speculum::raster
