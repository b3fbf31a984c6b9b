// The per-chunk id counting pass (chunk_counts.h), written once over Lanes<W>.
#include "parallel/chunk_counts.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "parallel/lanes_stream.h"
#include "parallel/stream.h"

namespace speculum::par {

template <int W>
std::vector<std::uint32_t> count_ids_per_chunk(Executor& ex, std::string_view name,
                                               std::string_view phase,
                                               std::span<const std::uint32_t> ids,
                                               std::size_t bins, std::size_t chunk,
                                               std::string_view what, std::string_view id_kind) {
  using L = Lanes<W>;
  using U = LaneU32<W>;
  const std::size_t n = ids.size();
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  std::vector<std::uint32_t> counts(chunks * bins, 0);
  std::vector<std::uint8_t> bad(chunks, 0);  // one flag per chunk: no shared writes
  const auto out_of_range_error = [&] {
    return std::invalid_argument(std::string(what) + ": a " + std::string(id_kind) + " id is >= the " +
                                 std::string(id_kind) + " count " + std::to_string(bins));
  };
  if (bins == 0 && n > 0) throw out_of_range_error();  // no slot 0 to count a bad id in
  // id >= bins as id > the largest valid id (ids are 32-bit: past 2^32 bins none is bad).
  const std::uint32_t max_id = std::uint32_t(std::min<std::size_t>(bins - 1, 0xffffffffu));
  ex.parallel_for(launch_name(name, phase), n, chunk, [&](std::size_t b, std::size_t e) {
    // Locals, and no branch per element: an out-of-range id is counted in slot 0 (the call
    // throws anyway) and its lane flagged, so the loop is a plain increment stream. The
    // flags are OR-ed across groups and tested once per chunk.
    std::uint32_t* const count = counts.data() + (b / chunk) * bins;
    const std::uint32_t* const id = ids.data();
    typename U::mask_type out_of_range(false);
    const auto count_group = [&](const U& v, int lanes) {
      const auto bad_lanes = v > max_id;
      out_of_range |= bad_lanes;
      const U slot = L::select(bad_lanes, U(0u), v);
      for (int k = 0; k < lanes; ++k) ++count[std::uint32_t(slot[k])];  // lanes in element order
    };
    std::size_t i = b;
    for (; i + W <= e; i += W) count_group(L::load(id + i), W);
    // The short tail group reads only its own ids (missing lanes are id 0, never counted).
    if (i < e) count_group(L::load_partial(id + i, int(e - i)), int(e - i));
    bad[b / chunk] = std::uint8_t(L::any(out_of_range));
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end()) throw out_of_range_error();
  return counts;
}

std::vector<std::uint32_t> count_ids_per_chunk(Executor& ex, std::string_view name,
                                               std::string_view phase,
                                               std::span<const std::uint32_t> ids,
                                               std::size_t bins, std::size_t chunk,
                                               std::string_view what, std::string_view id_kind) {
  return dispatch_lanes(ex.lanes(), [&](auto w) {
    return count_ids_per_chunk<w.value>(ex, name, phase, ids, bins, chunk, what, id_kind);
  });
}

#define SPECULUM_COUNT_IDS_INSTANTIATE(W)                                                              \
  template std::vector<std::uint32_t> count_ids_per_chunk<W>(Executor&, std::string_view, std::string_view, \
                                                             std::span<const std::uint32_t>, std::size_t, \
                                                             std::size_t, std::string_view, std::string_view);
SPECULUM_COUNT_IDS_INSTANTIATE(1)
SPECULUM_COUNT_IDS_INSTANTIATE(4)
SPECULUM_COUNT_IDS_INSTANTIATE(8)
SPECULUM_COUNT_IDS_INSTANTIATE(16)
#undef SPECULUM_COUNT_IDS_INSTANTIATE

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
