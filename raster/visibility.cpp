// The `visibility` node: vertex stage → setup+bin per chunk of triangles → one task per
// tile (see visibility.h). Chunk sizes are constants, never derived from the thread count.
#include "raster/visibility.h"

#include <algorithm>
#include <string>

#include "core/camera_rays.h"
#include "core/error.h"
#include "raster/frame_plane.h"
#include "raster/tile_binning.h"
#include "raster/tile_rasterizer.h"
#include "raster/triangle_setup.h"

namespace speculum::raster {
namespace {
constexpr std::size_t kVertexChunk = 16384;
constexpr std::size_t kTriangleChunk = 4096;
constexpr std::size_t kTileChunk = 64;  // tiles per bin_offsets task
// Clipping makes at most 7 records of a triangle: a chunk's records must fit a reference.
static_assert(7 * kTriangleChunk <= std::size_t(1) << kRefIndexBits);
static_assert(kTriangleChunk % TriangleGroups::kSize == 0, "a setup chunk holds whole triangle groups");
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

namespace {

// rasterize_screen_vertices, leaving out the triangle groups flagged in `outside` (null:
// none; see triangle_groups.h): setup would drop each of their triangles anyway.
void rasterize(par::Executor& executor, const std::vector<ScreenVertex>& vertices,
               const std::vector<std::uint32_t>& indices, const std::vector<std::uint32_t>& triangle_object,
               int width, int height, const RasterOptions& options, const std::vector<std::uint8_t>* outside,
               TileBins& bins, VisibilityBuffer& out) {
  check_target_size(width, height);
  const int lanes = options.lanes == 0 ? executor.lanes() : options.lanes;
  const Viewport vp{width, height};
  const TileGrid grid = make_tile_grid(width, height);
  const std::size_t triangles = indices.size() / 3;
  if (triangle_object.size() < triangles)
    throw InputError("rasterizer", "fewer object ids (" + std::to_string(triangle_object.size()) +
                                       ") than triangles (" + std::to_string(triangles) + ")");
  const std::size_t chunks = (triangles + kTriangleChunk - 1) / kTriangleChunk;
  if (chunks > kMaxChunks)
    throw InputError("rasterizer", std::to_string(triangles) + " triangles exceed the " +
                                       std::to_string(kMaxChunks * kTriangleChunk) + " one frame can bin");
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  bins.chunks.resize(chunks);
  bins.chunk_tile.resize(chunks * tiles);
  bins.tile_offsets.resize(tiles + 1);
  const auto& excluded = options.excluded_objects;
  const int cull = cull_sign(options.cull);
  executor.parallel_for(
      "raster.setup_bin", triangles, kTriangleChunk, [&](std::size_t begin, std::size_t end) {
        const std::size_t c = begin / kTriangleChunk;
        BinnedChunk& chunk = bins.chunks[c];
        chunk.clip_maps.clear();
        // The runs of groups inside the view (without groups: the whole chunk), in triangle
        // order: the same records.
        constexpr std::size_t kGroup = TriangleGroups::kSize;
        const auto left_out = [&](std::size_t t) { return outside && (*outside)[t / kGroup]; };
        std::size_t n = 0;
        for (std::size_t run = begin; run < end;) {
          if (left_out(run)) {
            run += kGroup;
            continue;
          }
          std::size_t run_end = run;
          while (run_end < end && !left_out(run_end)) run_end = outside ? std::min(run_end + kGroup, end) : end;
          n = setup_triangles(vertices.data(), indices.data(), run, run_end, triangle_object.data(), excluded, vp,
                              cull, n, chunk.triangles, chunk.clip_maps);
          run = run_end;
        }
        chunk.count = n;
        count_chunk(bins, c, grid);
      });
  executor.parallel_for("raster.bin_offsets", tiles, kTileChunk,
                        [&](std::size_t begin, std::size_t end) {
                          bin_offsets(bins, begin, end, grid);
                        });
  finish_offsets(bins, grid);
  executor.parallel_for("raster.bin_scatter", chunks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) scatter_chunk(bins, c, grid);
  });

  out.width = width;
  out.height = height;
  ensure_plane_size(out.triangle, width, height);
  ensure_plane_size(out.object, width, height);
  ensure_plane_size(out.depth, width, height);
  ensure_plane_size(out.bary, width, height);
  if (options.count_coverage) ensure_plane_size(out.coverage, width, height);
  else out.coverage = IdBuffer();
  executor.parallel_for("raster.tiles", static_cast<std::size_t>(grid.count()), 1,
                        [&](std::size_t begin, std::size_t end) {
                          for (std::size_t tile = begin; tile < end; ++tile)
                            rasterize_tile(static_cast<int>(tile), lanes, grid, vp, bins, out);
                        });
}

}  // namespace

void rasterize_screen_vertices(par::Executor& executor, const std::vector<ScreenVertex>& vertices,
                               const std::vector<std::uint32_t>& indices,
                               const std::vector<std::uint32_t>& triangle_object, int width,
                               int height, const RasterOptions& options,
                               TileBins& bins, VisibilityBuffer& out) {
  rasterize(executor, vertices, indices, triangle_object, width, height, options, nullptr, bins, out);
}

VisibilityBuffer rasterize_screen_vertices(par::Executor& executor,
                                           const std::vector<ScreenVertex>& vertices,
                                           const std::vector<std::uint32_t>& indices,
                                           const std::vector<std::uint32_t>& triangle_object,
                                           int width, int height,
                                           const RasterOptions& options) {
  TileBins bins;
  VisibilityBuffer out;
  rasterize_screen_vertices(executor, vertices, indices, triangle_object, width, height, options,
                            bins, out);
  return out;
}

void render_visibility(par::Executor& executor, const Scene& scene, const Camera& camera,
                       int width, int height, const RasterOptions& options,
                       RasterWorkspace& workspace, VisibilityBuffer& out) {
  check_target_size(width, height);
  validate_camera(camera, scene.name);
  const Viewport vp{width, height};
  const glm::mat4 view_projection =
      projection_matrix(camera, width, height) * view_matrix(camera);
  const TriangleMesh& mesh = scene.mesh;
  auto& vertices = workspace.vertices;
  vertices.resize(mesh.vertex_count());
  executor.parallel_for("raster.vertices", vertices.size(), kVertexChunk,
                        [&](std::size_t begin, std::size_t end) {
                          make_screen_vertices(view_projection, &mesh.positions[begin],
                                               end - begin, vp, &vertices[begin]);
                        });
  const std::vector<std::uint8_t>* outside = nullptr;
  if (options.groups) {
    if (options.groups->triangles != mesh.triangle_count())
      throw InputError(scene.name, "triangle groups were built from another mesh");
    groups_outside(*options.groups, view_projection, workspace.outside_groups);
    outside = &workspace.outside_groups;
  }
  rasterize(executor, vertices, mesh.indices, mesh.triangle_object, width, height, options, outside,
            workspace.bins, out);
}

VisibilityBuffer render_visibility(par::Executor& executor, const Scene& scene,
                                   const Camera& camera, int width, int height,
                                   const RasterOptions& options) {
  RasterWorkspace workspace;
  VisibilityBuffer out;
  render_visibility(executor, scene, camera, width, height, options, workspace, out);
  return out;
}

VisibilityBuffer VisibilityPass::operator()(par::NodeContext& c) const {
  return render_visibility(c.executor(), *scene, camera, width, height);
}

}  // namespace speculum::raster
