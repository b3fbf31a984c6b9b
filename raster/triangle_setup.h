// Triangle setup for the tile rasterizer: clip-space transform, near/far and guard-band
// clipping, fixed-point snapping (8 sub-pixel bits) and orientation.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace speculum::raster {

constexpr int kSubpixelBits = 8;
constexpr int kSubpixelOne = 1 << kSubpixelBits;
// Pixels beyond each viewport side that setup accepts without clipping; together with
// kMaxTargetSide this bounds |fixed coordinates| below 2^23, so edge functions fit int64
// with a wide margin.
constexpr float kGuardBandPixels = 8192.0f;

// A vertex after the vertex stage: clip position plus, when it lies in front of the near
// plane and inside the guard band, its snapped screen position and 1/w.
struct ScreenVertex {
  glm::vec4 clip;
  std::int32_t x = 0, y = 0;  // fixed point, y down
  float inv_w = 0.0f;
  std::uint32_t outcode = 0;  // bits: viewport planes outside; kNeedsClip: must be clipped
};
constexpr std::uint32_t kNeedsClip = 1u << 8;

// A triangle ready to rasterize: positive area (E_i ≥ 0 inside), bounding box of the
// pixels whose centres it may cover, clamped to the viewport. Exactly one 64-byte cache
// line, aligned, so the bins (tile_binning.h) copy and stream whole lines.
struct alignas(64) SetupTriangle {
  std::int32_t x[3], y[3];
  float inv_w[3];
  std::int16_t px0, py0, px1, py1;  // inclusive pixel bounding box (sides ≤ kMaxTargetSide)
  std::uint32_t triangle;           // index in the scene's triangle soup
  std::uint32_t object;             // its object id (the resolve needs no scene lookup)
  std::int32_t clip_map = -1;       // index into the ClipMaps, -1: not clipped
  std::uint32_t swapped = 0;        // vertices 1 and 2 exchanged to make the area positive
  std::uint32_t reserved = 0;       // zero: records compare equal byte for byte
};
static_assert(sizeof(SetupTriangle) == 64);

// For a triangle produced by clipping: the original barycentrics of its three vertices.
struct ClipMap {
  glm::vec3 bary[3];
};

struct Viewport {
  int width = 0;
  int height = 0;
};

// Transforms and snaps one vertex (a pure function, so shared vertices snap identically).
ScreenVertex make_screen_vertex(const glm::vec4& clip, const Viewport& viewport);

// The vertex stage over a range: out[i] = make_screen_vertex(view_projection · (positions[i], 1))
// with the same bits, the viewport constants computed once per call.
void make_screen_vertices(const glm::mat4& view_projection, const glm::vec3* positions,
                          std::size_t count, const Viewport& viewport, ScreenVertex* out);

// Sets up triangle `triangle` from its three screen vertices and appends 0..7 triangles to
// `out` (more than one only when it was clipped; those also append a ClipMap). Triangles
// that cannot change a sample are dropped: zero area, culled, no sample centre in the
// bounding box, or at most 2×2 centres in it and none of them covered.
// cull_sign: 0 keeps both faces, +1 drops back faces, -1 drops front faces.
void setup_triangle(const ScreenVertex& v0, const ScreenVertex& v1, const ScreenVertex& v2,
                    std::uint32_t triangle, std::uint32_t object, const Viewport& viewport,
                    int cull_sign,
                    std::vector<SetupTriangle>& out, std::vector<ClipMap>& clip_maps);

// setup_triangle over triangles [begin, end) of an indexed list (indices[3t..3t+2]) and
// objects triangle_object[t] with the same results, skipping triangles whose object is
// flagged in `excluded` (indexed by object id; empty: none). Writes the records to
// out[first ..) in triangle order and returns the end index; `out` grows as needed but never shrinks (entries past the end are
// stale), so a buffer reused across frames is not re-initialized. The common case (no
// clipping) appends without a branch on the triangle's outcome.
std::size_t setup_triangles(const ScreenVertex* vertices, const std::uint32_t* indices,
                            std::size_t begin, std::size_t end,
                            const std::uint32_t* triangle_object,
                            const std::vector<std::uint8_t>& excluded, const Viewport& viewport,
                            int cull_sign, std::size_t first, std::vector<SetupTriangle>& out,
                            std::vector<ClipMap>& clip_maps);

}  // namespace speculum::raster
