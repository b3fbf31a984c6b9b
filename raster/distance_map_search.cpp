// The distance-map search on a cube map: see distance_map_search.h.
#include "raster/distance_map_search.h"

#include <cstdint>
#include <limits>

#include "parallel/lanes.h"
#include "raster/cube_coord_lanes.h"

namespace speculum::raster {

namespace {

// The linear march on a cube map, eight samples in lanes: per lane the operations of the
// march's parameter and of ratio() (l = x + r d, |l|, cube_coord, the nearest texel's
// distance, |l| / stored or 0 where the map is empty) in their order, so the same bits.
struct CubeMarch {
  const CubeMap& map;
  void operator()(const glm::vec3& x, const glm::vec3& r, float x_len, int n, int first, MarchBatch& b) const {
    using L = par::Lanes<8>;
    using f32 = L::f32;
    using i32 = L::i32;
    const i32 k = L::iota(first);
    const f32 t = L::to_float(k) / float(n);
    const f32 d = L::select(k == 0, f32(0.0f), x_len * t / (1.0f - t));
    const f32 l[3] = {x.x + r.x * d, x.y + r.y * d, x.z + r.z * d};
    const f32 len = L::sqrt((l[0] * l[0] + l[1] * l[1]) + l[2] * l[2]);
    const L::mask reads = !(len <= 0.0f) && L::mask(k < n);
    const CubeCoordLanes c = cube_coord8(l, map.size);
    // distance_at's texel; lanes that read nothing (l = 0: their coordinates are NaN, which
    // no float-to-int conversion may see) read texel 0 of face 0 instead.
    const i32 last(map.size - 1), zero(0);
    const f32 at_x = L::select(reads, c.x, f32(0.0f)), at_y = L::select(reads, c.y, f32(0.0f));
    const i32 tx = L::clamp(L::to_int(at_x), zero, last), ty = L::clamp(L::to_int(at_y), zero, last);
    const i32 face = L::select(reads, c.face, zero);
    alignas(32) std::int32_t fx[8], px[8], py[8];
    L::store_aligned(face, fx), L::store_aligned(tx, px), L::store_aligned(ty, py);
    alignas(32) float stored_at[8];
    for (int j = 0; j < 8; ++j) stored_at[j] = map.distance[fx[j]].at(px[j], py[j]);
    const f32 stored = L::load_aligned(stored_at);
    const f32 g = L::select(L::abs(stored) == std::numeric_limits<float>::infinity(), f32(0.0f), len / stored);
    L::store(L::select(reads, g, f32(0.0f)), b.g);
    L::store(d, b.d);
    L::store(L::select(reads, i32(1), zero), b.counted);
  }
};

}  // namespace

DistanceSearchResult search_distance_map(const CubeMap& map, const glm::vec3& x_world,
                                         const glm::vec3& r, const DistanceSearchOptions& options) {
  return search_distance([&](const glm::vec3& d) { return map.distance_towards(d); }, CubeMarch{map},
                         x_world - map.centre, r, options);
}

std::string describe_search(const DistanceSearchOptions& o) {
  return "parallax=" + (o.parallax ? std::to_string(o.parallax_steps) : std::string("off")) +
         " linear=" + (o.linear ? std::to_string(o.linear_steps) : std::string("off")) +
         " secant=" + (o.secant ? std::to_string(o.secant_steps) : std::string("off")) +
         " lobe=" + std::to_string(o.lobe_directions);
}

}  // namespace speculum::raster
