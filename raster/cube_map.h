// The `cube_map` node: the scene rendered from a point into six 90° faces holding colour
// and Euclidean distance |y − o| — the distance maps of SURVEY §4 — plus the face
// conventions every cube lookup in speculum uses (environment, shadow and distance maps).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "raster/gbuffer.h"
#include "raster/visibility.h"

namespace speculum::raster {

constexpr int kCubeFaces = 6;  // +X, −X, +Y, −Y, +Z, −Z

// The camera of face `face` at `centre`: a 90° square frustum along the face axis. Face
// pixels follow core/camera_rays.h, so a face image is an ordinary render of this camera.
Camera cube_face_camera(int face, const glm::vec3& centre, float znear, float zfar);

// A face and continuous pixel coordinates on it in [0, size]² (pixel centres at +0.5).
struct CubeCoord {
  int face = 0;
  glm::vec2 pixel{0.0f};
};
// The axes of face `face`'s frame (forward, right, up): each is a signed unit axis, so a dot
// product with it is one signed component (up to the sign of a zero).
struct CubeFaceAxes {
  int forward = 0, right = 0, up = 0;                       // axis index 0..2
  float forward_sign = 1.0f, right_sign = 1.0f, up_sign = 1.0f;
};
// Every face's axes, derived from the face cameras' frames at start-up.
extern const std::array<CubeFaceAxes, kCubeFaces> kCubeFaceAxes;

// Where direction d (any length, non-zero) lands. Inline: every shadow tap, map lookup,
// prefilter tap and distance-map search step calls it.
inline CubeCoord cube_coord(const glm::vec3& d, int size) {
  const glm::vec3 a = glm::abs(d);
  int face;
  if (a.x >= a.y && a.x >= a.z) face = d.x >= 0.0f ? 0 : 1;
  else if (a.y >= a.z) face = d.y >= 0.0f ? 2 : 3;
  else face = d.z >= 0.0f ? 4 : 5;
  // The frame's axes are signed unit axes, so each dot product with them is one signed
  // component: the same value (up to the sign of a zero, which the +1 below removes) for a
  // fraction of the work.
  const CubeFaceAxes& f = kCubeFaceAxes[face];
  const float depth = f.forward_sign * d[f.forward];
  const float ndc_x = f.right_sign * d[f.right] / depth;
  const float ndc_y = f.up_sign * d[f.up] / depth;
  const float s = static_cast<float>(size);
  return {face, {std::clamp((ndc_x + 1.0f) * 0.5f * s, 0.0f, s),
                 std::clamp((1.0f - ndc_y) * 0.5f * s, 0.0f, s)}};
}

// Bit f set: face f may hold a direction within angle `margin` of unit direction p. Face f
// (axis k, sign σ) holds the directions with σ p_k ≥ |p_j| for j ≠ k, the side of four great
// circles (unit normals m = (σ e_k ∓ e_j)/√2) where q·m ≥ 0; each circle is tested on its own:
// a superset test, so no face a direction within the margin lands on is left out.
unsigned cube_faces_near(const glm::vec3& p, float margin);

// Continuous pixel coordinates of direction d on the plane of face `face` (any face whose axis
// d makes an acute angle with: not clamped to the face, no face chosen), so that a
// neighbourhood of d can be bounded on a face next to the one d lands on.
glm::vec2 cube_face_plane_pixel(int face, const glm::vec3& d, int size);
// The direction through continuous pixel coordinates of a face (unit length).
glm::vec3 cube_direction(int face, glm::vec2 pixel, int size);

struct CubeMap {
  int size = 0;
  glm::vec3 centre{0.0f};
  std::array<ImageRGBA, kCubeFaces> colour;   // may be empty (distance-only maps)
  std::array<ImageF, kCubeFaces> distance;    // |y − o|, +inf where nothing was hit
  // Each rendered face's visibility (all but the depths, which resolving does not read), kept
  // only under CubeMapOptions::keep_visibility: a map whose colour is shaded later
  // (shade_cube_faces), once its readers are known.
  std::array<VisibilityBuffer, kCubeFaces> visibility;

  // Bilinear colour towards d (clamped at face borders).
  glm::vec4 colour_towards(const glm::vec3& d) const { return colour_at(cube_coord(d, size)); }
  // Nearest-texel distance towards d.
  float distance_towards(const glm::vec3& d) const { return distance_at(cube_coord(d, size)); }
  // The same at a direction's cube_coord(d, size), for a caller that needs it more than once.
  glm::vec4 colour_at(const CubeCoord& c) const;
  // Inline: every step of a distance-map search reads one.
  float distance_at(const CubeCoord& c) const {
    const int x = std::min(static_cast<int>(c.pixel.x), size - 1);
    const int y = std::min(static_cast<int>(c.pixel.y), size - 1);
    return distance[c.face].at(x, y);
  }
};

// Which texels of each face a map's readers can reach, in square tiles of `tile` level-0
// texels: a refinement of CubeMapOptions::face_mask for maps whose reads are known (the
// directions a frame looks up; reflector_maps.h). A texel outside every read tile is never
// read at any level, so it need not be shaded or prefiltered.
struct CubeTileMask {
  static constexpr int kTile = 8;  // the default tile side
  int size = 0;  // level-0 side; 0: no mask (every texel of the faces in face_mask)
  int tile = kTile;  // tile side in level-0 texels
  std::array<std::vector<std::uint8_t>, kCubeFaces> tiles;  // tiles_per_side()² per face, 1: read
  // Reads too wide for a bound on one face's plane (LookupTileMarker), recorded first per
  // coarse cell of directions, wide_cells()² a face: 0 or the bits of the widest reach read
  // in the cell (a positive float, so the bits order as the values). settle_wide_reads
  // (reflector_maps.h) turns them into tiles.
  static constexpr int kWideCells = 16;
  std::array<std::vector<std::uint32_t>, kCubeFaces> wide;
  int wide_cells() const { return size < kWideCells ? size : kWideCells; }

  bool active() const { return size > 0; }
  // Bit f: face f has a read tile.
  unsigned faces() const {
    unsigned mask = 0;
    for (int f = 0; f < kCubeFaces; ++f)
      if (std::find(tiles[f].begin(), tiles[f].end(), std::uint8_t(1)) != tiles[f].end()) mask |= 1u << f;
    return mask;
  }
  // Every tile of every face read (the tiles sized already).
  void mark_all() {
    for (auto& t : tiles) std::fill(t.begin(), t.end(), std::uint8_t(1));
  }
  int tiles_per_side() const { return (size + tile - 1) / tile; }
  // Level-`level` texel (x, y) of `face` (a side of size >> level) overlaps a read tile.
  // Inline for a texel inside one tile (the per-texel tests of prefiltering and shading).
  bool covers(int face, int level, int x, int y) const {
    if (!active()) return true;
    if ((1 << level) > tile) return covers_tiles(face, level, x, y);
    const std::vector<std::uint8_t>& t = tiles[face];
    return !t.empty() && t[static_cast<std::size_t>((y << level) / tile) * tiles_per_side() + (x << level) / tile];
  }
  // The level-0 texels of `face` in read tiles, one byte each (1: read), row-major.
  std::vector<std::uint8_t> texels(int face) const;
  // Level-0 texels in read tiles, over the faces in `face_mask` (0 for an inactive mask).
  double texel_count(unsigned face_mask) const;

 private:
  bool covers_tiles(int face, int level, int x, int y) const;  // covers over several tiles
};

// Colour of face `face` from its G-buffer; background samples (object == kNoId) too. `read`
// (null: every texel) flags the texels a reader can reach: the others may be left black.
using CubeFaceShader = std::function<ImageRGBA(const GBuffer&, const Camera&, int face,
                                               const std::vector<std::uint8_t>* read)>;

// Near and far planes of a cube map rendered from a point inside or just beside a region
// whose bounding-box diagonal is `extent`: no point of the region is farther than about one
// diagonal from such a centre, so far = 4 diagonals clips none of it; near = 1e-4 diagonals
// clips only what touches the centre, at any scene scale.
struct CubeDepthRange {
  float znear = 0.0f;
  float zfar = 0.0f;
};
CubeDepthRange cube_depth_range(float extent);
// The range for a map that sees the whole scene: extent = the diagonal of scene.bounds()
// (1 for an empty scene).
CubeDepthRange scene_cube_depth_range(const Scene& scene);

struct CubeMapOptions {
  int size = 256;
  float znear = 0.01f;
  float zfar = 1000.0f;
  RasterOptions raster;  // e.g. excluded_objects: leave the reflector out of its own map
  // Bit f: render face f. The others are left black with distance +inf, for a map whose
  // readers provably never look there (reflector_maps.h MapSizing::reads).
  unsigned face_mask = 0x3fu;
  // Within the faces rendered, only the texels of the read tiles are resolved and shaded
  // (null or inactive: all); the others hold distance +inf and black.
  const CubeTileMask* tiles = nullptr;
  // Keep each face's visibility in CubeMap::visibility for shade_cube_faces (no tiles: the
  // distances stay whole).
  bool keep_visibility = false;

  void set_depth_range(const CubeDepthRange& range) {
    znear = range.znear;
    zfar = range.zfar;
  }
};

// The memory one face at a time needs (raster bins, visibility and G-buffer planes). A caller
// that renders several maps passes one to all of them, so that each map does not allocate,
// zero and fault in its own planes on the launching thread; every face rewrites all of it.
struct CubeMapScratch {
  RasterWorkspace workspace;
  VisibilityBuffer vis;
  GBuffer g;
  // The scene's triangle groups, built by the first map rendered with this scratch: a face
  // sets up only the groups that reach it (a cube face sees about a sixth of the scene).
  TriangleGroups groups;
  const TriangleMesh* groups_of = nullptr;
  // The scene's G-buffer records, built by the first face shaded with this scratch: the
  // faces' resolves read them instead of the mesh's index and vertex arrays (the same bytes,
  // about half the time), the build paid once for all of them.
  FrameRecords records;
};

// Renders the six faces: visibility → G-buffer → `shade` (skipped when empty: a
// distance-only map, as for shadow maps). Without `scratch` the map uses its own.
CubeMap render_cube_map(par::Executor& executor, const Scene& scene, const glm::vec3& centre,
                        const CubeMapOptions& options, const CubeFaceShader& shade = {},
                        CubeMapScratch* scratch = nullptr);

// The colour faces of a map rendered with keep_visibility, shaded now: each face of
// `options.face_mask` from its kept visibility, only the texels of `options.tiles` (null or
// inactive: all) — what render_cube_map with those options and `shade` gives, the same bytes.
// Faces outside the mask are black.
std::array<ImageRGBA, kCubeFaces> shade_cube_faces(par::Executor& executor, const Scene& scene, const CubeMap& cube,
                                                   const CubeMapOptions& options, const CubeFaceShader& shade,
                                                   CubeMapScratch* scratch = nullptr);

}  // namespace speculum::raster
