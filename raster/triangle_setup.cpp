// Triangle setup: see triangle_setup.h. Clipping is Sutherland–Hodgman in homogeneous clip
// space against near, far and the four guard-band planes; every intersection is computed
// from the inside vertex towards the outside one, so two triangles sharing an edge produce
// bit-identical clip points (no cracks along clipped shared edges).
#include "raster/triangle_setup.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <immintrin.h>

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
  for (std::size_t t = begin; t < end; ++t) {
    const std::uint32_t object = triangle_object[t];
    if (!excluded.empty() && object < excluded.size() && excluded[object]) continue;
    const std::uint32_t* idx = &indices[3 * t];
    const ScreenVertex& v0 = vertices[idx[0]];
    const ScreenVertex& v1 = vertices[idx[1]];
    const ScreenVertex& v2 = vertices[idx[2]];
    if ((v0.outcode & v1.outcode & v2.outcode) & 0x3fu) continue;
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
      continue;
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
  }
  return n;
}

}  // namespace speculum::raster
