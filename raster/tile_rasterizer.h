// Per-tile rasterization: integer edge functions with the top-left fill rule, 8×8 block
// rejection then pixel coverage in rows of W lanes, early depth test on 1/w with ties won
// by the lower triangle index, perspective-correct barycentrics.
#pragma once

#include <cstdint>
#include <vector>

#include "raster/tile_binning.h"
#include "raster/visibility.h"

namespace speculum::raster {

// Rasterizes tile `tile` of `grid` from its list in `bins` (submission order) and writes
// that tile's region of `out`. One call owns its tile: calls for different tiles may run
// concurrently. `lanes` is 1, 4, 8 or 16 (same bits for each).
void rasterize_tile(int tile, int lanes, const TileGrid& grid, const Viewport& viewport,
                    const TileBins& bins, VisibilityBuffer& out);

}  // namespace speculum::raster
