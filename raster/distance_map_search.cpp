// The distance-map search on a cube map: see distance_map_search.h.
#include "raster/distance_map_search.h"

#include <bit>
#include <cstdint>
#include <limits>

#include "parallel/lanes.h"
#include "raster/cube_coord_lanes.h"

namespace speculum::raster {

namespace {

using L = par::Lanes<8>;
using f32 = L::f32;
using i32 = L::i32;

// A cube's six distance faces: each face's first texel.
struct DistanceFaces {
  const float* pixels[kCubeFaces];
  explicit DistanceFaces(const CubeMap& map) {
    for (int f = 0; f < kCubeFaces; ++f) pixels[f] = map.distance[f].pixels.data();
  }
};

// ratio() for eight points l = x + r d at once (x and r per lane), each lane with its
// operations in their order (l, |l|, cube_coord, the nearest texel's distance, |l| / stored
// or 0 where the map is empty), so the same bits; lanes outside `wanted` read nothing. The
// lanes that read the map (what ratio() counts) in `reads`.
[[gnu::always_inline]] inline f32 ratio8(const CubeMap& map, const DistanceFaces& faces, const f32 (&x)[3],
                                         const f32 (&r)[3], const f32& d, const L::mask& wanted, L::mask& reads) {
  const f32 l[3] = {x[0] + r[0] * d, x[1] + r[1] * d, x[2] + r[2] * d};
  const f32 len = L::sqrt((l[0] * l[0] + l[1] * l[1]) + l[2] * l[2]);
  reads = !(len <= 0.0f) && wanted;
  const CubeCoordLanes c = cube_coord8(l, map.size);
  // distance_at's texel; lanes that read nothing (l = 0: their coordinates are NaN, which
  // no float-to-int conversion may see) read texel 0 of face 0 instead.
  const CubeCoordLanes at{L::select(reads, c.face, i32(0)), L::select(reads, c.x, f32(0.0f)), L::select(reads, c.y, f32(0.0f))};
  i32 tx, ty;
  nearest_texel8(at, map.size, tx, ty);
  alignas(32) std::int32_t fx[8], texel[8];
  L::store_aligned(at.face, fx), L::store_aligned(ty * i32(map.size) + tx, texel);
  alignas(32) float stored_at[8];
  for (int j = 0; j < 8; ++j) stored_at[j] = faces.pixels[fx[j]][texel[j]];
  const f32 stored = L::load_aligned(stored_at);
  const f32 g = L::select(L::abs(stored) == std::numeric_limits<float>::infinity(), f32(0.0f), len / stored);
  return L::select(reads, g, f32(0.0f));
}

// The linear march on a cube map, eight samples in lanes: per lane the operations of the
// march's parameter and of ratio() in their order, so the same bits.
struct CubeMarch {
  const CubeMap& map;
  DistanceFaces faces;
  explicit CubeMarch(const CubeMap& m) : map(m), faces(m) {}
  void operator()(const glm::vec3& x, const glm::vec3& r, float x_len, int n, int first, MarchBatch& b) const {
    const i32 k = L::iota(first);
    batch(k, L::to_float(k) / float(n), n, x, r, x_len, b);
  }
  // The same batch of two marches (a and b) in one call: two independent chains of work side
  // by side, each with its own operations.
  void pair(const glm::vec3& xa, const glm::vec3& ra, float xa_len, const glm::vec3& xb, const glm::vec3& rb,
            float xb_len, int n, int first, MarchBatch& a, MarchBatch& b) const {
    const i32 k = L::iota(first);
    const f32 t = L::to_float(k) / float(n);
    batch(k, t, n, xa, ra, xa_len, a);
    batch(k, t, n, xb, rb, xb_len, b);
  }

 private:
  [[gnu::always_inline]] void batch(const i32& k, const f32& t, int n, const glm::vec3& x, const glm::vec3& r, float x_len,
                                    MarchBatch& b) const {
    const f32 d = L::select(k == 0, f32(0.0f), x_len * t / (1.0f - t));
    const f32 xs[3] = {f32(x.x), f32(x.y), f32(x.z)}, rs[3] = {f32(r.x), f32(r.y), f32(r.z)};
    L::mask reads;
    const f32 g = ratio8(map, faces, xs, rs, d, L::mask(k < n), reads);
    L::store(g, b.g);
    L::store(d, b.d);
    L::store(L::select(reads, i32(1), i32(0)), b.counted);
  }
};

// refine_bracket for the searches j with bit j of `pending` (from x[j] along r[j]), side by
// side: per lane the scalar steps (secant_from_ratios, ratio, the bracket's update, the stop
// at a ratio of 1).
void refine_brackets8(const CubeMap& map, const glm::vec3* x, const glm::vec3* r, const distance_search_detail::Bracket* b,
                      unsigned pending, const DistanceSearchOptions& o, DistanceSearchResult* out) {
  // Lanes of other searches repeat the first pending one: valid inputs, results dropped.
  const int first = std::countr_zero(pending);
  alignas(32) float in[10][8];
  for (int j = 0; j < 8; ++j) {
    const int k = (pending >> j) & 1u ? j : first;
    in[0][j] = b[k].d_l, in[1][j] = b[k].g_l, in[2][j] = b[k].d_p, in[3][j] = b[k].g_p;
    in[4][j] = r[k].x, in[5][j] = r[k].y, in[6][j] = r[k].z;
    in[7][j] = x[k].x, in[8][j] = x[k].y, in[9][j] = x[k].z;
  }
  f32 d_l = L::load_aligned(in[0]), g_l = L::load_aligned(in[1]), d_p = L::load_aligned(in[2]),
      g_p = L::load_aligned(in[3]);
  const f32 rs[3] = {L::load_aligned(in[4]), L::load_aligned(in[5]), L::load_aligned(in[6])};
  const f32 xs[3] = {L::load_aligned(in[7]), L::load_aligned(in[8]), L::load_aligned(in[9])};
  alignas(32) std::int32_t bits[8];
  for (int j = 0; j < 8; ++j) bits[j] = (pending >> j) & 1u ? -1 : 0;
  L::mask active = L::load_aligned(bits) != i32(0);
  const DistanceFaces faces(map);
  f32 best = d_p;
  i32 lookups(0);
  const f32 inf(std::numeric_limits<float>::infinity());
  for (int s = 0; o.secant && s < o.secant_steps && L::any(active); ++s) {
    // secant_from_ratios
    const f32 denom = g_p - g_l;
    const L::mask degenerate = denom == 0.0f || !(L::abs(denom) < inf);
    const f32 d_new = L::select(degenerate, d_l, d_l + (d_p - d_l) * (1.0f - g_l) / denom);
    best = L::select(active, d_new, best);
    L::mask reads;
    const f32 g_new = ratio8(map, faces, xs, rs, d_new, active, reads);
    lookups = lookups + L::select(reads, i32(1), i32(0));
    const L::mask under = active && g_new < 1.0f, over = active && !(g_new < 1.0f);
    d_l = L::select(under, d_new, d_l), g_l = L::select(under, g_new, g_l);
    d_p = L::select(over, d_new, d_p), g_p = L::select(over, g_new, g_p);
    active = active && !(g_new == 1.0f);
  }
  alignas(32) float best_at[8];
  alignas(32) std::int32_t lookups_at[8];
  L::store_aligned(best, best_at), L::store_aligned(lookups, lookups_at);
  for (int j = 0; j < 8; ++j) {
    if (!((pending >> j) & 1u)) continue;
    out[j].bracketed = true;
    out[j].lookups += lookups_at[j];
    out[j].d = best_at[j];
    out[j].direction = distance_search_detail::hit_direction(x[j], r[j], best_at[j]);
  }
}

}  // namespace

DistanceSearchResult search_distance_map(const CubeMap& map, const glm::vec3& x_world,
                                         const glm::vec3& r, const DistanceSearchOptions& options) {
  return search_distance([&](const glm::vec3& d) { return map.distance_towards(d); }, CubeMarch{map},
                         x_world - map.centre, r, options);
}

void search_distance_map8(const CubeMap& map, const glm::vec3* x_world, const glm::vec3* r, int count,
                          const DistanceSearchOptions& options, DistanceSearchResult* out) {
  using namespace distance_search_detail;
  const bool march = options.linear && options.linear_steps >= 2;
  if (count < 2 || !march) {
    for (int j = 0; j < count; ++j) out[j] = search_distance_map(map, x_world[j], r[j], options);
    return;
  }
  const auto towards = [&](const glm::vec3& d) { return map.distance_towards(d); };
  glm::vec3 x[8];
  float x_len[8];
  Bracket b[8];
  MarchState state[8];
  unsigned marching = 0;
  for (int j = 0; j < count; ++j) {
    x[j] = x_world[j] - map.centre;
    x_len[j] = glm::length(x[j]);
    if (x_len[j] == 0.0f) {  // a direct lookup (search_distance)
      out[j] = search_distance_map(map, x_world[j], r[j], options);
      continue;
    }
    out[j] = {};
    marching |= 1u << j;
  }
  // The marches batch by batch: each batch of every search still marching is computed before
  // any is scanned (independent work side by side, no branch on a scan between them), each
  // search's batches and scans in its own order, so the same results as march_to_bracket.
  const int n = options.linear_steps;
  MarchBatch batch[8];
  const CubeMarch marcher(map);
  for (int first = 0; first < n && marching; first += kMarchBatch) {
    for (unsigned m = marching; m;) {
      const int j = std::countr_zero(m);
      m &= m - 1;
      if (!m) {
        marcher(x[j], r[j], x_len[j], n, first, batch[j]);
        break;
      }
      const int i = std::countr_zero(m);
      m &= m - 1;
      marcher.pair(x[j], r[j], x_len[j], x[i], r[i], x_len[i], n, first, batch[j], batch[i]);
    }
    for (unsigned m = marching; m; m &= m - 1) {
      const int j = std::countr_zero(m);
      scan_batch(batch[j], first, n, state[j], out[j].lookups, b[j]);
      if (state[j].ended) marching &= ~(1u << j);
    }
  }
  unsigned pending = 0;
  for (int j = 0; j < count; ++j) {
    if (b[j].found) pending |= 1u << j;
    else if (x_len[j] != 0.0f) search_unbracketed(towards, x[j], r[j], options, out[j]);
  }
  if (pending) refine_brackets8(map, x, r, b, pending, options, out);
}

std::string describe_search(const DistanceSearchOptions& o) {
  return "parallax=" + (o.parallax ? std::to_string(o.parallax_steps) : std::string("off")) +
         " linear=" + (o.linear ? std::to_string(o.linear_steps) : std::string("off")) +
         " secant=" + (o.secant ? std::to_string(o.secant_steps) : std::string("off")) +
         " lobe=" + std::to_string(o.lobe_directions);
}

}  // namespace speculum::raster
