// Dynamic environment maps per reflector: see reflector_maps.h.
#include "raster/reflector_maps.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "core/sampling.h"

#include "parallel/compact.h"
#include "raster/direct_light.h"
#include "raster/envmap_reflect.h"
#include "raster/planar_mirror.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {

namespace {

// Mean position and normal of object `object`'s samples, summed serially in sample order
// (a fixed-order reduction). False when the object covers no sample.
bool visible_centroid(const GBuffer& g, std::uint32_t object, glm::vec3& centre, glm::vec3& normal) {
  glm::dvec3 p(0.0), n(0.0);
  std::size_t count = 0;
  for (std::size_t i = 0; i < g.object.size(); ++i)
    if (g.object.pixels[i] == object) {
      p += glm::dvec3(g.position.pixels[i]);
      n += glm::dvec3(g.normal.pixels[i]);
      ++count;
    }
  if (count == 0) return false;
  centre = glm::vec3(p / double(count));
  const double nl = glm::length(n);
  normal = nl > 0.0 ? glm::vec3(n / nl) : glm::vec3(0.0f, 1.0f, 0.0f);
  return true;
}

// The smallest Phong exponent a reflection node reads an object's map with for this
// material: refractors read sharply (specular_radiance.h); a roughness texture can only
// scale roughness down (glTF), but be safe and keep every level then (exponent 0).
float map_lookup_exponent(const Material& material, const SurfaceParams& s) {
  if (s.is_refractor()) return kSharpLookupExponent;
  if (material.metallic_roughness_texture.valid()) return 0.0f;
  return s.phong_exponent;
}

// The finest share of a reflector's samples whose need sets its map's side: a few samples
// on a concave spot or a crease (reflected directions almost equal) do not force the cap on
// the whole map, while the reflector's smooth bulk is sampled at least as finely as it is
// seen.
constexpr double kFootprintQuantile = 0.05;

// Texels per step between neighbouring samples' reflected directions: 2 would be the
// sampling rate, twice that keeps the bilinear blur of a lookup well under the pixel step
// (at 2 the exact specular error of a mirror sphere seen at 160×120 grew by 0.5%).
constexpr float kTexelsPerSampleStep = 4.0f;

// Half-power angle of a Phong lobe of exponent n (cos^n θ = 1/2, small-angle form).
float lobe_half_power_angle(float n) { return std::sqrt(2.0f * 0.69314718f / std::max(n, 1e-6f)); }

// The texel angle a glossy lobe of exponent n needs: `share` of the half-power angle of
// distance-map's sharpest read of it, the sub-lobe of exponent 4n (distance_map_reflect.cpp).
float glossy_need(float n, float share) { return share * lobe_half_power_angle(4.0f * n); }

// Maps read along R (from_footprint): a quarter keeps every read at level 2 or above
// (prefiltered, as with the full-size map).
constexpr float kFootprintTexelShare = 0.25f;
// Searched maps (from_lobes): a quarter halved living-room's floor map (n ≈ 131) and its frame
// error grew (matrix at 160×120, distance-map 19.23 → 19.32 mae8); at this share the floor
// keeps 256² and only the wider lobes shrink (the vase, n ≈ 47, to 128²), with no error grown.
constexpr float kLobeTexelShare = 0.15f;

constexpr float kTexelAngleTimesSize = 0.5f * kPi;  // texel angle of a side-s face: (π/2)/s

// The smallest power-of-two side (at least kMinFootprintSize, at most `size`) whose texel
// angle is at most `need`.
int side_for_need(float need, int size) {
  int side = kMinFootprintSize;
  while (side < size && !(kTexelAngleTimesSize / static_cast<float>(side) <= need)) side *= 2;
  return std::min(side, size);
}

// The coarsest texel angle camera sample i can use without losing what the frame shows,
// or NaN when i reads no map or has no neighbour on its object. Samples sit one pixel
// apart; their reflected directions R differ by δ (the chord, at most the angle), and a
// texel of δ / kTexelsPerSampleStep keeps that many texels per sample step. A glossy lookup
// reads the map blurred by its lobe; the sharpest read is distance-map's sub-lobe of exponent
// 4n (distance_map_reflect.cpp), half the lobe's angle, and a texel of a quarter of that
// keeps every read at level 2 or above (prefiltered, as with the full-size map) — the coarser
// of the two is enough.
float sample_need(const GBuffer& g, std::size_t i) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (!g.covered(i)) return nan;
  const SurfaceParams& s = g.surface[i];
  if (!is_specular(s) || s.is_refractor()) return nan;
  const std::uint32_t object = g.object.pixels[i];
  const auto reflected = [&](std::size_t j) { return reflect(-g.view_direction(j), g.normal.pixels[j]); };
  const glm::vec3 r = reflected(i);
  const std::size_t w = static_cast<std::size_t>(g.width);
  const std::size_t x = i % w, y = i / w;
  float delta = std::numeric_limits<float>::infinity();
  const auto neighbour = [&](std::size_t j) {
    if (g.object.pixels[j] != object || !is_specular(g.surface[j])) return;
    delta = std::min(delta, glm::length(reflected(j) - r));
  };
  if (x + 1 < w) neighbour(i + 1);
  if (x > 0) neighbour(i - 1);
  if (y + 1 < static_cast<std::size_t>(g.height)) neighbour(i + w);
  if (y > 0) neighbour(i - w);
  if (!std::isfinite(delta)) return nan;
  float need = delta / kTexelsPerSampleStep;
  if (!s.is_mirror_lobe() && s.phong_exponent > 0.0f && s.phong_exponent < 1e6f)
    need = std::max(need, glossy_need(s.phong_exponent, kFootprintTexelShare));
  return need;
}

// Faces within `margin` of the great-circle arc from unit a to unit b: points along it at
// most 0.1 rad apart, each tested with the margin grown by half a step (every point of the
// arc is that close to one of them). Nearly opposite ends have no one arc: every face.
unsigned faces_near_arc(const glm::vec3& a, const glm::vec3& b, float margin) {
  const float angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
  if (!(angle < kPi - 0.05f)) return 0x3fu;
  const int steps = std::max(1, static_cast<int>(std::ceil(angle / 0.1f)));
  const float step = angle / static_cast<float>(steps);
  const float sin_angle = std::sin(angle);
  unsigned mask = 0;
  for (int i = 0; i <= steps; ++i) {
    const float u = static_cast<float>(i) / static_cast<float>(steps);
    const glm::vec3 p = sin_angle > 1e-6f ? glm::normalize((std::sin((1.0f - u) * angle) * a + std::sin(u * angle) * b) / sin_angle)
                                          : a;
    mask |= cube_faces_near(p, margin + 0.5f * step + 1e-3f);
  }
  return mask;
}

// The widest of `count` Hamersley directions of a Phong lobe of exponent n about its axis
// (sample_phong_lobe: u.x = (count−1)/count gives cos θ = (1/count)^(1/(n+1))).
float widest_lobe_sample(int count, float n) {
  return std::acos(std::pow(1.0f / static_cast<float>(count), 1.0f / (n + 1.0f)));
}

// Margins at or beyond this angle mark every face they reach whole: a tile bound would cover
// most of the face anyway, and below it the bound of mark_near holds.
constexpr float kWholeFaceMargin = 0.5f;

// Sets tiles t[first, first + count): chunks of samples mark one mask at once, and a tile is
// only ever set to 1, so the mask is the same whatever thread marked what. A tile already set
// is not written again (the threads would otherwise trade its cache line back and forth).
void mark(std::vector<std::uint8_t>& t, std::size_t first, std::size_t count) {
  for (std::size_t k = first; k < first + count; ++k) {
    std::atomic_ref<std::uint8_t> tile(t[k]);
    if (!tile.load(std::memory_order_relaxed)) tile.store(1, std::memory_order_relaxed);
  }
}

// Adds to `whole` the faces whose every tile is set (by any chunk): marking skips them.
void note_full_faces(std::array<std::vector<std::uint8_t>, kCubeFaces>& tiles, unsigned& whole) {
  for (int f = 0; f < kCubeFaces; ++f) {
    if ((whole >> f) & 1u) continue;
    std::vector<std::uint8_t>& t = tiles[f];
    bool full = true;
    for (std::size_t k = 0; k < t.size() && full; ++k)
      full = std::atomic_ref<std::uint8_t>(t[k]).load(std::memory_order_relaxed) != 0;
    if (full) whole |= 1u << f;
  }
}

// The angle within which lookup_level's bilinear taps lie around a direction: a texel's
// diagonal (lookup_reach for a lobe read at level 0 alone).
float texel_reach(int size) { return 2.0f * 1.4142136f / static_cast<float>(size); }

// Marks in `tiles` (one CubeTileMask face array each, n tiles of `tile` texels a side, for a
// map of side `size`) the tiles holding every texel centre within angle `margin` of unit
// direction d. Along a great circle the face-plane coordinate ndc = (p·right)/(p·forward)
// moves at most 1/(p·forward)² per radian. A texel t read by d lies on face f (within
// acos(1/√3) of its axis) and every point p of the arc from d to t is within `margin` of both
// t and d, so along it p·forward ≥ cos(min(acos(1/√3), θ_d) + margin) = z, θ_d being d's angle
// to the axis: t is at most margin/z² in ndc, margin·size/(2z²) texels, from d's point on the
// face's plane. One texel more absorbs rounding.
// `whole` (bit f: face f marked whole already) spares a caller marking many directions the
// repeated whole-face marks.
// `last` (may be null): per face the rectangle of tiles the caller's previous mark set there
// (x0, y0, x1, y1), updated here; a rectangle within it is not marked again.
// The rectangle of tiles (x0, y0, x1, y1) of face f that mark_near marks for d and `margin`
// (below kWholeFaceMargin); false when it is empty.
bool tiles_near_on_face(int f, int tile, int n, int size, const glm::vec3& d, float margin, std::array<int, 4>& rect) {
  constexpr float kFaceHalfAngle = 0.95531662f;  // acos(1/√3)
  const float theta_d = std::acos(std::clamp(glm::dot(d, cube_direction(f, {0.5f, 0.5f}, 1)), -1.0f, 1.0f));
  const float z = std::cos(std::min(kFaceHalfAngle, theta_d) + margin);
  const float half = margin * static_cast<float>(size) / (2.0f * z * z) + 1.0f;
  const glm::vec2 p = cube_face_plane_pixel(f, d, size);
  const float lo_x = (p.x - half) / tile, hi_x = (p.x + half) / tile;
  const float lo_y = (p.y - half) / tile, hi_y = (p.y + half) / tile;
  if (!(hi_x >= 0.0f && hi_y >= 0.0f && lo_x < float(n) && lo_y < float(n))) return false;
  rect = {std::max(0, static_cast<int>(std::floor(lo_x))), std::max(0, static_cast<int>(std::floor(lo_y))),
          std::min(n - 1, static_cast<int>(hi_x)), std::min(n - 1, static_cast<int>(hi_y))};
  return true;
}

void mark_near(std::array<std::vector<std::uint8_t>, kCubeFaces>& tiles, int tile, int n, int size,
               const glm::vec3& d, float margin, unsigned& whole,
               std::array<std::array<int, 4>, kCubeFaces>* last = nullptr) {
  const unsigned faces = cube_faces_near(d, margin) & ~whole;
  for (int f = 0; f < kCubeFaces; ++f) {
    if (!((faces >> f) & 1u)) continue;
    std::vector<std::uint8_t>& t = tiles[f];
    if (margin >= kWholeFaceMargin) {
      mark(t, 0, t.size());
      whole |= 1u << f;
      continue;
    }
    std::array<int, 4> rect;
    if (!tiles_near_on_face(f, tile, n, size, d, margin, rect)) continue;
    const auto [x0, y0, x1, y1] = rect;
    if (last) {
      std::array<int, 4>& r = (*last)[f];
      if (x0 >= r[0] && y0 >= r[1] && x1 <= r[2] && y1 <= r[3]) continue;
      r = rect;
    }
    for (int y = y0; y <= y1; ++y) mark(t, static_cast<std::size_t>(y) * n + x0, static_cast<std::size_t>(x1 - x0 + 1));
  }
}

// Marks the level-0 texels a lookup along unit direction d reads when it reads level 0 alone
// (EnvironmentMap::radiance of a lobe no wider than a texel: lookup_level's bilinear taps),
// with a hundredth of a texel to spare for the rounding of the reader's own (unnormalized)
// direction. Near a face's edge, where that rounding could pick the neighbouring face, the
// angular bound of mark_near marks instead.
void mark_taps(std::array<std::vector<std::uint8_t>, kCubeFaces>& tiles, int tile, int n, int size,
               const glm::vec3& d, unsigned& whole) {
  const glm::vec3 a = glm::abs(d);
  const float largest = std::max({a.x, a.y, a.z});
  const float second = a.x == largest ? std::max(a.y, a.z) : a.y == largest ? std::max(a.x, a.z) : std::max(a.x, a.y);
  if (second >= largest * (1.0f - 1e-3f)) {
    mark_near(tiles, tile, n, size, d, texel_reach(size), whole);
    return;
  }
  const CubeCoord c = cube_coord(d, size);
  constexpr float kSlack = 0.01f;
  const float last = static_cast<float>(size - 1);
  // bilinear_face's taps: x0 = int(clamp(x − 0.5, 0, side − 1)) and x0 + 1 (clamped).
  const auto first_tap = [&](float p, float delta) { return static_cast<int>(std::clamp(p - 0.5f + delta, 0.0f, last)); };
  const int x0 = first_tap(c.pixel.x, -kSlack), x1 = std::min(first_tap(c.pixel.x, kSlack) + 1, size - 1);
  const int y0 = first_tap(c.pixel.y, -kSlack), y1 = std::min(first_tap(c.pixel.y, kSlack) + 1, size - 1);
  for (int y = y0 / tile; y <= y1 / tile; ++y)
    mark(tiles[c.face], static_cast<std::size_t>(y) * n + x0 / tile, static_cast<std::size_t>(x1 / tile - x0 / tile + 1));
}

// Records in the coarse cell of direction d (any length, non-zero) a read of reach `reach`:
// the cell keeps the widest (a max of positive floats' bits, the same whatever order the
// threads record in).
void record_wide_read(CubeTileMask& mask, const glm::vec3& d, float reach) {
  const int cells = mask.wide_cells();
  const CubeCoord c = cube_coord(d, cells);
  const int x = std::min(static_cast<int>(c.pixel.x), cells - 1), y = std::min(static_cast<int>(c.pixel.y), cells - 1);
  std::atomic_ref<std::uint32_t> cell(mask.wide[c.face][static_cast<std::size_t>(y) * cells + x]);
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(reach);
  std::uint32_t now = cell.load(std::memory_order_relaxed);
  while (now < bits && !cell.compare_exchange_weak(now, bits, std::memory_order_relaxed)) {
  }
}

// The largest angle from the centre direction of a square of `span` texels (a tile or a
// cell) of a face of side `size` to its corners, over every such square of a face: a point in
// the square is no farther from its centre's direction (the square is a convex spherical
// quadrilateral, farthest at a corner). When the squares tile the face evenly, the face's
// mirror symmetries (x ↔ n−1−x, y ↔ n−1−y, x ↔ y, each an isometry of the sphere) map them
// onto each other, so one eighth of them holds every radius (float rounding aside, which
// settle_wide_reads' margin covers).
float square_radius(int size, int span) {
  float widest = 0.0f;
  const int n = (size + span - 1) / span;
  const bool even = size % span == 0;
  const int half = even ? (n + 1) / 2 : n;
  for (int y = 0; y < half; ++y)
    for (int x = even ? y : 0; x < half; ++x) {
      const float x0 = float(x * span), y0 = float(y * span);
      const float x1 = float(std::min(size, (x + 1) * span)), y1 = float(std::min(size, (y + 1) * span));
      const glm::vec3 centre = cube_direction(0, {0.5f * (x0 + x1), 0.5f * (y0 + y1)}, size);
      for (const glm::vec2 corner : {glm::vec2(x0, y0), glm::vec2(x1, y0), glm::vec2(x0, y1), glm::vec2(x1, y1)})
        widest = std::max(widest, std::acos(std::clamp(glm::dot(centre, cube_direction(0, corner, size)), -1.0f, 1.0f)));
    }
  return widest;
}

// The direction of the centre of tile (tx, ty) of face f (a partial last tile's own centre).
glm::vec3 tile_centre(const CubeTileMask& mask, int f, int tx, int ty) {
  const float x0 = float(tx * mask.tile), y0 = float(ty * mask.tile);
  const float x1 = float(std::min(mask.size, (tx + 1) * mask.tile)), y1 = float(std::min(mask.size, (ty + 1) * mask.tile));
  return cube_direction(f, {0.5f * (x0 + x1), 0.5f * (y0 + y1)}, mask.size);
}

// A reflector map face's colour (MapFaceLayers: `kept`, may be null, receives its layers).
CubeFaceShader reflector_face_shader(par::Executor& executor, const Scene& scene, const std::vector<ShadowMap>& shadows,
                                     const EnvironmentMap& env, const FaceLight& add_light, MapFaceLayers* kept) {
  return [&executor, &scene, &shadows, &env, &add_light, kept](const GBuffer& g, const Camera& cam, int face,
                                                                const std::vector<std::uint8_t>* read) {
    // Other reflectors seen in this map show the environment along their own R (and T): the
    // first-order fallback, so a mirror seen in a mirror is never black.
    ImageRGBA direct = direct_light(executor, scene, g, cam, shadows, env, read);
    if (add_light) direct = add_light(g, direct);
    if (kept) {
      kept->specular[face] = specular_texels(executor, g, kept->specular_texel[face]);
      kept->direct[face] = direct;
    }
    envmap_reflect_onto(executor, g, env, direct);
    return direct;
  };
}

}  // namespace

void mark_tiles_near(CubeTileMask& mask, const glm::vec3& d, float margin) {
  const int n = mask.tiles_per_side();
  for (auto& t : mask.tiles)
    if (t.size() != static_cast<std::size_t>(n) * n) t.assign(static_cast<std::size_t>(n) * n, 0);
  unsigned whole = 0;
  mark_near(mask.tiles, mask.tile, n, mask.size, d, margin, whole);
}

GBuffer specular_texels(par::Executor& executor, const GBuffer& g, std::vector<std::uint32_t>& texel) {
  constexpr std::size_t kChunk = 4096;
  std::vector<std::uint8_t> keep(g.object.size());
  executor.parallel_for("specular_texels.keep", keep.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) keep[i] = g.covered(i) && is_specular(g.surface[i]);
  });
  texel.resize(keep.size());
  texel.resize(par::compact_scatter(executor, "specular_texels", keep, texel));
  const int n = static_cast<int>(texel.size());
  GBuffer out;
  out.width = n;
  out.height = n > 0 ? 1 : 0;
  out.eye = g.eye;
  out.object = IdBuffer(n, out.height);
  out.position = Buffer2D<glm::vec3>(n, out.height);
  out.normal = Buffer2D<glm::vec3>(n, out.height);
  out.uv = Buffer2D<glm::vec2>(n, out.height);
  out.surface.slot = IdBuffer(n, out.height);
  out.surface.shared = g.surface.shared;
  if (!g.surface.own.empty()) out.surface.own = Buffer2D<SurfaceParams>(n, out.height);
  out.reflector = IdBuffer(n, out.height);
  executor.parallel_for("specular_texels.gather", texel.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = texel[k];
      out.object.pixels[k] = g.object.pixels[i];
      out.position.pixels[k] = g.position.pixels[i];
      out.normal.pixels[k] = g.normal.pixels[i];
      out.uv.pixels[k] = g.uv.pixels[i];
      out.surface.slot.pixels[k] = g.surface.slot.pixels[i];
      if (!g.surface.own.empty()) out.surface.own.pixels[k] = g.surface.own.pixels[i];
      out.reflector.pixels[k] = g.reflector.pixels[i];
    }
  });
  return out;
}

CubeTileMask tile_mask_for_reads(int size, int level_count) {
  CubeTileMask mask;
  mask.size = size;
  // A map read at level 0 alone (mirror lobes) is read at each lookup's bilinear taps: texel
  // tiles. A prefiltered level reads a wide footprint of level 0 anyway.
  if (level_count == 1) mask.tile = 1;
  const int n_tiles = mask.tiles_per_side();
  for (auto& t : mask.tiles) t.assign(static_cast<std::size_t>(n_tiles) * n_tiles, 0);
  const int cells = mask.wide_cells();
  if (mask.tile > 1)
    for (auto& w : mask.wide) w.assign(static_cast<std::size_t>(cells) * cells, 0u);
  return mask;
}

std::vector<CubeTileMask> tile_masks_for_reads(const ReflectorMaps& maps) {
  std::vector<CubeTileMask> masks;
  for (std::size_t m = 0; m < maps.cubes.size(); ++m) masks.push_back(tile_mask_for_reads(maps.cubes[m].size, maps.levels[m]));
  return masks;
}

LookupTileMarker::LookupTileMarker(CubeTileMask& mask, int level_count) : mask_(mask), level_count_(level_count) {
  for (std::array<int, 4>& r : last_marked_) r = {0, 0, -1, -1};
}

void LookupTileMarker::mark(const glm::vec3& d, float exponent) {
  const int size = mask_.size, n_tiles = mask_.tiles_per_side();
  if (!(exponent == last_exponent_)) {
    last_exponent_ = exponent;
    margin_ = std::max(lookup_reach(size, level_count_, exponent), 1e-3f);
    level0_ = levels_for_lobes(size, exponent) == 1;
    wide_ = !level0_ && margin_ >= kWholeFaceMargin && !mask_.wide[0].empty();
  }
  if (wide_) {
    record_wide_read(mask_, d, margin_);
    return;
  }
  // A wide lobe's marks soon fill whole faces (every sample of a glossy floor marks most of
  // a face): faces found full stop costing their marks' arithmetic. Maps of one-texel tiles
  // (level 0 alone) are too large to scan this often.
  if (mask_.tile > 1 && ++marks_ % 256 == 0) note_full_faces(mask_.tiles, whole_);
  if (whole_ == 0x3fu) return;  // every face marked whole: nothing left to mark
  const glm::vec3 r = glm::normalize(d);
  if (level0_) mark_taps(mask_.tiles, mask_.tile, n_tiles, size, r, whole_);
  else mark_near(mask_.tiles, mask_.tile, n_tiles, size, r, margin_, whole_, &last_marked_);
}

void settle_wide_reads(par::Executor& executor, CubeTileMask& mask) {
  if (!mask.active() || mask.wide[0].empty()) return;
  const int cells = mask.wide_cells(), n = mask.tiles_per_side();
  // The recorded cells: centre direction and the cosine of the widest angle a tile centre
  // may lie from it (the reach, the two squares' radii and a margin for float rounding).
  struct Cell {
    glm::vec3 centre;
    float cos_within;
  };
  std::vector<Cell> recorded;
  float radii = -1.0f;
  for (int f = 0; f < kCubeFaces; ++f)
    for (int y = 0; y < cells; ++y)
      for (int x = 0; x < cells; ++x) {
        const std::uint32_t bits = mask.wide[f][static_cast<std::size_t>(y) * cells + x];
        if (bits == 0u) continue;
        if (radii < 0.0f) radii = square_radius(cells, 1) + square_radius(mask.size, mask.tile) + 1e-3f;
        const float within = std::bit_cast<float>(bits) + radii;
        recorded.push_back({cube_direction(f, {x + 0.5f, y + 0.5f}, cells),
                            within >= kPi ? -2.0f : std::cos(within)});
      }
  if (recorded.empty()) return;
  const std::size_t per_face = static_cast<std::size_t>(n) * n;
  executor.parallel_for("tile_marks.settle_wide", kCubeFaces * per_face, 1024, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const int f = static_cast<int>(k / per_face);
      const std::size_t i = k % per_face;
      std::uint8_t& tile = mask.tiles[f][i];
      if (tile) continue;
      const int tx = static_cast<int>(i % n), ty = static_cast<int>(i / n);
      const glm::vec3 centre = tile_centre(mask, f, tx, ty);
      for (const Cell& c : recorded)
        if (glm::dot(c.centre, centre) >= c.cos_within) {
          tile = 1;
          break;
        }
    }
  });
  // Settled: a later call (marks into the same masks, e.g. each face's searches of a
  // multi-reflection round) tests only what is recorded after this one.
  for (auto& w : mask.wide) std::fill(w.begin(), w.end(), 0u);
}

namespace {

// Whether a level ≥ 1 texel over tile `i` of face f is prefiltered under a face mask and tiles
// (null: all).
bool prefiltered_over(unsigned faces, const CubeTileMask* tiles, int f, std::size_t i) {
  return ((faces >> f) & 1u) && (!tiles || !tiles->active() || (i < tiles->tiles[f].size() && tiles->tiles[f][i]));
}

}  // namespace

PrefilterReuse prefilter_reuse(par::Executor& executor, const std::array<ImageRGBA, kCubeFaces>& faces,
                               unsigned face_mask, const CubeTileMask* tiles, const EnvironmentMap& from,
                               unsigned from_faces, const CubeTileMask* from_tiles, int level_count) {
  PrefilterReuse reuse;
  reuse.from = &from;
  reuse.faces = from_faces;
  reuse.tiles = from_tiles;
  const int size = faces[0].width;
  const int levels = std::min<int>(level_count, static_cast<int>(from.levels.size()));
  CubeTileMask changed = tile_mask_for_reads(std::max(size, 1), 2);
  const int n = changed.tiles_per_side(), tile = changed.tile;
  const bool same_tiles = [&] {  // both masks tile the faces alike (else nothing is taken)
    for (const CubeTileMask* t : {tiles, from_tiles})
      if (t && t->active() && (t->size != size || t->tile != tile)) return false;
    return true;
  }();
  if (size < 1 || levels < 2 || from.size != size || !same_tiles) {
    reuse.faces = 0;  // nothing to take
    return reuse;
  }
  // Level 0: the tiles holding a texel whose bits differ (or a face of another size).
  executor.parallel_for("environment.changed_texels", static_cast<std::size_t>(kCubeFaces) * n, 1,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t row = begin; row < end; ++row) {
      const int f = static_cast<int>(row / n), ty = static_cast<int>(row % n);
      const ImageRGBA &now = faces[f], &was = from.levels[0][f];
      std::uint8_t* marks = &changed.tiles[f][static_cast<std::size_t>(ty) * n];
      if (now.width != size || was.width != size || now.height != size || was.height != size) {
        std::fill(marks, marks + n, std::uint8_t(1));
        continue;
      }
      for (int y = ty * tile; y < std::min(size, (ty + 1) * tile); ++y)
        for (int tx = 0; tx < n; ++tx) {
          if (marks[tx]) continue;
          const int x0 = tx * tile, count = std::min(size, x0 + tile) - x0;
          const std::size_t at = static_cast<std::size_t>(y) * size + x0;
          marks[tx] = std::memcmp(&now.pixels[at], &was.pixels[at], count * sizeof(glm::vec4)) != 0;
        }
    }
  });
  // Level l: every level-l texel with an input (prefilter_reach of its centre) in a texel of
  // level l − 1 under a changed tile. Such an input's centre is within the tile's radius and
  // its own diagonal of the tile's centre, and the level-l texel covers a level-0 texel centre
  // within a level-0 diagonal of its own centre: every tile holding a texel centre within all
  // of these added of the tile's centre is marked, so a tile that texel covers is. Levels past
  // kReusedLevels, and those after most tiles have changed, are all taken as changed: their
  // marks, ever wider, would cost more than the few texels they spare.
  constexpr int kReusedLevels = 2;
  const float tile_radius = square_radius(size, tile);
  std::array<std::vector<glm::vec3>, kCubeFaces> centre;  // every tile's centre direction
  for (int f = 0; f < kCubeFaces; ++f)
    for (int ty = 0; ty < n; ++ty)
      for (int tx = 0; tx < n; ++tx) {
        centre[f].push_back(tile_centre(changed, f, tx, ty));
      }
  const std::size_t all_tiles = static_cast<std::size_t>(kCubeFaces) * n * n;
  reuse.changed.resize(static_cast<std::size_t>(levels));
  bool most = false;
  for (int l = 1; l < levels; ++l) {
    CubeTileMask next = tile_mask_for_reads(size, 2);
    std::size_t marked = 0;
    if (most || l > kReusedLevels) {
      next.mark_all();
    } else {
      const float margin = prefilter_reach(size, l) + tile_radius + texel_reach(std::max(1, size >> (l - 1))) +
                           texel_reach(size) + 1e-3f;
      // A tile holds a texel centre within `margin` only if its centre is within margin and
      // its radius: tested on the tiles of mark_near's rectangles (loose near the corners).
      // One task per face marked (each writes its own face).
      const float within = std::cos(std::min(kPi, margin + tile_radius));
      executor.parallel_for("environment.changed_tiles", kCubeFaces, 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t task = begin; task < end; ++task) {
          const int g = static_cast<int>(task);
          for (int f = 0; f < kCubeFaces; ++f)
            for (std::size_t i = 0; i < changed.tiles[f].size(); ++i) {
              if (!changed.tiles[f][i]) continue;
              const glm::vec3& c = centre[f][i];
              if (!((cube_faces_near(c, margin) >> g) & 1u)) continue;
              std::array<int, 4> rect{0, 0, n - 1, n - 1};
              if (margin < kWholeFaceMargin && !tiles_near_on_face(g, tile, n, size, c, margin, rect)) continue;
              for (int y = rect[1]; y <= rect[3]; ++y)
                for (int x = rect[0]; x <= rect[2]; ++x) {
                  const std::size_t j = static_cast<std::size_t>(y) * n + x;
                  if (!next.tiles[g][j] && glm::dot(c, centre[g][j]) >= within) next.tiles[g][j] = 1;
                }
            }
        }
      });
    }
    // The inputs of level l + 1: level l's changed texels, and those prefiltered in one map
    // and not in the other (the other holds the default there).
    changed = next;
    for (int f = 0; f < kCubeFaces; ++f)
      for (std::size_t i = 0; i < changed.tiles[f].size(); ++i) {
        changed.tiles[f][i] |= prefiltered_over(face_mask, tiles, f, i) != prefiltered_over(from_faces, from_tiles, f, i);
        marked += changed.tiles[f][i];
      }
    most = 2 * marked > all_tiles;
    reuse.changed[static_cast<std::size_t>(l)] = std::move(next);
  }
  return reuse;
}

void merge_reads(std::vector<CubeTileMask>& into, const std::vector<CubeTileMask>& from) {
  for (std::size_t m = 0; m < into.size() && m < from.size(); ++m)
    for (int f = 0; f < kCubeFaces; ++f) {
      std::vector<std::uint8_t>& to = into[m].tiles[f];
      const std::vector<std::uint8_t>& marked = from[m].tiles[f];
      for (std::size_t k = 0; k < to.size() && k < marked.size(); ++k) to[k] |= marked[k];
    }
}

CubeTileMask tiles_read(par::Executor& executor, const GBuffer& g, const std::vector<std::uint32_t>& samples,
                        int size, int level_count, bool refractors_read_at_surface) {
  CubeTileMask mask = tile_mask_for_reads(size, level_count);
  std::atomic<bool> refracts{false};
  executor.parallel_for("reflector_cube_maps.tiles", samples.size(), 4096, [&](std::size_t begin, std::size_t end) {
    LookupTileMarker marker(mask, level_count);
    const auto mark_lookup = [&](const glm::vec3& d, float exponent) {
      marker.mark(d, exponent);
      return glm::vec3(0.0f);
    };
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t i = samples[k];
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      if (s.is_refractor() && !refractors_read_at_surface) {  // paths through it go anywhere (faces_read keeps every face)
        refracts.store(true, std::memory_order_relaxed);
        break;
      }
      // The lookups specular_radiance makes for this sample (envmap_reflect's reads): along R
      // with the material's exponent, a refractor's along R and T sharply.
      specular_radiance(s, g.normal.pixels[i], g.view_direction(i), mark_lookup);
    }
  });
  if (refracts.load()) for (auto& t : mask.tiles) std::fill(t.begin(), t.end(), std::uint8_t(1));
  else settle_wide_reads(executor, mask);
  return mask;
}

unsigned faces_read(par::Executor& executor, const GBuffer& g, const std::vector<std::uint32_t>& samples,
                    const glm::vec3& centre, int size, int level_count, const MapSizing& sizing) {
  if (sizing.reads == MapSizing::Reads::anywhere) return 0x3fu;
  // distance_map_reflect searches a glossy lobe along sub-lobes below this exponent.
  constexpr float kGlossySearchExponent = 1e4f;
  constexpr std::size_t kChunk = 1024;
  std::vector<unsigned> per_chunk((samples.size() + kChunk - 1) / kChunk, 0u);
  executor.parallel_for("reflector_cube_maps.faces", samples.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    unsigned mask = 0;
    for (std::size_t k = begin; k < end && mask != 0x3fu; ++k) {
      const std::size_t i = samples[k];
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      if (s.is_refractor()) {
        mask = 0x3fu;
        break;
      }
      // specular_radiance's lookup: along R with the material's exponent.
      const glm::vec3 r = glm::normalize(reflect(-g.view_direction(i), g.normal.pixels[i]));
      const float exponent = s.phong_exponent;
      if (sizing.reads == MapSizing::Reads::direction) {
        mask |= cube_faces_near(r, std::max(lookup_reach(size, level_count, exponent), 1e-3f));
        continue;
      }
      // A search reads distances and colour along the directions from the centre to the
      // points x + t d of its ray (t ≥ 0): the arc from x − o to d. A glossy lobe is searched
      // along sub-lobes (exponent 4n/3 about R, each read at 4n): their arcs lie within the
      // widest sub-lobe direction's angle of R's.
      float margin = std::max(lookup_reach(size, level_count, exponent), 1e-3f);
      if (sizing.lobe_directions > 1 && exponent < kGlossySearchExponent)
        margin = std::max(lookup_reach(size, level_count, 4.0f * exponent), 1e-3f) +
                 widest_lobe_sample(sizing.lobe_directions, exponent * (4.0f / 3.0f)) + 0.02f;
      const glm::vec3 from = g.position.pixels[i] - centre;
      const float from_length = glm::length(from);
      mask |= from_length > 0.0f ? faces_near_arc(from / from_length, r, margin) : cube_faces_near(r, margin);
    }
    per_chunk[begin / kChunk] = mask;
  });
  unsigned mask = 0;
  for (const unsigned m : per_chunk) mask |= m;
  return mask;
}

std::vector<std::uint8_t> seen_reflectors(const Scene& scene, const GBuffer& g) {
  std::vector<std::uint8_t> seen(scene.objects.size(), 0);
  for (std::size_t i = 0; i < g.object.size(); ++i) {
    const std::uint32_t o = g.object.pixels[i];
    if (g.covered(i) && o < seen.size() && is_specular(g.surface[i])) seen[o] = 1;
  }
  return seen;
}

std::vector<int> footprint_sizes(par::Executor& executor, const Scene& scene, const GBuffer& g, int size) {
  std::vector<int> sizes(scene.objects.size(), 0);
  std::vector<float> need(g.object.size());
  executor.parallel_for("reflector_cube_maps.footprint", need.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
                          for (std::size_t i = begin; i < end; ++i) need[i] = sample_need(g, i);
                        });
  // Per object, in sample order (serial: the lists and their quantiles do not depend on the
  // thread count).
  std::vector<std::vector<float>> per_object(scene.objects.size());
  const std::vector<std::uint8_t> seen = seen_reflectors(scene, g);
  for (std::size_t i = 0; i < need.size(); ++i) {
    if (!g.covered(i)) continue;
    const std::uint32_t o = g.object.pixels[i];
    if (o >= scene.objects.size()) continue;
    const SurfaceParams& s = g.surface[i];
    if (!is_specular(s)) continue;
    // A refractor's sample, or a specular sample with no neighbour on its object: need 0
    // (the cap) for refractors; a lone sample is no evidence either way and is left out.
    if (s.is_refractor()) per_object[o].push_back(0.0f);
    else if (!std::isnan(need[i])) per_object[o].push_back(need[i]);
  }
  for (std::size_t o = 0; o < per_object.size(); ++o) {
    if (!seen[o]) continue;
    std::vector<float>& v = per_object[o];
    if (v.empty()) {
      sizes[o] = size;
      continue;
    }
    const std::size_t k = static_cast<std::size_t>(kFootprintQuantile * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    sizes[o] = side_for_need(v[k], size);
  }
  return sizes;
}

const char* to_string(ReflectorSelection which) {
  switch (which) {
    case ReflectorSelection::not_planar_mirrors: return "all but planar mirrors";
    case ReflectorSelection::refractors: return "refractors";
    default: return "all";
  }
}

ReflectorMaps render_reflector_maps(par::Executor& executor, const Scene& scene,
                                    const std::vector<ShadowMap>& shadows,
                                    const EnvironmentMap& env, int size,
                                    const GBuffer* camera_view, ReflectorSelection which,
                                    const FaceLight& add_light, const std::vector<std::uint8_t>* skip,
                                    const MapSizing& sizing, std::vector<MapFaceLayers>* layers) {
  ReflectorMaps out;
  out.map_of_object.assign(scene.objects.size(), -1);
  // Seen reflectors alone need one pass over the samples; sizes need every sample's
  // neighbours as well, so they are computed only where they are used.
  std::vector<std::uint8_t> seen_by_camera;
  if (camera_view && sizing.skip_unseen) seen_by_camera = seen_reflectors(scene, *camera_view);
  std::vector<int> sizes;
  if (camera_view && sizing.from_footprint) sizes = footprint_sizes(executor, scene, *camera_view, size);
  // Each object's camera samples, in sample order, for the faces its readers reach.
  std::vector<std::vector<std::uint32_t>> samples_of;
  if (camera_view && sizing.reads != MapSizing::Reads::anywhere) {
    samples_of.resize(scene.objects.size());
    for (std::size_t i = 0; i < camera_view->object.size(); ++i) {
      const std::uint32_t object = camera_view->object.pixels[i];
      if (object < samples_of.size()) samples_of[object].push_back(static_cast<std::uint32_t>(i));
    }
  }
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  const TriangleMesh& m = scene.mesh;
  // What each material asks of a map, once per material rather than per triangle.
  struct MaterialReads {
    bool specular = false, refracts = false;
    float lobe = 1e6f;  // the Phong exponent a map is read with
    int lobe_side = 0;  // MapSizing::from_lobes: the side its sharpest read needs
  };
  std::vector<MaterialReads> reads(scene.materials.size());
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const SurfaceParams s = surface_params(scene.materials[i]);
    if (!is_specular(s)) continue;
    // A mirror lobe, a refractor or a roughness texture (any lobe, down to a mirror's) need
    // the full side.
    const bool glossy = !s.is_refractor() && !s.is_mirror_lobe() && s.phong_exponent > 0.0f &&
                        s.phong_exponent < 1e6f && !scene.materials[i].metallic_roughness_texture.valid();
    reads[i] = {true, s.is_refractor(), map_lookup_exponent(scene.materials[i], s),
                glossy ? side_for_need(glossy_need(s.phong_exponent, kLobeTexelShare), size) : size};
  }
  CubeMapScratch scratch;  // shared by the maps (each face rewrites it)
  for (std::size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    if (skip && o < skip->size() && (*skip)[o]) continue;
    bool specular = false, refracts = false;
    float widest_lobe = 1e6f;  // smallest Phong exponent the map is read with
    int lobe_side = 0;         // the side the sharpest read needs (MapSizing::from_lobes)
    Bounds b;
    for (std::uint32_t t = object.first_triangle; t < object.first_triangle + object.triangle_count;
         ++t) {
      const MaterialReads& r = reads[m.triangle_material[t]];
      if (r.specular) {
        specular = true;
        refracts = refracts || r.refracts;
        widest_lobe = std::min(widest_lobe, r.lobe);
        lobe_side = std::max(lobe_side, r.lobe_side);
      }
      for (int k = 0; k < 3; ++k) b.grow(m.positions[m.indices[3 * t + k]]);
    }
    if (!specular || !b.valid()) continue;
    if (which == ReflectorSelection::not_planar_mirrors && planar_mirror_plane(scene, static_cast<std::uint32_t>(o)))
      continue;
    if (which == ReflectorSelection::refractors && !refracts) continue;
    int side = size;
    if (!seen_by_camera.empty() && !seen_by_camera[o]) continue;
    if (!sizes.empty() && sizes[o] > 0) side = sizes[o];
    if (sizing.from_lobes) side = std::min(side, lobe_side);
    glm::vec3 centre = b.center();
    const glm::vec3 e = b.extent();
    const float smallest = std::min({e.x, e.y, e.z}), largest = std::max({e.x, e.y, e.z});
    glm::vec3 seen, normal;
    if (camera_view && smallest < 0.05f * largest &&
        visible_centroid(*camera_view, static_cast<std::uint32_t>(o), seen, normal))
      centre = seen + normal * (0.01f * glm::length(e));
    const int levels = levels_for_lobes(side, widest_lobe);
    CubeMapOptions opt;
    opt.size = side;
    // Maps read along R (powers of two, so that every level's texels nest in level 0's):
    // only the tiles around the directions read, as well as only the faces.
    CubeTileMask tiles;
    if (!samples_of.empty() && sizing.reads == MapSizing::Reads::direction && std::has_single_bit(unsigned(side))) {
      tiles = tiles_read(executor, *camera_view, samples_of[o], side, levels, sizing.refractors_read_at_surface);
      opt.face_mask = tiles.faces();
      opt.tiles = &tiles;
    } else if (!samples_of.empty()) {
      opt.face_mask = faces_read(executor, *camera_view, samples_of[o], centre, side, levels, sizing);
    }
    opt.set_depth_range(depth_range);
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;  // a reflector does not see itself in its own map
    // Maps read for distances alone (MapSizing::colour_read false) get no shader: no face is
    // shaded or prefiltered, and they keep no tiles or layers.
    MapFaceLayers kept;
    opt.keep_visibility = !sizing.colour_read && sizing.keep_visibility;
    const CubeFaceShader shade =
        sizing.colour_read ? reflector_face_shader(executor, scene, shadows, env, add_light, layers ? &kept : nullptr)
                           : CubeFaceShader{};
    CubeMap cube = render_cube_map(executor, scene, centre, opt, shade, &scratch);
    out.map_of_object[o] = static_cast<int>(out.cubes.size());
    out.maps.push_back(sizing.colour_read ? environment_from_faces(executor, cube.colour, false, levels, opt.face_mask,
                                                                   tiles.active() ? &tiles : nullptr)
                                          : EnvironmentMap{});
    out.cubes.push_back(std::move(cube));
    out.centres.push_back(centre);
    out.faces.push_back(opt.face_mask);
    out.tiles.push_back(sizing.colour_read ? std::move(tiles) : CubeTileMask{});
    out.levels.push_back(levels);
    out.refracts.push_back(refracts ? 1 : 0);
    if (layers) layers->push_back(std::move(kept));
  }
  return out;
}

CubeMapOptions kept_face_options(const ReflectorMaps& distances, std::size_t m, const CubeDepthRange& depth_range,
                                 const CubeTileMask& tiles) {
  CubeMapOptions opt;
  opt.size = distances.cubes[m].size;
  opt.set_depth_range(depth_range);
  opt.face_mask = distances.faces[m] & tiles.faces();
  opt.tiles = &tiles;
  return opt;
}

ReflectorMaps shade_reflector_maps(par::Executor& executor, const Scene& scene, const std::vector<ShadowMap>& shadows,
                                   const EnvironmentMap& env, const ReflectorMaps& distances,
                                   std::vector<CubeTileMask> tiles, const FaceLight& add_light) {
  ReflectorMaps out;
  out.map_of_object = distances.map_of_object;
  out.centres = distances.centres;
  out.levels = distances.levels;
  out.refracts = distances.refracts;
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  const CubeFaceShader shade = reflector_face_shader(executor, scene, shadows, env, add_light, nullptr);
  CubeMapScratch scratch;
  for (std::size_t m = 0; m < distances.cubes.size(); ++m) {
    const CubeMap& from = distances.cubes[m];
    const CubeMapOptions opt = kept_face_options(distances, m, depth_range, tiles[m]);
    CubeMap cube;
    cube.size = from.size;
    cube.centre = from.centre;
    cube.distance = from.distance;
    cube.colour = shade_cube_faces(executor, scene, from, opt, shade, &scratch);
    out.maps.push_back(environment_from_faces(executor, cube.colour, false, distances.levels[m], opt.face_mask, &tiles[m]));
    out.cubes.push_back(std::move(cube));
    out.faces.push_back(opt.face_mask);
    out.tiles.push_back(std::move(tiles[m]));
  }
  return out;
}

double rendered_texels(const ReflectorMaps& maps) {
  double texels = 0.0;
  for (std::size_t m = 0; m < maps.cubes.size(); ++m) {
    const unsigned faces = m < maps.faces.size() ? maps.faces[m] : 0x3fu;
    if (m < maps.tiles.size() && maps.tiles[m].active()) texels += maps.tiles[m].texel_count(faces);
    else texels += double(std::popcount(faces)) * maps.cubes[m].size * maps.cubes[m].size;
  }
  return texels;
}

void count_maps(par::NodeContext& c, const ReflectorMaps& maps) {
  c.count("cube_maps", maps.cubes.size());
  c.count("cube_texels", rendered_texels(maps));
}

void map_parameters(par::Params& p, int size, ReflectorSelection which, const MapSizing& sizing) {
  p.set("size", size);
  p.set("reflectors", to_string(which));
  p.set("footprint_size", sizing.from_footprint ? 1 : 0);
  p.set("lobe_size", sizing.from_lobes ? 1 : 0);
  p.set("skip_unseen", sizing.skip_unseen ? 1 : 0);
  if (!sizing.colour_read) p.set("colour", "none (distances only)");
  p.set("faces", sizing.reads == MapSizing::Reads::anywhere ? "all"
                 : sizing.reads == MapSizing::Reads::direction ? "read along R" : "read by searches");
}

ReflectorMaps ReflectorDistanceMapsPass::operator()(par::NodeContext& c, const GBuffer& gbuffer) const {
  if (sizing.colour_read) throw std::logic_error("reflector_distance_maps: a sizing that shades colour needs the lights");
  const ShadowMaps unlit;
  const EnvironmentMap no_environment;
  ReflectorMaps maps = render_reflector_maps(c.executor(), *scene, unlit, no_environment, size, &gbuffer, which, {},
                                             nullptr, sizing);
  count_maps(c, maps);
  return maps;
}

ReflectorMaps ReflectorCubeMapsPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                const EnvironmentMap& environment,
                                                const GBuffer& gbuffer) const {
  ReflectorMaps maps = render_reflector_maps(c.executor(), *scene, shadows, environment, size, &gbuffer,
                                             which, {}, nullptr, sizing);
  count_maps(c, maps);
  return maps;
}

}  // namespace speculum::raster
