// Stable bucket partition and LSD radix sort on a shared counting scatter (partition.h;
// ROGER §4.5 bucket sort).
#include "parallel/partition.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace speculum::par {

namespace {

// Per-chunk counts → offsets[chunk * p + bucket] = first output slot of that chunk's
// elements of that bucket (bucket-major, then chunk order). Returns per-bucket totals.
std::vector<std::size_t> chunk_offsets(std::span<std::uint32_t> counts, std::size_t chunks,
                                       std::size_t p) {
  std::vector<std::size_t> totals(p, 0);
  std::size_t running = 0;
  for (std::size_t d = 0; d < p; ++d) {
    const std::size_t start = running;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint32_t k = counts[c * p + d];
      counts[c * p + d] = std::uint32_t(running);
      running += k;
    }
    totals[d] = running - start;
  }
  return totals;
}

template <class Key>
void radix_sort_impl(Executor& ex, std::string_view name, std::span<Key> keys,
                     std::span<std::uint32_t> payload, RadixSortScratch<Key>* scratch, std::size_t chunk) {
  const std::size_t n = keys.size();
  const bool with_payload = !payload.empty();
  if (with_payload && payload.size() != n)
    throw std::invalid_argument("radix_sort: payload size differs from key count");
  if (n <= 1) return;
  if (chunk == 0) chunk = 1;
  RadixSortScratch<Key> own;
  RadixSortScratch<Key>& s = scratch ? *scratch : own;
  s.keys.resize(n);
  if (with_payload) s.payload.resize(n);
  constexpr std::size_t kBuckets = 256;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  s.counts.resize(chunks * kBuckets);
  std::span<Key> src_k = keys, dst_k = s.keys;
  std::span<std::uint32_t> src_p = payload, dst_p = with_payload ? std::span(s.payload) : payload;
  const std::string hist_name = launch_name(name, "digit_counts");
  const std::string scatter_name = launch_name(name, "digit_scatter");
  for (unsigned shift = 0; shift < 8 * sizeof(Key); shift += 8) {
    ex.parallel_for(hist_name, n, chunk, [&](std::size_t b, std::size_t e) {
      std::uint32_t* count = s.counts.data() + (b / chunk) * kBuckets;
      std::fill(count, count + kBuckets, 0u);
      for (std::size_t i = b; i < e; ++i) ++count[(src_k[i] >> shift) & 0xff];
    });
    const auto totals = chunk_offsets(s.counts, chunks, kBuckets);
    if (std::find(totals.begin(), totals.end(), n) != totals.end()) continue;  // digit constant
    ex.parallel_for(scatter_name, n, chunk, [&](std::size_t b, std::size_t e) {
      std::uint32_t* offset = s.counts.data() + (b / chunk) * kBuckets;
      for (std::size_t i = b; i < e; ++i) {
        const std::uint32_t slot = offset[(src_k[i] >> shift) & 0xff]++;
        dst_k[slot] = src_k[i];
        if (with_payload) dst_p[slot] = src_p[i];
      }
    });
    std::swap(src_k, dst_k);
    std::swap(src_p, dst_p);
  }
  if (src_k.data() != keys.data()) {
    ex.parallel_for(launch_name(name, "copy_back"), n, chunk, [&](std::size_t b, std::size_t e) {
      std::copy(src_k.begin() + b, src_k.begin() + e, keys.begin() + b);
      if (with_payload) std::copy(src_p.begin() + b, src_p.begin() + e, payload.begin() + b);
    });
  }
}

}  // namespace

void partition_stable(Executor& ex, std::string_view name, std::span<const std::uint32_t> bucket,
                      std::uint32_t p, std::span<std::uint32_t> out,
                      std::span<std::uint32_t> bucket_begin, std::size_t chunk) {
  const std::size_t n = bucket.size();
  if (p == 0) throw std::invalid_argument("partition_stable: need at least one bucket");
  if (out.size() < n || bucket_begin.size() < std::size_t(p) + 1)
    throw std::invalid_argument("partition_stable: output spans too small");
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  std::vector<std::uint32_t> counts(chunks * p);
  std::vector<std::uint8_t> bad(chunks, 0);
  ex.parallel_for(launch_name(name, "bucket_counts"), n, chunk, [&](std::size_t b, std::size_t e) {
    std::uint32_t* count = counts.data() + (b / chunk) * p;
    for (std::size_t i = b; i < e; ++i) {
      if (bucket[i] >= p) {
        bad[b / chunk] = 1;
        return;
      }
      ++count[bucket[i]];
    }
  });
  if (std::find(bad.begin(), bad.end(), 1) != bad.end())
    throw std::invalid_argument("partition_stable: a bucket id is >= the bucket count " + std::to_string(p));
  const auto totals = chunk_offsets(counts, chunks, p);
  std::size_t running = 0;
  for (std::size_t d = 0; d < p; ++d) {
    bucket_begin[d] = std::uint32_t(running);
    running += totals[d];
  }
  bucket_begin[p] = std::uint32_t(running);
  ex.parallel_for(launch_name(name, "bucket_scatter"), n, chunk, [&](std::size_t b, std::size_t e) {
    std::uint32_t* offset = counts.data() + (b / chunk) * p;
    for (std::size_t i = b; i < e; ++i) out[offset[bucket[i]]++] = std::uint32_t(i);
  });
}

void radix_sort(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>* scratch,
                std::size_t chunk) {
  radix_sort_impl(ex, name, keys, payload, scratch, chunk);
}

void radix_sort(Executor& ex, std::string_view name, std::span<std::uint64_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint64_t>* scratch,
                std::size_t chunk) {
  radix_sort_impl(ex, name, keys, payload, scratch, chunk);
}

}  // namespace speculum::par
