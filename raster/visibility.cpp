// The `visibility` node: vertex stage → setup+bin per chunk of triangles → one task per
// tile (see visibility.h). Chunk sizes are constants, never derived from the thread count.
#include "raster/visibility.h"

#include <string>

#include "core/camera_rays.h"
#include "core/error.h"
#include "parallel/lanes.h"
#include "raster/tile_binning.h"
#include "raster/tile_rasterizer.h"
#include "raster/triangle_setup.h"

namespace speculum::raster {
namespace {
constexpr std::size_t kVertexChunk = 16384;
constexpr std::size_t kTriangleChunk = 16384;
}  // namespace

namespace {

void check_target_size(int width, int height) {
  if (width < 1 || height < 1 || width > kMaxTargetSide || height > kMaxTargetSide)
    throw InputError("render target", "size " + std::to_string(width) + "x" +
                                          std::to_string(height) + " is outside 1.." +
                                          std::to_string(kMaxTargetSide));
}

int cull_sign(CullMode mode) {
  return mode == CullMode::Back ? 1 : mode == CullMode::Front ? -1 : 0;
}

}  // namespace

VisibilityBuffer rasterize_screen_vertices(par::Executor& executor,
                                           const std::vector<ScreenVertex>& vertices,
                                           const std::vector<std::uint32_t>& indices,
                                           const std::vector<std::uint32_t>& triangle_object,
                                           int width, int height,
                                           const RasterOptions& options) {
  check_target_size(width, height);
  const int lanes = options.lanes == 0 ? par::default_lanes() : options.lanes;
  const Viewport vp{width, height};
  const TileGrid grid = make_tile_grid(width, height);
  const std::size_t triangles = indices.size() / 3;
  std::vector<BinnedChunk> chunks((triangles + kTriangleChunk - 1) / kTriangleChunk);
  const auto& excluded = options.excluded_objects;
  const int cull = cull_sign(options.cull);
  executor.parallel_for(
      "raster.setup_bin", triangles, kTriangleChunk, [&](std::size_t begin, std::size_t end) {
        BinnedChunk& chunk = chunks[begin / kTriangleChunk];
        chunk.triangles.reserve(end - begin);
        for (std::size_t t = begin; t < end; ++t) {
          if (!excluded.empty()) {
            const std::uint32_t object = triangle_object[t];
            if (object < excluded.size() && excluded[object]) continue;
          }
          const std::uint32_t* idx = &indices[3 * t];
          setup_triangle(vertices[idx[0]], vertices[idx[1]], vertices[idx[2]],
                         static_cast<std::uint32_t>(t), vp, cull, chunk.triangles,
                         chunk.clip_maps);
        }
        bin_chunk(chunk, grid);
      });

  VisibilityBuffer out;
  out.width = width;
  out.height = height;
  out.triangle = IdBuffer(width, height, kNoId);
  out.object = IdBuffer(width, height, kNoId);
  out.depth = ImageF(width, height);
  out.bary = Buffer2D<glm::vec2>(width, height);
  if (options.count_coverage) out.coverage = IdBuffer(width, height, 0u);
  executor.parallel_for("raster.tiles", static_cast<std::size_t>(grid.count()), 1,
                        [&](std::size_t begin, std::size_t end) {
                          for (std::size_t tile = begin; tile < end; ++tile)
                            rasterize_tile(static_cast<int>(tile), lanes, grid, vp, chunks,
                                           triangle_object, out);
                        });
  return out;
}

VisibilityBuffer render_visibility(par::Executor& executor, const Scene& scene,
                                   const Camera& camera, int width, int height,
                                   const RasterOptions& options) {
  check_target_size(width, height);
  validate_camera(camera, scene.name);
  const Viewport vp{width, height};
  const glm::mat4 view_projection =
      projection_matrix(camera, width, height) * view_matrix(camera);
  const TriangleMesh& mesh = scene.mesh;
  std::vector<ScreenVertex> vertices(mesh.vertex_count());
  executor.parallel_for("raster.vertices", vertices.size(), kVertexChunk,
                        [&](std::size_t begin, std::size_t end) {
                          for (std::size_t i = begin; i < end; ++i)
                            vertices[i] = make_screen_vertex(
                                view_projection * glm::vec4(mesh.positions[i], 1.0f), vp);
                        });
  return rasterize_screen_vertices(executor, vertices, mesh.indices, mesh.triangle_object, width,
                                   height, options);
}

}  // namespace speculum::raster
