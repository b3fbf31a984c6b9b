// The `visibility` node: rasterizes a scene's triangle soup from a camera into a
// per-sample visibility buffer (triangle id, object id, depth, barycentrics), following the
// setup → bin → rasterize structure of production software rasterizers such as Mesa's
// llvmpipe. Output is bit-identical for any thread count and lanes.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/tile_binning.h"
#include "raster/triangle_groups.h"
#include "raster/triangle_setup.h"

namespace speculum::raster {

// Front faces are counter-clockwise in NDC (OpenGL convention).
enum class CullMode : std::uint8_t { None, Back, Front };

struct RasterOptions {
  CullMode cull = CullMode::None;
  // Also count, per sample, how many triangles cover it (before the depth test): the
  // watertightness tests use it.
  bool count_coverage = false;
  int lanes = 0;                // pixel lanes per coverage block row; 0: the executor's, lanes()
  // Objects to leave out (e.g. the reflector a cube map is rendered around); indexed by
  // object id, empty: none excluded.
  std::vector<std::uint8_t> excluded_objects;
  // The scene's triangle groups (triangle_groups.h), built by a caller that renders many
  // views of one scene: render_visibility then sets up no group wholly outside the view. The
  // same output; null: every triangle is set up.
  const TriangleGroups* groups = nullptr;
};

// One entry per sample; samples are the pixels of the (possibly supersampled) target and
// sit at pixel centres (x + 0.5, y + 0.5) as in core/camera_rays.h.
struct VisibilityBuffer {
  int width = 0;
  int height = 0;
  IdBuffer triangle;        // kNoId where nothing is visible
  IdBuffer object;          // kNoId where nothing is visible
  ImageF depth;             // view-space depth (distance along the view axis), +inf if empty
  Buffer2D<glm::vec2> bary; // perspective-correct barycentrics (b1, b2); b0 = 1 - b1 - b2
  IdBuffer coverage;        // covering-triangle count per sample (only if count_coverage)
};

// Largest accepted target side: keeps fixed-point coordinates inside the guard band far
// from int32 overflow (raster/triangle_setup.h).
constexpr int kMaxTargetSide = 16384;

// Renders `camera` at width × height samples. Throws InputError for absurd sizes or a
// degenerate camera. Supersampling k×k is rendering at (k·w) × (k·h) and resolving later.
VisibilityBuffer render_visibility(par::Executor& executor, const Scene& scene,
                                   const Camera& camera, int width, int height,
                                   const RasterOptions& options = {});

// Memory kept between frames (transformed vertices, per-chunk bins) so repeated renders
// do not allocate and fault in fresh pages every frame.
struct RasterWorkspace {
  std::vector<ScreenVertex> vertices;
  TileBins bins;
  std::vector<std::uint8_t> outside_groups;  // RasterOptions::groups wholly outside the view
};

// As above, reusing `workspace` and `out` (resized only when the size changes).
void render_visibility(par::Executor& executor, const Scene& scene, const Camera& camera,
                       int width, int height, const RasterOptions& options,
                       RasterWorkspace& workspace, VisibilityBuffer& out);

// The same after the vertex stage: rasterizes triangles given by already transformed and
// snapped vertices (tests use it to place vertices exactly on sample centres).
VisibilityBuffer rasterize_screen_vertices(par::Executor& executor,
                                           const std::vector<ScreenVertex>& vertices,
                                           const std::vector<std::uint32_t>& indices,
                                           const std::vector<std::uint32_t>& triangle_object,
                                           int width, int height,
                                           const RasterOptions& options = {});
void rasterize_screen_vertices(par::Executor& executor, const std::vector<ScreenVertex>& vertices,
                               const std::vector<std::uint32_t>& indices,
                               const std::vector<std::uint32_t>& triangle_object, int width,
                               int height, const RasterOptions& options,
                               TileBins& bins, VisibilityBuffer& out);

// Pass "visibility": the camera's visibility buffer at width × height samples.
struct VisibilityPass {
  static constexpr const char* description =
      "Rasterizes the triangle soup from the camera at k×k samples per pixel into triangle id, "
      "object id, view depth and barycentrics per sample (SOFF §3.1 primary visibility; setup → "
      "bin → rasterize).";
  const Scene* scene = nullptr;
  Camera camera;
  int width = 0, height = 0;
  void parameters(par::Params& p) const { p.set("width", width).set("height", height); }
  VisibilityBuffer operator()(par::NodeContext& c) const;
};

}  // namespace speculum::raster
