// Binning into screen tiles: see tile_binning.h.
#include "raster/tile_binning.h"

#include <algorithm>

namespace speculum::raster {
namespace {

inline std::uint32_t tile_box(const SetupTriangle& t) {
  const std::uint32_t tx0 = std::uint32_t(t.px0) >> kTileShift, tx1 = std::uint32_t(t.px1) >> kTileShift;
  const std::uint32_t ty0 = std::uint32_t(t.py0) >> kTileShift, ty1 = std::uint32_t(t.py1) >> kTileShift;
  return tx0 | ty0 << 8 | tx1 << 16 | ty1 << 24;
}

template <class Visit>
inline void for_each_tile(std::uint32_t box, const TileGrid& grid, Visit&& visit) {
  const int tx0 = int(box & 0xff), ty0 = int(box >> 8 & 0xff);
  const int tx1 = int(box >> 16 & 0xff), ty1 = int(box >> 24);
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) visit(ty * grid.tiles_x + tx);
}

}  // namespace

void count_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  std::uint32_t* counts = &bins.chunk_tile[chunk * tiles];
  std::fill(counts, counts + tiles, 0u);
  BinnedChunk& c = bins.chunks[chunk];
  if (c.tile_box.size() < c.count) c.tile_box.resize(c.count);
  for (std::size_t i = 0; i < c.count; ++i) {
    const std::uint32_t box = tile_box(c.triangles[i]);
    c.tile_box[i] = box;
    if ((box & 0xffff) == box >> 16) ++counts[(box >> 8 & 0xff) * std::uint32_t(grid.tiles_x) + (box & 0xff)];
    else for_each_tile(box, grid, [&](int tile) { ++counts[tile]; });
  }
}

void bin_offsets(TileBins& bins, std::size_t begin, std::size_t end, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  const std::size_t chunks = bins.chunks.size();
  for (std::size_t tile = begin; tile < end; ++tile) {
    std::uint32_t running = 0;
    for (std::size_t c = 0; c < chunks; ++c) {
      std::uint32_t& slot = bins.chunk_tile[c * tiles + tile];
      const std::uint32_t n = slot;
      slot = running;
      running += n;
    }
    bins.tile_offsets[tile + 1] = running;
  }
}

void finish_offsets(TileBins& bins, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  bins.tile_offsets[0] = 0;
  for (std::size_t t = 0; t < tiles; ++t) bins.tile_offsets[t + 1] += bins.tile_offsets[t];
  // Grows only: keeps last frame's pages when the size is unchanged.
  if (bins.refs.size() < bins.tile_offsets[tiles]) bins.refs.resize(bins.tile_offsets[tiles]);
}

void scatter_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  std::uint32_t* cursor = &bins.chunk_tile[chunk * tiles];  // this chunk's row only
  const std::uint32_t* start = bins.tile_offsets.data();
  const BinnedChunk& c = bins.chunks[chunk];
  std::uint32_t* out = bins.refs.data();
  const std::uint32_t base = static_cast<std::uint32_t>(chunk) << kRefIndexBits;
  for (std::size_t i = 0; i < c.count; ++i) {
    const std::uint32_t ref = base | static_cast<std::uint32_t>(i);
    const std::uint32_t box = c.tile_box[i];
    if ((box & 0xffff) == box >> 16) {  // one tile: most triangles of a detailed mesh
      const std::uint32_t tile = (box >> 8 & 0xff) * std::uint32_t(grid.tiles_x) + (box & 0xff);
      out[start[tile] + cursor[tile]++] = ref;
    } else {
      for_each_tile(box, grid, [&](int tile) { out[start[tile] + cursor[tile]++] = ref; });
    }
  }
}

}  // namespace speculum::raster
