// Per-tile rasterization: see tile_rasterizer.h. Coverage and depth are computed from
// exact 64-bit edge values, so the result of a sample never depends on how the pixels were
// grouped (block size, lane width) or which thread ran the tile.
#include "raster/tile_rasterizer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include <immintrin.h>

#include "parallel/lanes.h"

namespace speculum::raster {
namespace {

constexpr int kBlock = 8;  // coverage block side: blocks whose corners all fail are skipped
constexpr int kTilePixels = kTileSize * kTileSize;
constexpr int kPad = 16;  // lanes may read/write past a row's end (never past the arrays)
constexpr std::uint32_t kNoRef = 0xffffffffu;
constexpr int kBlocksPerSide = kTileSize / kBlock;
constexpr std::uint32_t kRefSwapped = 1u, kRefClipped = 2u;
constexpr int kBlocksPerTile = kBlocksPerSide * kBlocksPerSide;
// Interpolated 1/w = Σ λ_i/w_i may exceed the largest vertex 1/w by rounding (a few ulps of
// three products and two sums); the rejection test widens the vertex maximum by far more.
constexpr float kHizMargin = 1.0f + 1.0f / 4096.0f;
constexpr std::uint32_t kRecordPrefetch = 16;  // list entries ahead
// Frames at least this large (5 MB of visibility buffer) are written with streaming stores.
// Smaller ones (cube-map faces, shadow maps) stay in cache for the pass that reads them.
constexpr std::size_t kStreamingMinSamples = std::size_t(1) << 18;

// The winner so far of every sample of one tile (the early depth test's state). All 32-bit
// so a row of W samples is tested and updated as W lanes.
struct TileScratch {
  alignas(64) float inv_w[kTilePixels + kPad];
  float p1[kTilePixels + kPad], p2[kTilePixels + kPad];  // the winner's perspective weights
                                                         // (eager: the resolve needs no edges)
  std::uint32_t triangle[kTilePixels + kPad];
  std::uint32_t ref[kTilePixels + kPad];  // index into the tile's triangle refs
  std::uint32_t coverage[kTilePixels + kPad];
  // Hierarchical depth: per 8×8 block, the farthest winner (smallest 1/w; 0 while any
  // sample of the block is empty). A triangle whose nearest vertex is farther than that
  // cannot win any sample of the block and skips it. Off when counting coverage (every
  // covering triangle must then be rasterized).
  alignas(32) float block_min[kBlocksPerTile];
  bool count_coverage;
  bool hiz;
  std::vector<const SetupTriangle*> setup;  // per ref
  std::vector<const ClipMap*> clip_map;     // per ref
  std::vector<std::uint32_t> flags;         // per ref: kRefSwapped | kRefClipped
  std::vector<std::uint32_t> object;        // per ref: the triangle's object id
};

// E_i(p) = A_i p.x + B_i p.y + C_i for the edge opposite vertex i, positive inside;
// a sample on the edge (E_i == 0) is covered only for top or left edges (threshold 0).
struct Edges {
  std::int64_t a[3], b[3], c[3];
  std::int64_t threshold[3];
  float inv_area;
  float inv_w[3];
  bool small;  // vertex extent ≤ 32 px: every edge value near the triangle fits in int32
};

Edges make_edges(const SetupTriangle& t) {
  Edges e;
  for (int i = 0; i < 3; ++i) {
    const int p = (i + 1) % 3, q = (i + 2) % 3;
    e.a[i] = std::int64_t(t.y[p]) - t.y[q];
    e.b[i] = std::int64_t(t.x[q]) - t.x[p];
    e.c[i] = std::int64_t(t.x[p]) * t.y[q] - std::int64_t(t.y[p]) * t.x[q];
    // Gradient (a, b) points inside: a left edge has the inside to its right (a > 0), a top
    // edge is horizontal with the inside below it (y down: b > 0).
    const bool top_left = e.a[i] > 0 || (e.a[i] == 0 && e.b[i] > 0);
    e.threshold[i] = top_left ? 0 : 1;
    e.inv_w[i] = t.inv_w[i];
  }
  const std::int64_t area = e.a[0] * t.x[0] + e.b[0] * t.y[0] + e.c[0];
  // |E(p)| ≤ |A||p.x − x_v| + |B||p.y − y_v| ≤ 2·D·(D + 16 px) for p in the bounding box
  // widened by up to 16 lanes: with D ≤ 2^13 that is < 2^28.
  const std::int32_t dx = std::max({t.x[0], t.x[1], t.x[2]}) - std::min({t.x[0], t.x[1], t.x[2]});
  const std::int32_t dy = std::max({t.y[0], t.y[1], t.y[2]}) - std::min({t.y[0], t.y[1], t.y[2]});
  e.small = dx <= (1 << 13) && dy <= (1 << 13);
  e.inv_area = 1.0f / static_cast<float>(area);
  return e;
}

inline std::int64_t centre(int pixel) {
  return std::int64_t(pixel) * kSubpixelOne + kSubpixelOne / 2;
}
inline std::int64_t edge_at(const Edges& e, int i, int px, int py) {
  return e.a[i] * centre(px) + e.b[i] * centre(py) + e.c[i];
}

// Perspective weights p_i = λ_i / w_i; their sum is the interpolated 1/w (the depth key).
// Written once and used by both the depth test and the resolve so both see equal bits.
struct Weights {
  float p0, p1, p2, inv_w;
};
inline Weights weights(const Edges& e, std::int64_t e0, std::int64_t e1, std::int64_t e2) {
  const float p0 = static_cast<float>(e0) * e.inv_area * e.inv_w[0];
  const float p1 = static_cast<float>(e1) * e.inv_area * e.inv_w[1];
  const float p2 = static_cast<float>(e2) * e.inv_area * e.inv_w[2];
  return {p0, p1, p2, (p0 + p1) + p2};
}

// Coverage + early depth test over the pixel rectangle [x0,x1]×[y0,y1] (inclusive,
// absolute pixels inside the tile at (ox, oy)), W pixels of a row at a time.
template <int W>
bool raster_rect_wide(const Edges& e, const SetupTriangle& t, std::uint32_t ref, int x0, int y0,
                      int x1, int y1, int ox, int oy, TileScratch& s) {
  bool won = false;
  const std::int64_t step0 = e.a[0] * kSubpixelOne, step1 = e.a[1] * kSubpixelOne,
                     step2 = e.a[2] * kSubpixelOne;
  // Per-lane offsets built by additions (AVX2 has no 64-bit multiply).
  std::int64_t off0[W], off1[W], off2[W];
  off0[0] = off1[0] = off2[0] = 0;
  for (int l = 1; l < W; ++l)
    off0[l] = off0[l - 1] + step0, off1[l] = off1[l - 1] + step1, off2[l] = off2[l - 1] + step2;
  const std::int64_t row0 = off0[W - 1] + step0, row1 = off1[W - 1] + step1,
                     row2 = off2[W - 1] + step2;
  std::int64_t start0 = edge_at(e, 0, x0, y0), start1 = edge_at(e, 1, x0, y0),
               start2 = edge_at(e, 2, x0, y0);
  const std::int64_t down0 = e.b[0] * kSubpixelOne, down1 = e.b[1] * kSubpixelOne,
                     down2 = e.b[2] * kSubpixelOne;
  for (int y = y0; y <= y1; ++y, start0 += down0, start1 += down1, start2 += down2) {
    std::int64_t r0 = start0, r1 = start1, r2 = start2;
    for (int x = x0; x <= x1; x += W) {
      std::int64_t v0[W], v1[W], v2[W];
      bool covered[W];
      bool any = false;
      for (int l = 0; l < W; ++l) {
        v0[l] = r0 + off0[l];
        v1[l] = r1 + off1[l];
        v2[l] = r2 + off2[l];
        covered[l] = (x + l <= x1) & (v0[l] >= e.threshold[0]) & (v1[l] >= e.threshold[1]) &
                     (v2[l] >= e.threshold[2]);
        any |= covered[l];
      }
      r0 += row0, r1 += row1, r2 += row2;
      if (!any) continue;
      for (int l = 0; l < W; ++l) {
        if (!covered[l]) continue;
        const Weights w = weights(e, v0[l], v1[l], v2[l]);
        const float inv_w = w.inv_w;
        const int idx = (y - oy) * kTileSize + (x + l - ox);
        if (s.count_coverage) ++s.coverage[idx];
        // Nearer = larger 1/w; equal depth: the lower triangle index wins, so the result
        // does not depend on submission order.
        if (inv_w > s.inv_w[idx] || (inv_w == s.inv_w[idx] && t.triangle < s.triangle[idx])) {
          s.inv_w[idx] = inv_w;
          s.p1[idx] = w.p1;
          s.p2[idx] = w.p2;
          s.triangle[idx] = t.triangle;
          s.ref[idx] = ref;
          won = true;
        }
      }
    }
  }
  return won;
}

// The same with 32-bit edge values in Lanes<W> (AVX2 has no 64-bit multiply or int64→float
// conversion): used when every edge value in the rectangle fits comfortably in int32. The
// integers are equal to the 64-bit ones and the float operations are the same, in the same
// order, so both paths give the same bits.
template <int W>
bool raster_rect_lanes(const Edges& e, const SetupTriangle& t, std::uint32_t ref, int x0, int y0,
                       int x1, int y1, int ox, int oy, TileScratch& s) {
  bool won = false;
  using L = par::Lanes<W>;
  using I = typename L::i32;
  using U = typename L::u32;
  using F = typename L::f32;
  const I lane = L::iota(0);
  const I off0 = lane * std::int32_t(e.a[0] * kSubpixelOne),
          off1 = lane * std::int32_t(e.a[1] * kSubpixelOne),
          off2 = lane * std::int32_t(e.a[2] * kSubpixelOne);
  const std::int32_t row0 = std::int32_t(e.a[0] * kSubpixelOne * W),
                     row1 = std::int32_t(e.a[1] * kSubpixelOne * W),
                     row2 = std::int32_t(e.a[2] * kSubpixelOne * W);
  const std::int32_t down0 = std::int32_t(e.b[0] * kSubpixelOne),
                     down1 = std::int32_t(e.b[1] * kSubpixelOne),
                     down2 = std::int32_t(e.b[2] * kSubpixelOne);
  const I t0 = I(std::int32_t(e.threshold[0])), t1 = I(std::int32_t(e.threshold[1])),
          t2 = I(std::int32_t(e.threshold[2]));
  const F ia(e.inv_area), iw0(e.inv_w[0]), iw1(e.inv_w[1]), iw2(e.inv_w[2]);
  const U tri(t.triangle), refs(ref);
  std::int32_t start0 = std::int32_t(edge_at(e, 0, x0, y0)),
               start1 = std::int32_t(edge_at(e, 1, x0, y0)),
               start2 = std::int32_t(edge_at(e, 2, x0, y0));
  for (int y = y0; y <= y1; ++y, start0 += down0, start1 += down1, start2 += down2) {
    std::int32_t r0 = start0, r1 = start1, r2 = start2;
    for (int x = x0; x <= x1; x += W, r0 += row0, r1 += row1, r2 += row2) {
      const I v0 = I(r0) + off0, v1 = I(r1) + off1, v2 = I(r2) + off2;
      const auto inside = (v0 >= t0) && (v1 >= t1) && (v2 >= t2) && (lane <= I(x1 - x));
      if (L::none(inside)) continue;
      const F p0 = L::to_float(v0) * ia * iw0, p1 = L::to_float(v1) * ia * iw1,
              p2 = L::to_float(v2) * ia * iw2;
      const F inv_w = (p0 + p1) + p2;
      const int idx = (y - oy) * kTileSize + (x - ox);
      const typename F::mask_type covered(inside);
      if (s.count_coverage)
        for (int l = 0; l < W; ++l) s.coverage[idx + l] += covered[l] ? 1u : 0u;
      const F best = L::load(&s.inv_w[idx]);
      const U best_tri = L::load(&s.triangle[idx]);
      const typename F::mask_type win =
          covered && ((inv_w > best) ||
                      ((inv_w == best) && typename F::mask_type(tri < best_tri)));
      if (L::none(win)) continue;
      L::store(L::select(win, inv_w, best), &s.inv_w[idx]);
      L::store(L::select(win, p1, L::load(&s.p1[idx])), &s.p1[idx]);
      L::store(L::select(win, p2, L::load(&s.p2[idx])), &s.p2[idx]);
      L::store(L::select(win, tri, best_tri), &s.triangle[idx]);
      L::store(L::select(win, refs, U(L::load(&s.ref[idx]))), &s.ref[idx]);
      won = true;
    }
  }
  return won;
}

// The depth test and update of 8 samples of one tile row for the AVX2 paths below: given
// the covered lanes and the float edge values, the same float operations as
// raster_rect_lanes in the same order (same bits). The stores write back the loaded value
// where a lane did not win (lanes past the row end stay inside the padded arrays, and one
// thread owns the tile), so a row needs no branch.
struct DepthTest8 {
  __m256 ia, iw0, iw1, iw2;
  __m256i flip, tri, tri_flipped, refs;
  __m256i won = _mm256_setzero_si256();

  DepthTest8(const Edges& e, const SetupTriangle& t, std::uint32_t ref)
      : ia(_mm256_set1_ps(e.inv_area)), iw0(_mm256_set1_ps(e.inv_w[0])),
        iw1(_mm256_set1_ps(e.inv_w[1])), iw2(_mm256_set1_ps(e.inv_w[2])),
        // Unsigned triangle-index order through a signed compare of sign-flipped values.
        flip(_mm256_set1_epi32(std::int32_t(0x80000000u))),
        tri(_mm256_set1_epi32(std::int32_t(t.triangle))),
        tri_flipped(_mm256_xor_si256(tri, flip)), refs(_mm256_set1_epi32(std::int32_t(ref))) {}

  inline void operator()(__m256i inside, __m256 f0, __m256 f1, __m256 f2, int idx, TileScratch& s) {
    const __m256 p0 = _mm256_mul_ps(_mm256_mul_ps(f0, ia), iw0);
    const __m256 p1 = _mm256_mul_ps(_mm256_mul_ps(f1, ia), iw1);
    const __m256 p2 = _mm256_mul_ps(_mm256_mul_ps(f2, ia), iw2);
    const __m256 inv_w = _mm256_add_ps(_mm256_add_ps(p0, p1), p2);
    const __m256 best = _mm256_loadu_ps(&s.inv_w[idx]);
    const __m256i best_tri = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&s.triangle[idx]));
    const __m256 nearer = _mm256_cmp_ps(inv_w, best, _CMP_GT_OQ);
    const __m256 tie = _mm256_and_ps(
        _mm256_cmp_ps(inv_w, best, _CMP_EQ_OQ),
        _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_xor_si256(best_tri, flip), tri_flipped)));
    const __m256 win = _mm256_and_ps(_mm256_castsi256_ps(inside), _mm256_or_ps(nearer, tie));
    won = _mm256_or_si256(won, _mm256_castps_si256(win));
    _mm256_storeu_ps(&s.inv_w[idx], _mm256_blendv_ps(best, inv_w, win));
    _mm256_storeu_ps(&s.p1[idx], _mm256_blendv_ps(_mm256_loadu_ps(&s.p1[idx]), p1, win));
    _mm256_storeu_ps(&s.p2[idx], _mm256_blendv_ps(_mm256_loadu_ps(&s.p2[idx]), p2, win));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(&s.triangle[idx]),
                        _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(best_tri),
                                                             _mm256_castsi256_ps(tri), win)));
    __m256i* ref_at = reinterpret_cast<__m256i*>(&s.ref[idx]);
    _mm256_storeu_si256(ref_at, _mm256_castps_si256(_mm256_blendv_ps(
                                    _mm256_castsi256_ps(_mm256_loadu_si256(ref_at)),
                                    _mm256_castsi256_ps(refs), win)));
  }
  bool any_won() const { return !_mm256_testz_si256(won, won); }
};

// The 32-bit path for 8 lanes in AVX2 intrinsics, branch-free inside a row: random small
// triangles made the "any lane covered / any lane won" branches of raster_rect_lanes
// mispredict about half the time. Not used when counting coverage.
bool raster_rect_avx2(const Edges& e, const SetupTriangle& t, std::uint32_t ref, int x0, int y0,
                      int x1, int y1, int ox, int oy, TileScratch& s) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i off0 = _mm256_mullo_epi32(lane, _mm256_set1_epi32(std::int32_t(e.a[0] * kSubpixelOne)));
  const __m256i off1 = _mm256_mullo_epi32(lane, _mm256_set1_epi32(std::int32_t(e.a[1] * kSubpixelOne)));
  const __m256i off2 = _mm256_mullo_epi32(lane, _mm256_set1_epi32(std::int32_t(e.a[2] * kSubpixelOne)));
  const std::int32_t row0 = std::int32_t(e.a[0] * kSubpixelOne * 8),
                     row1 = std::int32_t(e.a[1] * kSubpixelOne * 8),
                     row2 = std::int32_t(e.a[2] * kSubpixelOne * 8);
  const std::int32_t down0 = std::int32_t(e.b[0] * kSubpixelOne),
                     down1 = std::int32_t(e.b[1] * kSubpixelOne),
                     down2 = std::int32_t(e.b[2] * kSubpixelOne);
  // v >= threshold  ⇔  v > threshold − 1 (thresholds are 0 or 1).
  const __m256i t0 = _mm256_set1_epi32(std::int32_t(e.threshold[0]) - 1),
                t1 = _mm256_set1_epi32(std::int32_t(e.threshold[1]) - 1),
                t2 = _mm256_set1_epi32(std::int32_t(e.threshold[2]) - 1);
  DepthTest8 test(e, t, ref);
  std::int32_t start0 = std::int32_t(edge_at(e, 0, x0, y0)),
               start1 = std::int32_t(edge_at(e, 1, x0, y0)),
               start2 = std::int32_t(edge_at(e, 2, x0, y0));
  for (int y = y0; y <= y1; ++y, start0 += down0, start1 += down1, start2 += down2) {
    std::int32_t r0 = start0, r1 = start1, r2 = start2;
    for (int x = x0; x <= x1; x += 8, r0 += row0, r1 += row1, r2 += row2) {
      const __m256i v0 = _mm256_add_epi32(_mm256_set1_epi32(r0), off0);
      const __m256i v1 = _mm256_add_epi32(_mm256_set1_epi32(r1), off1);
      const __m256i v2 = _mm256_add_epi32(_mm256_set1_epi32(r2), off2);
      const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(x1 - x + 1), lane);
      const __m256i inside = _mm256_and_si256(
          _mm256_and_si256(_mm256_cmpgt_epi32(v0, t0), _mm256_cmpgt_epi32(v1, t1)),
          _mm256_and_si256(_mm256_cmpgt_epi32(v2, t2), in_row));
      test(inside, _mm256_cvtepi32_ps(v0), _mm256_cvtepi32_ps(v1), _mm256_cvtepi32_ps(v2),
           (y - oy) * kTileSize + (x - ox), s);
    }
  }
  return test.any_won();
}

// The wide path for 8 lanes in AVX2: edge values beyond int32 (large triangles, e.g. walls
// reaching into the guard band) held in doubles, two registers of 4 per edge. Every value is
// an integer below 2^50 in magnitude (the guard band keeps fixed-point coordinates below
// 2^23, so |A|, |B| < 2^24 and |C| < 2^47), so the
// doubles hold the int64 values of raster_rect_wide exactly, their sums are exact, the
// threshold compares are exact, and converting to float rounds once to nearest, as the
// int64 → float conversion does: the same bits. Not used when counting coverage.
bool raster_rect_avx2_wide(const Edges& e, const SetupTriangle& t, std::uint32_t ref, int x0,
                           int y0, int x1, int y1, int ox, int oy, TileScratch& s) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256d lo_lane = _mm256_setr_pd(0, 1, 2, 3), hi_lane = _mm256_setr_pd(4, 5, 6, 7);
  __m256d off_lo[3], off_hi[3], thr[3];
  double row[3], down[3], start[3];
  for (int i = 0; i < 3; ++i) {
    const __m256d step = _mm256_set1_pd(double(e.a[i] * kSubpixelOne));
    off_lo[i] = _mm256_mul_pd(lo_lane, step);  // exact: small integers times an integer < 2^32
    off_hi[i] = _mm256_mul_pd(hi_lane, step);
    row[i] = double(e.a[i] * kSubpixelOne * 8);
    down[i] = double(e.b[i] * kSubpixelOne);
    start[i] = double(edge_at(e, i, x0, y0));
    thr[i] = _mm256_set1_pd(double(e.threshold[i]));
  }
  DepthTest8 test(e, t, ref);
  auto covered = [](__m256d lo, __m256d hi, __m256d threshold) {
    const __m256i l = _mm256_castpd_si256(_mm256_cmp_pd(lo, threshold, _CMP_GE_OQ));
    const __m256i h = _mm256_castpd_si256(_mm256_cmp_pd(hi, threshold, _CMP_GE_OQ));
    // 64-bit masks → 32-bit lanes in order: take the low halves of each 64-bit lane.
    const __m256i idx = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
    return _mm256_blend_epi32(_mm256_permutevar8x32_epi32(l, idx),
                              _mm256_permutevar8x32_epi32(h, idx), 0xf0);
  };
  auto to_float = [](__m256d lo, __m256d hi) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(lo)), _mm256_cvtpd_ps(hi), 1);
  };
  for (int y = y0; y <= y1; ++y) {
    double r[3] = {start[0], start[1], start[2]};
    for (int x = x0; x <= x1; x += 8) {
      __m256d lo[3], hi[3];
      for (int i = 0; i < 3; ++i) {
        const __m256d base = _mm256_set1_pd(r[i]);
        lo[i] = _mm256_add_pd(base, off_lo[i]);
        hi[i] = _mm256_add_pd(base, off_hi[i]);
        r[i] += row[i];
      }
      const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(x1 - x + 1), lane);
      const __m256i inside = _mm256_and_si256(
          _mm256_and_si256(covered(lo[0], hi[0], thr[0]), covered(lo[1], hi[1], thr[1])),
          _mm256_and_si256(covered(lo[2], hi[2], thr[2]), in_row));
      test(inside, to_float(lo[0], hi[0]), to_float(lo[1], hi[1]), to_float(lo[2], hi[2]),
           (y - oy) * kTileSize + (x - ox), s);
    }
    for (int i = 0; i < 3; ++i) start[i] += down[i];
  }
  return test.any_won();
}

// Triangles whose box in the tile spans at most 4 × 2 pixels (most of a million-triangle view
// at about a pixel per triangle) in one 8-lane pass: lane l is the sample (x0 + l % 4,
// y0 + l / 4). The edge values are the integers of make_edges/edge_at (E_i written about
// vertex p, which it vanishes at: the same integer), exact in int32 for a vertex extent of at
// most 2^13 sub-pixels, and every float operation of DepthTest8 is the same in the same
// order (area → float once, then (E·(1/area))·(1/w_i), (p0 + p1) + p2): the same bits as
// raster_rect_avx2. Not used when counting coverage.
bool raster_tiny_avx2(const SetupTriangle& t, std::uint32_t ref, int x0, int y0, int x1, int y1,
                      int ox, int oy, TileScratch& s) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i dx = _mm256_and_si256(lane, _mm256_set1_epi32(3));
  const __m256i dy = _mm256_srli_epi32(lane, 2);
  const std::int32_t cx = x0 * kSubpixelOne + kSubpixelOne / 2, cy = y0 * kSubpixelOne + kSubpixelOne / 2;
  __m256i inside = _mm256_and_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(x1 - x0 + 1), dx),
                                    _mm256_cmpgt_epi32(_mm256_set1_epi32(y1 - y0 + 1), dy));
  __m256 f[3];
  std::int32_t area = 0;
  for (int i = 0; i < 3; ++i) {
    const int p = (i + 1) % 3, q = (i + 2) % 3;
    const std::int32_t a = t.y[p] - t.y[q], b = t.x[q] - t.x[p];
    if (i == 0) area = a * (t.x[0] - t.x[p]) + b * (t.y[0] - t.y[p]);
    const bool top_left = a > 0 || (a == 0 && b > 0);
    const std::int32_t start = a * (cx - t.x[p]) + b * (cy - t.y[p]);
    const __m256i v = _mm256_add_epi32(
        _mm256_set1_epi32(start),
        _mm256_add_epi32(_mm256_mullo_epi32(dx, _mm256_set1_epi32(a * kSubpixelOne)),
                         _mm256_mullo_epi32(dy, _mm256_set1_epi32(b * kSubpixelOne))));
    inside = _mm256_and_si256(inside, _mm256_cmpgt_epi32(v, _mm256_set1_epi32(top_left ? -1 : 0)));
    f[i] = _mm256_cvtepi32_ps(v);
  }
  if (_mm256_testz_si256(inside, inside)) return false;
  const __m256 ia = _mm256_set1_ps(1.0f / static_cast<float>(area));
  const __m256 p0 = _mm256_mul_ps(_mm256_mul_ps(f[0], ia), _mm256_set1_ps(t.inv_w[0]));
  const __m256 p1 = _mm256_mul_ps(_mm256_mul_ps(f[1], ia), _mm256_set1_ps(t.inv_w[1]));
  const __m256 p2 = _mm256_mul_ps(_mm256_mul_ps(f[2], ia), _mm256_set1_ps(t.inv_w[2]));
  const __m256 inv_w = _mm256_add_ps(_mm256_add_ps(p0, p1), p2);
  // Rows y0 and y0 + 1 (a one-row box points its masked upper half at another row of the
  // tile, so the two halves never store to the same samples).
  const int lo = (y0 - oy) * kTileSize + (x0 - ox);
  const int hi = y1 > y0 || y0 - oy < kTileSize - 1 ? lo + kTileSize : lo - kTileSize;
  auto load = [&](const float* plane) { return _mm256_loadu2_m128(plane + hi, plane + lo); };
  auto store = [&](float* plane, __m256 v) { _mm256_storeu2_m128(plane + hi, plane + lo, v); };
  const __m256i flip = _mm256_set1_epi32(std::int32_t(0x80000000u));
  const __m256i tri = _mm256_set1_epi32(std::int32_t(t.triangle));
  const __m256 best = load(s.inv_w);
  const __m256i best_tri = _mm256_castps_si256(load(reinterpret_cast<const float*>(s.triangle)));
  const __m256 nearer = _mm256_cmp_ps(inv_w, best, _CMP_GT_OQ);
  const __m256 tie = _mm256_and_ps(
      _mm256_cmp_ps(inv_w, best, _CMP_EQ_OQ),
      _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_xor_si256(best_tri, flip),
                                             _mm256_xor_si256(tri, flip))));
  const __m256 win = _mm256_and_ps(_mm256_castsi256_ps(inside), _mm256_or_ps(nearer, tie));
  if (_mm256_testz_ps(win, win)) return false;
  store(s.inv_w, _mm256_blendv_ps(best, inv_w, win));
  store(s.p1, _mm256_blendv_ps(load(s.p1), p1, win));
  store(s.p2, _mm256_blendv_ps(load(s.p2), p2, win));
  store(reinterpret_cast<float*>(s.triangle), _mm256_blendv_ps(_mm256_castsi256_ps(best_tri),
                                                                _mm256_castsi256_ps(tri), win));
  store(reinterpret_cast<float*>(s.ref),
        _mm256_blendv_ps(load(reinterpret_cast<const float*>(s.ref)),
                         _mm256_castsi256_ps(_mm256_set1_epi32(std::int32_t(ref))), win));
  return true;
}

// Picks the 32-bit lane path for small triangles (see make_edges) or when |E| stays below
// 2^30 over the rectangle widened to whole groups of W lanes (E is linear: its extremes are
// at the corners).
template <int W>
bool raster_rect(const Edges& e, const SetupTriangle& t, std::uint32_t ref, int x0, int y0,
                 int x1, int y1, int ox, int oy, TileScratch& s) {
  const int xw = x0 + ((x1 - x0) / W + 1) * W - 1;
  constexpr std::int64_t kLimit = std::int64_t(1) << 30;
  bool narrow = true;
  for (int i = 0; i < 3 && narrow && !e.small; ++i)
    for (const auto& [px, py] : {std::pair{x0, y0}, {xw, y0}, {x0, y1}, {xw, y1}}) {
      const std::int64_t v = edge_at(e, i, px, py);
      narrow &= v < kLimit && v > -kLimit;
    }
  if (narrow && W == 8 && !s.count_coverage)
    return raster_rect_avx2(e, t, ref, x0, y0, x1, y1, ox, oy, s);
  if (W == 8 && !s.count_coverage)
    return raster_rect_avx2_wide(e, t, ref, x0, y0, x1, y1, ox, oy, s);
  if (narrow && W > 1) return raster_rect_lanes<W>(e, t, ref, x0, y0, x1, y1, ox, oy, s);
  return raster_rect_wide<W>(e, t, ref, x0, y0, x1, y1, ox, oy, s);
}

// Recomputes the farthest winner of block (bx, by) after a triangle won samples in it.
inline void update_block_min(TileScratch& s, int bx, int by) {
  const float* row = &s.inv_w[(by * kBlock) * kTileSize + bx * kBlock];
  __m256 m = _mm256_loadu_ps(row);
  for (int r = 1; r < kBlock; ++r) m = _mm256_min_ps(m, _mm256_loadu_ps(row + r * kTileSize));
  __m128 h = _mm_min_ps(_mm256_castps256_ps128(m), _mm256_extractf128_ps(m, 1));
  h = _mm_min_ps(h, _mm_movehl_ps(h, h));
  h = _mm_min_ss(h, _mm_shuffle_ps(h, h, 1));
  s.block_min[by * kBlocksPerSide + bx] = _mm_cvtss_f32(h);
}

// Updates the blocks overlapped by the tile-relative pixel rectangle [x0,x1]×[y0,y1].
inline void update_block_mins(TileScratch& s, int x0, int y0, int x1, int y1) {
  for (int by = y0 / kBlock; by <= y1 / kBlock; ++by)
    for (int bx = x0 / kBlock; bx <= x1 / kBlock; ++bx) update_block_min(s, bx, by);
}

// Hierarchical coverage: small triangles go straight to pixels; larger ones are walked in
// the tile's 8×8 blocks and a block is skipped when one edge is negative at all four corner
// samples (E is linear, so its maximum over the block is at a corner) or when the hierarchical
// depth shows the triangle is behind everything already drawn there.
template <int W>
void raster_triangle(const SetupTriangle& t, std::uint32_t ref, int tx0, int ty0, int tx1,
                     int ty1, TileScratch& s) {
  const int x0 = std::max<int>(t.px0, tx0), x1 = std::min<int>(t.px1, tx1);
  const int y0 = std::max<int>(t.py0, ty0), y1 = std::min<int>(t.py1, ty1);
  if (x0 > x1 || y0 > y1) return;
  // Block range of the clipped bounding box, tile-relative.
  const int bx0 = (x0 - tx0) / kBlock, bx1 = (x1 - tx0) / kBlock;
  const int by0 = (y0 - ty0) / kBlock, by1 = (y1 - ty0) / kBlock;
  // 1/w is affine on the triangle: its maximum is at a vertex.
  const float nearest = std::max({t.inv_w[0], t.inv_w[1], t.inv_w[2]}) * kHizMargin;
  auto hidden = [&](int bx, int by) {
    return s.hiz && nearest < s.block_min[by * kBlocksPerSide + bx];
  };
  if (s.hiz) {
    bool any_visible = false;
    for (int by = by0; by <= by1 && !any_visible; ++by)
      for (int bx = bx0; bx <= bx1 && !any_visible; ++bx) any_visible = !hidden(bx, by);
    if (!any_visible) return;
  }
  if (W == 8 && !s.count_coverage && x1 - x0 < 4 && y1 - y0 < 2) {
    const std::int32_t dx = std::max({t.x[0], t.x[1], t.x[2]}) - std::min({t.x[0], t.x[1], t.x[2]});
    const std::int32_t dy = std::max({t.y[0], t.y[1], t.y[2]}) - std::min({t.y[0], t.y[1], t.y[2]});
    if (dx <= (1 << 13) && dy <= (1 << 13)) {
      if (raster_tiny_avx2(t, ref, x0, y0, x1, y1, tx0, ty0, s) && s.hiz)
        update_block_mins(s, x0 - tx0, y0 - ty0, x1 - tx0, y1 - ty0);
      return;
    }
  }
  const Edges e = make_edges(t);
  // Up to 2×2 blocks: the 8-lane kernel walks the whole rectangle (its rows are cheaper
  // than the per-block corner tests).
  const int small_side = W == 8 && !s.count_coverage ? 2 * kBlock : kBlock;
  if (x1 - x0 < small_side && y1 - y0 < small_side) {
    if (raster_rect<W>(e, t, ref, x0, y0, x1, y1, tx0, ty0, s) && s.hiz)
      update_block_mins(s, x0 - tx0, y0 - ty0, x1 - tx0, y1 - ty0);
    return;
  }
  for (int by = by0; by <= by1; ++by) {
    const int ry0 = std::max(y0, ty0 + by * kBlock), ry1 = std::min(y1, ty0 + by * kBlock + kBlock - 1);
    for (int bx = bx0; bx <= bx1; ++bx) {
      if (hidden(bx, by)) continue;
      const int rx0 = std::max(x0, tx0 + bx * kBlock);
      const int rx1 = std::min(x1, tx0 + bx * kBlock + kBlock - 1);
      bool rejected = false;
      for (int i = 0; i < 3 && !rejected; ++i) {
        const std::int64_t m =
            std::max({edge_at(e, i, rx0, ry0), edge_at(e, i, rx1, ry0), edge_at(e, i, rx0, ry1),
                      edge_at(e, i, rx1, ry1)});
        rejected = m < e.threshold[i];
      }
      if (!rejected && raster_rect<W>(e, t, ref, rx0, ry0, rx1, ry1, tx0, ty0, s) && s.hiz)
        update_block_min(s, bx, by);
    }
  }
}

// One sample's visibility-buffer values.
struct SampleOut {
  std::uint32_t* triangle;
  std::uint32_t* object;
  float* depth;
  glm::vec2* bary;
};

// Writes sample `idx` of the tile to slot o of `out`: the winner's ids, depth and
// barycentrics in the original triangle, or the empty-sample values.
inline void resolve_sample(const TileScratch& s, int idx, std::size_t o, const SampleOut& out) {
  const std::uint32_t ref = s.ref[idx];
  if (ref == kNoRef) {
    out.triangle[o] = kNoId;
    out.object[o] = kNoId;
    out.depth[o] = std::numeric_limits<float>::infinity();
    out.bary[o] = glm::vec2(0.0f);
    return;
  }
  const SetupTriangle* t = s.setup[ref];
  const float inv_w = s.inv_w[idx];
  float b1 = s.p1[idx] / inv_w, b2 = s.p2[idx] / inv_w;
  if (t->swapped) std::swap(b1, b2);
  if (const ClipMap* m = s.clip_map[ref]) {
    const float b0 = 1.0f - b1 - b2;
    const glm::vec3 b = b0 * m->bary[0] + b1 * m->bary[1] + b2 * m->bary[2];
    b1 = b.y, b2 = b.z;
  }
  out.triangle[o] = t->triangle;
  out.object[o] = t->object;
  out.depth[o] = 1.0f / inv_w;
  out.bary[o] = glm::vec2(b1, b2);
}

SampleOut frame_out(VisibilityBuffer& out) {
  return {out.triangle.pixels.data(), out.object.pixels.data(), out.depth.pixels.data(),
          out.bary.pixels.data()};
}

// One resolved tile row, staged in L1 before it is copied out.
struct RowStage {
  alignas(32) std::uint32_t triangle[kTileSize];
  alignas(32) std::uint32_t object[kTileSize];
  alignas(32) float depth[kTileSize];
  alignas(32) glm::vec2 bary[kTileSize];
  SampleOut slots() { return {triangle, object, depth, bary}; }
};

// Copies `bytes` to dst: the whole 64-byte lines inside the range with streaming stores (they
// skip reading each destination line first, and a large frame's planes cannot stay cached
// until the G-buffer reads them anyway), the partial lines at the ends, which neighbouring
// tiles share, with ordinary stores.
inline void stream_copy(void* dst, const void* src, std::size_t bytes) {
  auto* d = static_cast<unsigned char*>(dst);
  const auto* s = static_cast<const unsigned char*>(src);
  const std::size_t head = std::min(bytes, (64 - (reinterpret_cast<std::uintptr_t>(d) & 63)) & 63);
  std::memcpy(d, s, head);
  d += head, s += head, bytes -= head;
  for (; bytes >= 64; d += 64, s += 64, bytes -= 64) {
    _mm256_stream_si256(reinterpret_cast<__m256i*>(d),
                        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s)));
    _mm256_stream_si256(reinterpret_cast<__m256i*>(d + 32),
                        _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s + 32)));
  }
  std::memcpy(d, s, bytes);
}

// The resolve 8 samples at a time: the same IEEE divisions as resolve_sample (so the same
// bits), the winners' object ids gathered from the tile's refs, clipped winners and the row
// tail left to resolve_sample. Each row is resolved into a stage; `stream` copies it out with
// streaming stores (large frames), otherwise with ordinary ones.
void resolve_tile_avx2(const TileScratch& s, int tx0, int ty0, int tx1, int ty1,
                       const Viewport& vp, bool stream, VisibilityBuffer& out) {
  const __m256i no_ref = _mm256_set1_epi32(-1);
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const int* flags = reinterpret_cast<const int*>(s.flags.data());
  const int* objects = reinterpret_cast<const int*>(s.object.data());
  const int n = tx1 - tx0 + 1;
  const int full = n / 8 * 8;
  RowStage stage;
  const SampleOut slots = stage.slots();
  for (int y = ty0; y <= ty1; ++y) {
    const int row = (y - ty0) * kTileSize;
    for (int x = 0; x < full; x += 8) {
      const int idx = row + x;
      const __m256i ref = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&s.ref[idx]));
      const __m256i valid = _mm256_xor_si256(_mm256_cmpeq_epi32(ref, no_ref), no_ref);
      const __m256i flag =
          _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), flags, ref, valid, 4);
      const __m256i clipped =
          _mm256_cmpeq_epi32(_mm256_and_si256(flag, _mm256_set1_epi32(int(kRefClipped))),
                             _mm256_set1_epi32(int(kRefClipped)));
      const __m256 swapped = _mm256_castsi256_ps(
          _mm256_cmpeq_epi32(_mm256_and_si256(flag, _mm256_set1_epi32(int(kRefSwapped))),
                             _mm256_set1_epi32(int(kRefSwapped))));
      const __m256i tri = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&s.triangle[idx]));
      const __m256i object = _mm256_mask_i32gather_epi32(no_ref, objects, ref, valid, 4);
      const __m256 inv_w = _mm256_loadu_ps(&s.inv_w[idx]);
      const __m256 q1 = _mm256_div_ps(_mm256_loadu_ps(&s.p1[idx]), inv_w);
      const __m256 q2 = _mm256_div_ps(_mm256_loadu_ps(&s.p2[idx]), inv_w);
      const __m256 validf = _mm256_castsi256_ps(valid);
      const __m256 b1 = _mm256_and_ps(validf, _mm256_blendv_ps(q1, q2, swapped));
      const __m256 b2 = _mm256_and_ps(validf, _mm256_blendv_ps(q2, q1, swapped));
      const __m256 depth = _mm256_blendv_ps(inf, _mm256_div_ps(one, inv_w), validf);
      // Empty samples keep kNoId in s.triangle (never won).
      _mm256_store_si256(reinterpret_cast<__m256i*>(&stage.triangle[x]), tri);
      _mm256_store_si256(reinterpret_cast<__m256i*>(&stage.object[x]), object);
      _mm256_store_ps(&stage.depth[x], depth);
      const __m256 lo = _mm256_unpacklo_ps(b1, b2), hi = _mm256_unpackhi_ps(b1, b2);
      float* bary = &stage.bary[x].x;
      _mm256_store_ps(bary, _mm256_permute2f128_ps(lo, hi, 0x20));
      _mm256_store_ps(bary + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
      if (const int c = _mm256_movemask_ps(_mm256_castsi256_ps(clipped)); c != 0)
        for (int l = 0; l < 8; ++l)
          if (c & (1 << l)) resolve_sample(s, idx + l, std::size_t(x + l), slots);
    }
    for (int x = full; x < n; ++x) resolve_sample(s, row + x, std::size_t(x), slots);
    const std::size_t o = static_cast<std::size_t>(y) * vp.width + tx0;
    const std::size_t u = static_cast<std::size_t>(n);
    if (stream) {
      stream_copy(&out.triangle.pixels[o], stage.triangle, u * sizeof(std::uint32_t));
      stream_copy(&out.object.pixels[o], stage.object, u * sizeof(std::uint32_t));
      stream_copy(&out.depth.pixels[o], stage.depth, u * sizeof(float));
      stream_copy(&out.bary.pixels[o], stage.bary, u * sizeof(glm::vec2));
    } else {
      std::memcpy(&out.triangle.pixels[o], stage.triangle, u * sizeof(std::uint32_t));
      std::memcpy(&out.object.pixels[o], stage.object, u * sizeof(std::uint32_t));
      std::memcpy(&out.depth.pixels[o], stage.depth, u * sizeof(float));
      std::memcpy(&out.bary.pixels[o], stage.bary, u * sizeof(glm::vec2));
    }
  }
  if (stream) _mm_sfence();  // weakly ordered: fence before another thread reads the frame
}

template <int W>
void rasterize_tile_w(int tile, const TileGrid& grid, const Viewport& vp, const TileBins& bins,
                      VisibilityBuffer& out) {
  thread_local TileScratch scratch;  // fully re-initialized below: no state crosses tiles
  TileScratch& s = scratch;
  const int tx0 = (tile % grid.tiles_x) * kTileSize, ty0 = (tile / grid.tiles_x) * kTileSize;
  const int tx1 = std::min(tx0 + kTileSize, vp.width) - 1;
  const int ty1 = std::min(ty0 + kTileSize, vp.height) - 1;
  std::fill(std::begin(s.inv_w), std::end(s.inv_w), 0.0f);
  std::fill(std::begin(s.triangle), std::end(s.triangle), kNoId);
  std::fill(std::begin(s.ref), std::end(s.ref), kNoRef);
  s.count_coverage = !out.coverage.empty();
  s.hiz = !s.count_coverage;
  std::fill(std::begin(s.block_min), std::end(s.block_min), 0.0f);
  if (s.count_coverage) std::fill(std::begin(s.coverage), std::end(s.coverage), 0u);

  const std::uint32_t begin = bins.tile_offsets[tile], end = bins.tile_offsets[tile + 1];
  // Per-ref data in arrays sized once per tile (no growth check per reference).
  s.setup.resize(end - begin);
  s.clip_map.resize(end - begin);
  s.flags.resize(end - begin);
  s.object.resize(end - begin);
  // The records are gathered from their chunks (whole 64-byte lines, mostly from memory):
  // prefetched far enough ahead to cover a DRAM miss behind the small triangles' short work.
  const std::uint32_t* refs = bins.refs.data();
  for (std::uint32_t k = begin; k < std::min(end, begin + kRecordPrefetch); ++k)
    _mm_prefetch(reinterpret_cast<const char*>(&bins.record(refs[k])), _MM_HINT_T0);
  for (std::uint32_t k = begin; k < end; ++k) {
    if (k + kRecordPrefetch < end)
      _mm_prefetch(reinterpret_cast<const char*>(&bins.record(refs[k + kRecordPrefetch])), _MM_HINT_T0);
    const SetupTriangle& t = bins.record(refs[k]);
    const std::uint32_t ref = k - begin;
    s.setup[ref] = &t;
    s.clip_map[ref] = t.clip_map >= 0 ? &bins.clip_map(refs[k], t) : nullptr;
    s.flags[ref] = (t.swapped ? kRefSwapped : 0u) | (t.clip_map >= 0 ? kRefClipped : 0u);
    s.object[ref] = t.object;
    raster_triangle<W>(t, ref, tx0, ty0, tx1, ty1, s);
  }

  // Resolve: barycentrics only for the winners (deferred, like a visibility buffer).
  if (W == 8 && !s.count_coverage) {
    const bool stream = std::size_t(vp.width) * std::size_t(vp.height) >= kStreamingMinSamples;
    resolve_tile_avx2(s, tx0, ty0, tx1, ty1, vp, stream, out);
    return;
  }
  const SampleOut frame = frame_out(out);
  for (int y = ty0; y <= ty1; ++y) {
    for (int x = tx0; x <= tx1; ++x) {
      const int idx = (y - ty0) * kTileSize + (x - tx0);
      const std::size_t o = static_cast<std::size_t>(y) * vp.width + x;
      if (s.count_coverage) out.coverage.pixels[o] = s.coverage[idx];
      resolve_sample(s, idx, o, frame);
    }
  }
}

}  // namespace

void rasterize_tile(int tile, int lanes, const TileGrid& grid, const Viewport& viewport,
                    const TileBins& bins, VisibilityBuffer& out) {
  par::dispatch_lanes(lanes, [&](auto w) {
    rasterize_tile_w<decltype(w)::value>(tile, grid, viewport, bins, out);
  });
}

}  // namespace speculum::raster
