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
    std::uint32_t* count = counts.data() + (b / chunk) * bins;
    for (std::size_t i = b; i < e; ++i) {
      if (ids[i] >= bins) {
        bad[b / chunk] = 1;
        return;
      }
      ++count[ids[i]];
    }
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end())
    throw std::invalid_argument(std::string(what) + ": a " + std::string(id_kind) +
                                " id is >= the " + std::string(id_kind) + " count " +
                                std::to_string(bins));
  return counts;
}

}  // namespace speculum::par
