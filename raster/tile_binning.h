// Binning of set-up triangles into 64×64 screen tiles by count → offsets → scatter, giving
// per-tile lists in submission order. Each chunk of input triangles counts
// its triangles per tile; the offsets place tile t's list, chunk by chunk in chunk order
// (= submission order, for any thread count), in one contiguous run of `binned`; each
// chunk then copies its triangles into its slots. A tile task streams through one run of
// whole 64-byte records instead of gathering pieces of every chunk's bins.
#pragma once

#include <cstddef>
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

// The set-up triangles of one chunk of input triangles.
struct BinnedChunk {
  std::vector<SetupTriangle> triangles;  // the first `count` are this frame's (see setup_triangles)
  std::size_t count = 0;
  std::vector<ClipMap> clip_maps;        // indexed by the chunk's records' clip_map
};

// All bins of one frame. Buffers keep their capacity across frames.
struct TileBins {
  std::vector<BinnedChunk> chunks;
  // [chunk · tiles + tile]: the chunk's triangle count in the tile, then (after
  // bin_offsets) its first slot in the tile's list relative to the list's start.
  std::vector<std::uint32_t> chunk_tile;
  std::vector<std::uint32_t> tile_offsets;  // tiles + 1: tile t's list is binned[t .. t+1)
  std::vector<std::uint32_t> clip_base;     // per chunk: its first entry in clip_maps
  std::vector<ClipMap> clip_maps;           // every chunk's clip maps, in chunk order
  std::vector<SetupTriangle> binned;        // one copy per overlapped tile, tile-major;
                                            // clip_map indexes the frame's clip_maps
};

// Counts chunk `chunk`'s triangles per tile into its row of bins.chunk_tile (which must
// have chunks.size() · grid.count() entries).
void count_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid);

// Turns the counts of tiles [begin, end) into per-chunk slots (running sums over chunks)
// and writes the tiles' totals to tile_offsets[t + 1].
void bin_offsets(TileBins& bins, std::size_t begin, std::size_t end, const TileGrid& grid);

// After bin_offsets of every tile: prefix sum of the totals into tile_offsets, clip-map
// bases, and `binned` / `clip_maps` sized for the frame. Serial and short (tiles + chunks).
void finish_offsets(TileBins& bins, const TileGrid& grid);

// Copies chunk `chunk`'s triangles (and its clip maps) into their slots.
void scatter_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid);

}  // namespace speculum::raster
