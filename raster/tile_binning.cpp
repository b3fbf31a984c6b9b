// Binning into screen tiles: see tile_binning.h.
#include "raster/tile_binning.h"

#include <algorithm>

#include <immintrin.h>

namespace speculum::raster {
namespace {

template <class Visit>
inline void for_each_tile(const SetupTriangle& t, const TileGrid& grid, Visit&& visit) {
  const int tx0 = t.px0 >> kTileShift, tx1 = t.px1 >> kTileShift;
  const int ty0 = t.py0 >> kTileShift, ty1 = t.py1 >> kTileShift;
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx) visit(ty * grid.tiles_x + tx);
}

}  // namespace

void count_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  std::uint32_t* counts = &bins.chunk_tile[chunk * tiles];
  std::fill(counts, counts + tiles, 0u);
  const BinnedChunk& c = bins.chunks[chunk];
  for (std::size_t i = 0; i < c.count; ++i)
    for_each_tile(c.triangles[i], grid, [&](int tile) { ++counts[tile]; });
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
  bins.clip_base.resize(bins.chunks.size());
  std::uint32_t clips = 0;
  for (std::size_t c = 0; c < bins.chunks.size(); ++c) {
    bins.clip_base[c] = clips;
    clips += static_cast<std::uint32_t>(bins.chunks[c].clip_maps.size());
  }
  bins.clip_maps.resize(clips);
  // Grows only: keeps last frame's pages when the size is unchanged.
  if (bins.binned.size() < bins.tile_offsets[tiles]) bins.binned.resize(bins.tile_offsets[tiles]);
}

void scatter_chunk(TileBins& bins, std::size_t chunk, const TileGrid& grid) {
  const std::size_t tiles = static_cast<std::size_t>(grid.count());
  std::uint32_t* cursor = &bins.chunk_tile[chunk * tiles];  // this chunk's row only
  const std::uint32_t* start = bins.tile_offsets.data();
  const BinnedChunk& c = bins.chunks[chunk];
  const std::int32_t clip_base = static_cast<std::int32_t>(bins.clip_base[chunk]);
  std::copy(c.clip_maps.begin(), c.clip_maps.end(), bins.clip_maps.begin() + clip_base);
  SetupTriangle* out = bins.binned.data();
  for (std::size_t i = 0; i < c.count; ++i) {
    SetupTriangle t = c.triangles[i];
    if (t.clip_map >= 0) t.clip_map += clip_base;
    // Whole, aligned cache lines that the tile pass reads much later: streaming stores
    // skip reading the destination lines first.
    const __m256i lo = _mm256_load_si256(reinterpret_cast<const __m256i*>(&t));
    const __m256i hi = _mm256_load_si256(reinterpret_cast<const __m256i*>(&t) + 1);
    for_each_tile(t, grid, [&](int tile) {
      __m256i* dst = reinterpret_cast<__m256i*>(&out[start[tile] + cursor[tile]++]);
      _mm256_stream_si256(dst, lo);
      _mm256_stream_si256(dst + 1, hi);
    });
  }
  _mm_sfence();
}

}  // namespace speculum::raster
