// Binning of set-up triangles into 64×64 screen tiles by count → offsets → scatter, giving
// per-tile lists in submission order. Each chunk of input triangles keeps its set-up records
// where setup wrote them and counts them per tile; the offsets place tile t's list, chunk by
// chunk in chunk order (= submission order, for any thread count), in one contiguous run of
// `refs`; each chunk then writes a 4-byte reference to its record into its slots. The bins
// hold references rather than copies of the 64-byte records: a copy per tile would write and
// read every record twice more (about 170 MB per frame for a million small triangles), and
// the tile pass prefetches the records it gathers.
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

// A reference to record `index` of chunk `chunk`: chunk << kRefIndexBits | index.
constexpr int kRefIndexBits = 15;
constexpr std::uint32_t kRefIndexMask = (1u << kRefIndexBits) - 1;
// Chunks a frame may have so that every reference fits 32 bits.
constexpr std::size_t kMaxChunks = std::size_t(1) << (32 - kRefIndexBits);

// The set-up triangles of one chunk of input triangles.
struct BinnedChunk {
  std::vector<SetupTriangle> triangles;  // the first `count` are this frame's (see setup_triangles)
  std::size_t count = 0;
  std::vector<ClipMap> clip_maps;        // indexed by the chunk's records' clip_map
  // Per record, the inclusive tile range of its pixel box (tx0, ty0, tx1, ty1, a byte each:
  // at most 256 tiles a side), so the scatter reads 4 bytes instead of the record.
  std::vector<std::uint32_t> tile_box;
};

// All bins of one frame. Buffers keep their capacity across frames.
struct TileBins {
  std::vector<BinnedChunk> chunks;
  // [chunk · tiles + tile]: the chunk's triangle count in the tile, then (after
  // bin_offsets) its first slot in the tile's list relative to the list's start.
  std::vector<std::uint32_t> chunk_tile;
  std::vector<std::uint32_t> tile_offsets;  // tiles + 1: tile t's list is refs[t .. t+1)
  std::vector<std::uint32_t> refs;          // one reference per overlapped tile, tile-major

  const SetupTriangle& record(std::uint32_t ref) const {
    return chunks[ref >> kRefIndexBits].triangles[ref & kRefIndexMask];
  }
  const ClipMap& clip_map(std::uint32_t ref, const SetupTriangle& t) const {
    return chunks[ref >> kRefIndexBits].clip_maps[static_cast<std::size_t>(t.clip_map)];
  }
};

// Counts chunk `chunk`'s triangles per tile into its row of bins.chunk_tile (which must
// have chunks.size() · grid.count() entries) and fills the chunk's tile_box.
void count_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid);

// Turns the counts of tiles [begin, end) into per-chunk slots (running sums over chunks)
// and writes the tiles' totals to tile_offsets[t + 1].
void bin_offsets(TileBins& bins, std::size_t begin, std::size_t end, const TileGrid& grid);

// After bin_offsets of every tile: prefix sum of the totals into tile_offsets and `refs`
// sized for the frame. Serial and short (tiles).
void finish_offsets(TileBins& bins, const TileGrid& grid);

// Writes the references to chunk `chunk`'s records into their slots.
void scatter_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid);

}  // namespace speculum::raster
