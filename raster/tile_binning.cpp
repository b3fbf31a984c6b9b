// Binning into screen tiles: see tile_binning.h.
#include "raster/tile_binning.h"

namespace speculum::raster {

void bin_chunk(BinnedChunk& chunk, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  chunk.tile_offsets.assign(tiles + 1, 0);
  // Pass 1: count per tile (offset by one so the prefix sum lands in place).
  for (std::size_t i = 0; i < chunk.count; ++i) {
    const SetupTriangle& t = chunk.triangles[i];
    const int tx0 = t.px0 >> kTileShift, tx1 = t.px1 >> kTileShift;
    const int ty0 = t.py0 >> kTileShift, ty1 = t.py1 >> kTileShift;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) ++chunk.tile_offsets[ty * grid.tiles_x + tx + 1];
  }
  for (std::size_t i = 0; i < tiles; ++i) chunk.tile_offsets[i + 1] += chunk.tile_offsets[i];
  // Reuses the previous frame's memory when the size is unchanged.
  chunk.binned.resize(chunk.tile_offsets[tiles]);
  // Pass 2: fill in triangle order, using a cursor per tile.
  std::vector<std::uint32_t> cursor(chunk.tile_offsets.begin(), chunk.tile_offsets.end() - 1);
  for (std::size_t i = 0; i < chunk.count; ++i) {
    const SetupTriangle& t = chunk.triangles[i];
    const int tx0 = t.px0 >> kTileShift, tx1 = t.px1 >> kTileShift;
    const int ty0 = t.py0 >> kTileShift, ty1 = t.py1 >> kTileShift;
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) chunk.binned[cursor[ty * grid.tiles_x + tx]++] = t;
  }
}

}  // namespace speculum::raster
