// Stable bucket partition: ROGER §4.5 bucket sort as one counting scatter (partition.h),
// written once over Lanes<W> and instantiated for W = 1, 4, 8, 16.
#include "parallel/partition.h"

#include <stdexcept>

#include "parallel/chunk_counts.h"
#include "parallel/lanes.h"

namespace speculum::par {

template <int W>
void partition_stable(Executor& ex, std::string_view name, std::span<const std::uint32_t> bucket,
                      std::uint32_t p, std::span<std::uint32_t> out,
                      std::span<std::uint32_t> bucket_begin, std::size_t chunk) {
  const std::size_t n = bucket.size();
  if (p == 0) throw std::invalid_argument("partition_stable: need at least one bucket");
  if (out.size() < n || bucket_begin.size() < std::size_t(p) + 1)
    throw std::invalid_argument("partition_stable: output spans too small");
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  // The range check and the counting run over W lanes; every id is valid past this call.
  std::vector<std::uint32_t> counts = count_ids_per_chunk<W>(
      ex, name, "bucket_counts", bucket, p, chunk, "partition_stable", "bucket");
  const auto totals = chunk_offsets(counts, chunks, p);
  std::size_t running = 0;
  for (std::size_t d = 0; d < p; ++d) {
    bucket_begin[d] = std::uint32_t(running);
    running += totals[d];
  }
  bucket_begin[p] = std::uint32_t(running);
  ex.parallel_for(launch_name(name, "bucket_scatter"), n, chunk, [&](std::size_t b, std::size_t e) {
    // Locals: through the spans every store to out could alias offset and force reloads.
    std::uint32_t* const offset = counts.data() + (b / chunk) * p;
    const std::uint32_t* const id = bucket.data();
    std::uint32_t* const dst = out.data();
    // The scatter is per element (each lane bumps its bucket's cursor, and lanes of one group
    // may share a bucket), so a W-group's lanes go in element order: stable for every W.
    // The ids are read straight from memory: a vector load plus W lane extracts would only
    // add work to this store-bound loop.
    std::size_t i = b;
    for (; i + W <= e; i += W)
      for (int k = 0; k < W; ++k) dst[offset[id[i + k]]++] = std::uint32_t(i + k);
    for (; i < e; ++i) dst[offset[id[i]]++] = std::uint32_t(i);
  });
}

void partition_stable(Executor& ex, std::string_view name, std::span<const std::uint32_t> bucket,
                      std::uint32_t p, std::span<std::uint32_t> out,
                      std::span<std::uint32_t> bucket_begin, std::size_t chunk) {
  dispatch_lanes(ex.lanes(), [&](auto w) { partition_stable<w.value>(ex, name, bucket, p, out, bucket_begin, chunk); });
}

template void partition_stable<1>(Executor&, std::string_view, std::span<const std::uint32_t>, std::uint32_t,
                                  std::span<std::uint32_t>, std::span<std::uint32_t>, std::size_t);
template void partition_stable<4>(Executor&, std::string_view, std::span<const std::uint32_t>, std::uint32_t,
                                  std::span<std::uint32_t>, std::span<std::uint32_t>, std::size_t);
template void partition_stable<8>(Executor&, std::string_view, std::span<const std::uint32_t>, std::uint32_t,
                                  std::span<std::uint32_t>, std::span<std::uint32_t>, std::size_t);
template void partition_stable<16>(Executor&, std::string_view, std::span<const std::uint32_t>, std::uint32_t,
                                   std::span<std::uint32_t>, std::span<std::uint32_t>, std::size_t);

}  // namespace speculum::par
