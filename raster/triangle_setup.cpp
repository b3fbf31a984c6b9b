// Triangle setup: see triangle_setup.h. Clipping is Sutherland–Hodgman in homogeneous clip
// space against near, far and the four guard-band planes; every intersection is computed
// from the inside vertex towards the outside one, so two triangles sharing an edge produce
// bit-identical clip points (no cracks along clipped shared edges).
#include "raster/triangle_setup.h"

#include <algorithm>
#include <cmath>
#include <utility>

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

// Emits a snapped triangle if it has area, faces the right way and covers a sample centre.
void emit(std::int32_t x0, std::int32_t y0, float w0, std::int32_t x1, std::int32_t y1, float w1,
          std::int32_t x2, std::int32_t y2, float w2, std::uint32_t triangle, const Viewport& vp,
          int cull_sign, const ClipMap* map, std::vector<SetupTriangle>& out,
          std::vector<ClipMap>& clip_maps) {
  // area = E_01(v2); screen y points down, so OpenGL front faces (CCW in NDC) are negative.
  const std::int64_t area = (std::int64_t(y0) - y1) * x2 + (std::int64_t(x1) - x0) * y2 +
                            (std::int64_t(x0) * y1 - std::int64_t(y0) * x1);
  if (area == 0) return;
  if ((cull_sign > 0 && area > 0) || (cull_sign < 0 && area < 0)) return;
  const int half = kSubpixelOne / 2;
  // Pixel px is a candidate when its centre px*256+128 lies in [min, max].
  const std::int32_t minx = std::min({x0, x1, x2}), maxx = std::max({x0, x1, x2});
  const std::int32_t miny = std::min({y0, y1, y2}), maxy = std::max({y0, y1, y2});
  SetupTriangle t;
  t.px0 = std::max<std::int32_t>(0, (minx - half + kSubpixelOne - 1) >> kSubpixelBits);
  t.py0 = std::max<std::int32_t>(0, (miny - half + kSubpixelOne - 1) >> kSubpixelBits);
  t.px1 = std::min<std::int32_t>(vp.width - 1, (maxx - half) >> kSubpixelBits);
  t.py1 = std::min<std::int32_t>(vp.height - 1, (maxy - half) >> kSubpixelBits);
  if (t.px0 > t.px1 || t.py0 > t.py1) return;  // covers no sample centre
  t.triangle = triangle;
  const bool swap = area < 0;  // make E_i >= 0 inside
  t.x[0] = x0, t.y[0] = y0, t.inv_w[0] = w0;
  t.x[1] = swap ? x2 : x1, t.y[1] = swap ? y2 : y1, t.inv_w[1] = swap ? w2 : w1;
  t.x[2] = swap ? x1 : x2, t.y[2] = swap ? y1 : y2, t.inv_w[2] = swap ? w1 : w2;
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
                   std::uint32_t triangle, const Viewport& vp, int cull_sign,
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
    emit(xs[0], ys[0], ws[0], xs[i], ys[i], ws[i], xs[i + 1], ys[i + 1], ws[i + 1], triangle, vp,
         cull_sign, &map, out, clip_maps);
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

}  // namespace

ScreenVertex make_screen_vertex(const glm::vec4& clip, const Viewport& vp) {
  return screen_vertex(clip, vp, guard_band(vp));
}

void make_screen_vertices(const glm::mat4& view_projection, const glm::vec3* positions,
                          std::size_t count, const Viewport& vp, ScreenVertex* out) {
  const GuardBand g = guard_band(vp);
  for (std::size_t i = 0; i < count; ++i)
    out[i] = screen_vertex(view_projection * glm::vec4(positions[i], 1.0f), vp, g);
}

void setup_triangle(const ScreenVertex& v0, const ScreenVertex& v1, const ScreenVertex& v2,
                    std::uint32_t triangle, const Viewport& vp, int cull_sign,
                    std::vector<SetupTriangle>& out, std::vector<ClipMap>& clip_maps) {
  // Trivial reject: all three vertices outside one viewport plane.
  if ((v0.outcode & v1.outcode & v2.outcode) & 0x3fu) return;
  if ((v0.outcode | v1.outcode | v2.outcode) & kNeedsClip) {
    clip_and_emit(v0, v1, v2, triangle, vp, cull_sign, out, clip_maps);
    return;
  }
  emit(v0.x, v0.y, v0.inv_w, v1.x, v1.y, v1.inv_w, v2.x, v2.y, v2.inv_w, triangle, vp,
       cull_sign, nullptr, out, clip_maps);
}

}  // namespace speculum::raster
