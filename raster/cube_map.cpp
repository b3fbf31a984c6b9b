// The `cube_map` node and cube conventions: see cube_map.h.
#include "raster/cube_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"

namespace speculum::raster {
namespace {

struct FaceBasis {
  glm::vec3 forward, up;
};
// The up vectors only have to be fixed and non-parallel to the axis; right and the true
// up are derived exactly as core/camera_rays.cpp derives them.
constexpr FaceBasis kFaces[kCubeFaces] = {
    {{1, 0, 0}, {0, 1, 0}},  {{-1, 0, 0}, {0, 1, 0}}, {{0, 1, 0}, {0, 0, -1}},
    {{0, -1, 0}, {0, 0, 1}}, {{0, 0, 1}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}}};

struct FaceFrame {
  glm::vec3 forward, right, up;
};
FaceFrame make_frame(int face) {
  const glm::vec3 f = kFaces[face].forward;
  const glm::vec3 r = glm::normalize(glm::cross(f, kFaces[face].up));
  return {f, r, glm::cross(r, f)};
}
// Computed once: cube_coord runs per map lookup (dozens per prefiltered texel). The axes
// are exact (cross products of unit axes), so the table equals per-call computation.
const std::array<FaceFrame, kCubeFaces> kFrames = {make_frame(0), make_frame(1), make_frame(2),
                                                   make_frame(3), make_frame(4), make_frame(5)};
const FaceFrame& frame(int face) { return kFrames[face]; }

}  // namespace

Camera cube_face_camera(int face, const glm::vec3& centre, float znear, float zfar) {
  Camera c;
  c.name = "cube face " + std::to_string(face);
  c.eye = centre;
  c.target = centre + kFaces[face].forward;
  c.up = kFaces[face].up;
  c.vfov_degrees = 90.0f;
  c.znear = znear;
  c.zfar = zfar;
  return c;
}

CubeDepthRange cube_depth_range(float extent) {
  CubeDepthRange range;
  range.znear = 1e-4f * extent;
  range.zfar = 4.0f * extent;
  return range;
}

CubeDepthRange scene_cube_depth_range(const Scene& scene) {
  const Bounds all = scene.bounds();
  return cube_depth_range(all.valid() ? glm::length(all.extent()) : 1.0f);
}

namespace {

CubeFaceAxes face_axes(int face) {
  const FaceFrame& f = frame(face);
  const auto axis = [](const glm::vec3& v, int& index, float& sign) {
    index = -1;
    for (int k = 0; k < 3; ++k) {
      if (v[k] == 0.0f) continue;
      if (index >= 0 || std::fabs(v[k]) != 1.0f) throw std::logic_error("cube face frame is not axis-aligned");
      index = k;
      sign = v[k];
    }
  };
  CubeFaceAxes a;
  axis(f.forward, a.forward, a.forward_sign);
  axis(f.right, a.right, a.right_sign);
  axis(f.up, a.up, a.up_sign);
  return a;
}

}  // namespace

// Initialized after kFrames (same translation unit, in order).
const std::array<CubeFaceAxes, kCubeFaces> kCubeFaceAxes = {face_axes(0), face_axes(1), face_axes(2),
                                                            face_axes(3), face_axes(4), face_axes(5)};

unsigned cube_faces_near(const glm::vec3& p, float margin) {
  // Over the directions within angle θ of p the largest q·m is sin(asin(p·m) + θ) (up to
  // θ ≤ π/2), so one of them is on m's side when p·m ≥ −sin θ: σ p_k − |p_j| ≥ −√2 sin θ.
  // Beyond π/2 every face passes (the sum is at least −√2).
  const float slack = margin < 1.5707963f ? 1.4142136f * std::sin(margin) : 2.0f;
  unsigned mask = 0;
  for (int f = 0; f < kCubeFaces; ++f) {
    const int k = f / 2;
    const float along = (f % 2 == 0 ? 1.0f : -1.0f) * p[k];
    bool near = true;
    for (int j = 0; j < 3 && near; ++j)
      if (j != k) near = along - std::fabs(p[j]) >= -slack;
    if (near) mask |= 1u << f;
  }
  return mask;
}

glm::vec2 cube_face_plane_pixel(int face, const glm::vec3& d, int size) {
  const FaceFrame& f = frame(face);
  const float depth = glm::dot(d, f.forward);
  const float s = static_cast<float>(size);
  return {(glm::dot(d, f.right) / depth + 1.0f) * 0.5f * s, (1.0f - glm::dot(d, f.up) / depth) * 0.5f * s};
}

glm::vec3 cube_direction(int face, glm::vec2 pixel, int size) {
  const FaceFrame& f = frame(face);
  const float s = static_cast<float>(size);
  const float ndc_x = 2.0f * pixel.x / s - 1.0f, ndc_y = 1.0f - 2.0f * pixel.y / s;
  return glm::normalize(f.forward + f.right * ndc_x + f.up * ndc_y);
}

glm::vec4 CubeMap::colour_at(const CubeCoord& c) const {
  const ImageRGBA& img = colour[c.face];
  const float fx = std::clamp(c.pixel.x - 0.5f, 0.0f, float(size - 1));
  const float fy = std::clamp(c.pixel.y - 0.5f, 0.0f, float(size - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
  const float tx = fx - x0, ty = fy - y0;
  return (img.at(x0, y0) * (1 - tx) + img.at(x1, y0) * tx) * (1 - ty) +
         (img.at(x0, y1) * (1 - tx) + img.at(x1, y1) * tx) * ty;
}

bool CubeTileMask::covers_tiles(int face, int level, int x, int y) const {
  const std::vector<std::uint8_t>& t = tiles[face];
  if (t.empty()) return false;
  const int n = tiles_per_side();
  // The level-0 texels under level-`level` texel (x, y), and the tiles they fall in.
  const int x0 = (x << level) / tile, x1 = std::min(n - 1, (((x + 1) << level) - 1) / tile);
  const int y0 = (y << level) / tile, y1 = std::min(n - 1, (((y + 1) << level) - 1) / tile);
  for (int ty = y0; ty <= y1; ++ty)
    for (int tx = x0; tx <= x1; ++tx)
      if (t[static_cast<std::size_t>(ty) * n + tx]) return true;
  return false;
}

std::vector<std::uint8_t> CubeTileMask::texels(int face) const {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(size) * size, 0);
  const std::vector<std::uint8_t>& t = tiles[face];
  if (t.empty()) return out;
  const int n = tiles_per_side();
  if (tile == 1) return t;  // one texel per tile: the tiles are the texels
  // Row by row, each tile's byte over its run of texels (no division per texel).
  for (int y = 0; y < size; ++y) {
    const std::uint8_t* row = &t[static_cast<std::size_t>(y / tile) * n];
    std::uint8_t* o = &out[static_cast<std::size_t>(y) * size];
    for (int tx = 0, x = 0; tx < n; ++tx, x += tile) std::memset(o + x, row[tx], std::min(tile, size - x));
  }
  return out;
}

double CubeTileMask::texel_count(unsigned face_mask) const {
  const int n = tiles_per_side();
  double count = 0.0;
  for (int f = 0; f < kCubeFaces; ++f) {
    if (!((face_mask >> f) & 1u) || tiles[f].empty()) continue;
    // Tiles on the last row or column hold only the texels left of a side not divisible by the tile.
    for (int ty = 0; ty < n; ++ty)
      for (int tx = 0; tx < n; ++tx)
        if (tiles[f][static_cast<std::size_t>(ty) * n + tx])
          count += double(std::min(tile, size - tx * tile)) * std::min(tile, size - ty * tile);
  }
  return count;
}

namespace {

// The flags of the texels a reader reaches on `face` (empty: every texel).
std::vector<std::uint8_t> read_texels(const CubeMapOptions& options, int face) {
  return options.tiles && options.tiles->active() ? options.tiles->texels(face) : std::vector<std::uint8_t>{};
}

// Resolves face `face`'s G-buffer from `vis` (the texels outside `read` already background)
// and shades it (`s`: the scratch's G-buffer and records).
ImageRGBA shade_face(par::Executor& executor, const Scene& scene, const CubeMap& cube, const CubeMapOptions& options,
                     int face, const VisibilityBuffer& vis, const std::vector<std::uint8_t>& read,
                     const CubeFaceShader& shade, CubeMapScratch& s) {
  const Camera cam = cube_face_camera(face, cube.centre, options.znear, options.zfar);
  resolve_gbuffer(executor, scene, s.records.of(executor, scene), vis, cube.centre, s.g);
  return shade(s.g, cam, face, read.empty() ? nullptr : &read);
}

}  // namespace

CubeMap render_cube_map(par::Executor& executor, const Scene& scene, const glm::vec3& centre,
                        const CubeMapOptions& options, const CubeFaceShader& shade,
                        CubeMapScratch* scratch) {
  CubeMap cube;
  cube.size = options.size;
  cube.centre = centre;
  // One set of planes for every face (the G-buffer's are about 90 bytes a texel): allocated
  // and cleared once, not once per face on the thread that launches the face's passes.
  CubeMapScratch own;
  CubeMapScratch& s = scratch ? *scratch : own;
  VisibilityBuffer& vis = s.vis;
  if (s.groups_of != &scene.mesh) {
    s.groups = triangle_groups(executor, scene.mesh);
    s.groups_of = &scene.mesh;
  }
  RasterOptions raster = options.raster;
  raster.groups = &s.groups;
  for (int face = 0; face < kCubeFaces; ++face) {
    if (!((options.face_mask >> face) & 1u)) {
      cube.distance[face] = ImageF(options.size, options.size, std::numeric_limits<float>::infinity());
      if (shade) cube.colour[face] = ImageRGBA(options.size, options.size, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
      continue;
    }
    const Camera cam = cube_face_camera(face, centre, options.znear, options.zfar);
    render_visibility(executor, scene, cam, options.size, options.size, raster, s.workspace, vis);
    // Texels no reader reaches become background: not resolved, not shaded.
    const std::vector<std::uint8_t> read = read_texels(options, face);
    if (!read.empty())
      executor.parallel_for("cube_map.unread", read.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
          if (!read[i]) vis.triangle.pixels[i] = vis.object.pixels[i] = kNoId;
      });
    ImageF& dist = cube.distance[face];
    dist = ImageF(options.size, options.size, std::numeric_limits<float>::infinity());
    // What resolving reads (not the depths) kept for shading later, copied by the distance
    // kernel's chunks, not serially after it.
    VisibilityBuffer* kept = options.keep_visibility ? &cube.visibility[face] : nullptr;
    if (kept) {
      kept->width = vis.width, kept->height = vis.height;
      kept->triangle = IdBuffer(vis.width, vis.height);
      kept->object = IdBuffer(vis.width, vis.height);
      kept->bary = Buffer2D<glm::vec2>(vis.width, vis.height);
      kept->coverage = vis.coverage;
    }
    executor.parallel_for("cube_map.distance", dist.size(), 4096,
                          [&](std::size_t begin, std::size_t end) {
                            visible_distances(scene.mesh, vis, centre, begin, end, dist.pixels.data() + begin);
                            if (!kept) return;
                            const auto from = static_cast<std::ptrdiff_t>(begin), to = static_cast<std::ptrdiff_t>(end);
                            std::copy(vis.triangle.pixels.begin() + from, vis.triangle.pixels.begin() + to, kept->triangle.pixels.begin() + from);
                            std::copy(vis.object.pixels.begin() + from, vis.object.pixels.begin() + to, kept->object.pixels.begin() + from);
                            std::copy(vis.bary.pixels.begin() + from, vis.bary.pixels.begin() + to, kept->bary.pixels.begin() + from);
                          });
    // Colour needs the full G-buffer; distance-only maps (shadows) skip it.
    if (shade) cube.colour[face] = shade_face(executor, scene, cube, options, face, vis, read, shade, s);
  }
  return cube;
}

std::array<ImageRGBA, kCubeFaces> shade_cube_faces(par::Executor& executor, const Scene& scene, const CubeMap& cube,
                                                   const CubeMapOptions& options, const CubeFaceShader& shade,
                                                   CubeMapScratch* scratch) {
  std::array<ImageRGBA, kCubeFaces> colour;
  CubeMapScratch own;
  CubeMapScratch& s = scratch ? *scratch : own;
  for (int face = 0; face < kCubeFaces; ++face) {
    const VisibilityBuffer& kept = cube.visibility[face];
    if (!((options.face_mask >> face) & 1u) || kept.width == 0) {
      colour[face] = ImageRGBA(cube.size, cube.size, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
      continue;
    }
    // The kept visibility with the texels no reader reaches made background (render_cube_map's
    // mask), in the scratch planes.
    const std::vector<std::uint8_t> read = read_texels(options, face);
    VisibilityBuffer& vis = s.vis;
    vis.width = kept.width, vis.height = kept.height;
    vis.depth = ImageF{};  // not kept: resolving does not read it
    vis.coverage = kept.coverage;
    if (vis.triangle.width != kept.width || vis.triangle.height != kept.height) {
      vis.triangle = IdBuffer(kept.width, kept.height);
      vis.object = IdBuffer(kept.width, kept.height);
    }
    if (vis.bary.width != kept.width || vis.bary.height != kept.height)
      vis.bary = Buffer2D<glm::vec2>(kept.width, kept.height);
    // The planes copied by the kernel's chunks, not serially before it.
    executor.parallel_for("cube_map.read_visibility", kept.triangle.size(), 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const bool r = read.empty() || read[i];
        vis.triangle.pixels[i] = r ? kept.triangle.pixels[i] : kNoId;
        vis.object.pixels[i] = r ? kept.object.pixels[i] : kNoId;
      }
      std::copy(kept.bary.pixels.begin() + std::ptrdiff_t(begin), kept.bary.pixels.begin() + std::ptrdiff_t(end),
                vis.bary.pixels.begin() + std::ptrdiff_t(begin));
    });
    colour[face] = shade_face(executor, scene, cube, options, face, vis, read, shade, s);
  }
  return colour;
}

}  // namespace speculum::raster
