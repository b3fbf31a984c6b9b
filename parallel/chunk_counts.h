// Per-chunk counts of small integer ids: the counting pass shared by stable partition and
// histogram (ROGER §4.5 bucket sort counts per block before any output is placed).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "parallel/executor.h"

namespace speculum::par {

// counts[c * bins + id] = how many elements of chunk c carry `id`. Launch "<name>/<phase>".
// Throws std::invalid_argument("<what>: a <id_kind> id is >= the <id_kind> count N") when an
// id is out of range. The template range-checks W ids per lane compare (Lanes<W>) and counts
// the lanes of each group in element order; the plain function uses ex.lanes().
template <int W>
std::vector<std::uint32_t> count_ids_per_chunk(Executor& ex, std::string_view name,
                                               std::string_view phase,
                                               std::span<const std::uint32_t> ids,
                                               std::size_t bins, std::size_t chunk,
                                               std::string_view what, std::string_view id_kind);
std::vector<std::uint32_t> count_ids_per_chunk(Executor& ex, std::string_view name,
                                               std::string_view phase,
                                               std::span<const std::uint32_t> ids,
                                               std::size_t bins, std::size_t chunk,
                                               std::string_view what, std::string_view id_kind);

// Turns counts[c * bins + id] (from count_ids_per_chunk or a digit count) into the first
// output slot of chunk c's elements with that id: id-major, then chunk order (the stable
// counting-scatter layout). Returns the per-id totals.
std::vector<std::size_t> chunk_offsets(std::span<std::uint32_t> counts, std::size_t chunks,
                                       std::size_t bins);

}  // namespace speculum::par
