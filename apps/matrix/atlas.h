// The matrix atlas, DIR/index.html: rows techniques, columns scenes; each cell its image, heat
// maps of its difference to both references, time and errors; per scene an error-vs-time
// chart (drawn by gnuplot) with the Pareto front of the techniques.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/image.h"

namespace speculum::matrix {

// Per pixel the largest 8-bit RGB difference of a and b, black 0 .. white at 64 and above
// (a fixed scale, so heat maps compare across cells); pixels outside `mask` (when given:
// where its red channel is below 0.5) are dark grey.
ImageRGBA difference_heat_map(const ImageRGBA& a, const ImageRGBA& b, const ImageRGBA* mask = nullptr);

// Writes DIR/index.html and DIR/charts/SCENE.svg from results.json's value. Without gnuplot
// on PATH the page says so instead of showing the charts (a warning on stderr unless quiet).
void write_atlas(const std::filesystem::path& dir, const nlohmann::ordered_json& results, bool quiet);

}  // namespace speculum::matrix
