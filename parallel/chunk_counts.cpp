// The per-chunk id counting pass (chunk_counts.h).
#include "parallel/chunk_counts.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "parallel/stream.h"

namespace speculum::par {

std::vector<std::uint32_t> count_ids_per_chunk(Executor& ex, std::string_view name,
                                               std::string_view phase,
                                               std::span<const std::uint32_t> ids,
                                               std::size_t bins, std::size_t chunk,
                                               std::string_view what, std::string_view id_kind) {
  const std::size_t n = ids.size();
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  std::vector<std::uint32_t> counts(chunks * bins, 0);
  std::vector<std::uint8_t> bad(chunks, 0);  // one flag per chunk: no shared writes
  ex.parallel_for(launch_name(name, phase), n, chunk, [&](std::size_t b, std::size_t e) {
    // Locals, and no branch per element: an out-of-range id is counted in slot 0 (the call
    // throws anyway) and flagged, so the loop is a plain increment stream.
    std::uint32_t* const count = counts.data() + (b / chunk) * bins;
    const std::uint32_t* const id = ids.data();
    const std::size_t limit = bins;
    std::uint32_t out_of_range = 0;
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t v = id[i];
      const bool bad_id = v >= limit;
      out_of_range |= bad_id;
      ++count[bad_id ? 0 : v];
    }
    bad[b / chunk] = std::uint8_t(out_of_range);
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end())
    throw std::invalid_argument(std::string(what) + ": a " + std::string(id_kind) +
                                " id is >= the " + std::string(id_kind) + " count " +
                                std::to_string(bins));
  return counts;
}

std::vector<std::size_t> chunk_offsets(std::span<std::uint32_t> counts, std::size_t chunks,
                                       std::size_t bins) {
  // Same offsets as walking id-major, but row by row: per-id totals, id starts, then each
  // chunk's row in chunk order (contiguous reads; a column walk strides by bins).
  std::vector<std::size_t> totals(bins, 0);
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t d = 0; d < bins; ++d) totals[d] += counts[c * bins + d];
  std::vector<std::uint32_t> next(bins);
  std::size_t running = 0;
  for (std::size_t d = 0; d < bins; ++d) {
    next[d] = std::uint32_t(running);
    running += totals[d];
  }
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t d = 0; d < bins; ++d) {
      const std::uint32_t k = counts[c * bins + d];
      counts[c * bins + d] = next[d];
      next[d] += k;
    }
  return totals;
}

}  // namespace speculum::par
