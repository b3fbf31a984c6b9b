// Binning of set-up triangles into 64×64 screen tiles. Each chunk of input triangles bins
// its own output (a counting sort by tile), so a tile's list is the concatenation of the
// chunks' lists in chunk order = submission order, for any thread count (issue 4). Bins hold
// copies of the triangles, so a tile task streams through contiguous memory instead of
// gathering triangles scattered over the whole frame's setup output.
#pragma once

#include <cstdint>
#include <vector>

#include "raster/triangle_setup.h"

namespace speculum::raster {

constexpr int kTileSize = 64;
constexpr int kTileShift = 6;

struct TileGrid {
  int tiles_x = 0;
  int tiles_y = 0;
  int count() const { return tiles_x * tiles_y; }
};

inline TileGrid make_tile_grid(int width, int height) {
  return {(width + kTileSize - 1) / kTileSize, (height + kTileSize - 1) / kTileSize};
}

// The set-up triangles of one chunk of input triangles and their per-tile bins:
// tile t's triangles are binned[tile_offsets[t] .. tile_offsets[t+1]), in chunk order.
struct BinnedChunk {
  std::vector<SetupTriangle> triangles;  // the first `count` are this frame's (see setup_triangles)
  std::size_t count = 0;
  std::vector<ClipMap> clip_maps;
  std::vector<std::uint32_t> tile_offsets;  // grid.count() + 1
  std::vector<SetupTriangle> binned;        // one copy per overlapped tile
};

// Fills chunk.tile_offsets / binned from chunk.triangles[0, count) (which keep their order).
void bin_chunk(BinnedChunk& chunk, const TileGrid& grid);

}  // namespace speculum::raster
