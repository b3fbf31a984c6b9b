// Stable bucket partition and LSD radix sort on a shared counting scatter (partition.h;
// ROGER §4.5 bucket sort).
#include "parallel/partition.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

#include "parallel/chunk_counts.h"

namespace speculum::par {

namespace {

// Per-chunk counts → offsets[chunk * p + bucket] = first output slot of that chunk's
// elements of that bucket (bucket-major, then chunk order). Returns per-bucket totals.
std::vector<std::size_t> chunk_offsets(std::span<std::uint32_t> counts, std::size_t chunks,
                                       std::size_t p) {
  // Same offsets as walking bucket-major, but row by row: per-bucket totals, bucket starts,
  // then each chunk's row in chunk order (contiguous reads; a column walk strides by p).
  std::vector<std::size_t> totals(p, 0);
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t d = 0; d < p; ++d) totals[d] += counts[c * p + d];
  std::vector<std::uint32_t> next(p);
  std::size_t running = 0;
  for (std::size_t d = 0; d < p; ++d) {
    next[d] = std::uint32_t(running);
    running += totals[d];
  }
  for (std::size_t c = 0; c < chunks; ++c)
    for (std::size_t d = 0; d < p; ++d) {
      const std::uint32_t k = counts[c * p + d];
      counts[c * p + d] = next[d];
      next[d] += k;
    }
  return totals;
}

// Software write-combining for the digit scatter: each bucket collects one cache line of
// keys (and the matching payloads) before they go out together, so the scatter writes
// whole lines instead of one element to each of up to 2048 pages per step.
template <class Key>
struct WriteCombine {
  static constexpr std::size_t kLine = 64 / sizeof(Key);  // elements per bucket buffer
  std::vector<Key> keys;
  std::vector<std::uint32_t> payload;
  std::vector<std::uint32_t> fill;
  void reserve(std::size_t buckets) {
    if (fill.size() >= buckets) return;
    keys.resize(buckets * kLine);
    payload.resize(buckets * kLine);
    fill.resize(buckets);
  }
};

template <class Key>
WriteCombine<Key>& thread_write_combine(std::size_t buckets) {
  thread_local WriteCombine<Key> wc;
  wc.reserve(buckets);
  return wc;
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
  // Only the bits that differ between keys need sorting passes: find them in one read
  // (OR of key ^ keys[0]), then cover [lowest, highest] varying bit with the fewest digits
  // of at most kMaxDigitBits bits, equally sized (3 passes for full 32-bit keys).
  constexpr unsigned kMaxDigitBits = 11;
  const Key first = keys[0];
  const Key varying = ex.parallel_reduce(
      launch_name(name, "varying_bits"), n, chunk, Key{0},
      [&](std::size_t b, std::size_t e) {
        Key v = 0;
        for (std::size_t i = b; i < e; ++i) v |= keys[i] ^ first;
        return v;
      },
      [](Key a, Key b) { return Key(a | b); });
  if (varying == 0) return;  // all keys equal: a stable sort leaves everything in place
  const unsigned lo_bit = unsigned(std::countr_zero(varying));
  const unsigned bits = unsigned(std::bit_width(varying)) - lo_bit;
  const unsigned passes = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
  const unsigned digit_bits = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t(1) << digit_bits;

  RadixSortScratch<Key> own;
  RadixSortScratch<Key>& s = scratch ? *scratch : own;
  s.keys.resize(n);
  if (with_payload) s.payload.resize(n);
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  s.counts.resize(chunks * buckets);
  std::span<Key> src_k = keys, dst_k = s.keys;
  std::span<std::uint32_t> src_p = payload, dst_p = with_payload ? std::span(s.payload) : payload;
  const std::string hist_name = launch_name(name, "digit_counts");
  const std::string scatter_name = launch_name(name, "digit_scatter");
  for (unsigned pass = 0; pass < passes; ++pass) {
    const unsigned shift = lo_bit + pass * digit_bits;
    const Key mask = Key(buckets - 1);
    ex.parallel_for(hist_name, n, chunk, [&](std::size_t b, std::size_t e) {
      std::uint32_t* const count = s.counts.data() + (b / chunk) * buckets;
      const Key* const in_k = src_k.data();
      const unsigned sh = shift;
      const Key m = mask;
      std::fill(count, count + buckets, 0u);
      for (std::size_t i = b; i < e; ++i) ++count[(in_k[i] >> sh) & m];
    });
    const auto totals = chunk_offsets(s.counts, chunks, buckets);
    if (std::find(totals.begin(), totals.end(), n) != totals.end()) continue;  // digit constant
    ex.parallel_for(scatter_name, n, chunk, [&](std::size_t b, std::size_t e) {
      constexpr std::size_t L = WriteCombine<Key>::kLine;
      // Everything the loop touches in locals: through the closure, every store could
      // alias the captures and force reloads.
      std::uint32_t* const offset = s.counts.data() + (b / chunk) * buckets;
      WriteCombine<Key>& wc = thread_write_combine<Key>(buckets);
      std::uint32_t* const fill = wc.fill.data();
      Key* const buf_k = wc.keys.data();
      std::uint32_t* const buf_p = wc.payload.data();
      const Key* const in_k = src_k.data();
      const std::uint32_t* const in_p = src_p.data();
      Key* const out_k = dst_k.data();
      std::uint32_t* const out_p = dst_p.data();
      const unsigned sh = shift;
      const Key m = mask;
      const bool pay = with_payload;
      std::fill(fill, fill + buckets, 0u);
      for (std::size_t i = b; i < e; ++i) {
        const Key k = in_k[i];
        const std::size_t d = std::size_t((k >> sh) & m);
        const std::uint32_t f = fill[d];
        buf_k[d * L + f] = k;
        if (pay) buf_p[d * L + f] = in_p[i];
        if (f + 1 == L) {  // fixed-size copies: inlined vector moves, not memmove calls
          std::memcpy(out_k + offset[d], buf_k + d * L, L * sizeof(Key));
          if (pay) std::memcpy(out_p + offset[d], buf_p + d * L, L * sizeof(std::uint32_t));
          offset[d] += L;
          fill[d] = 0;
        } else {
          fill[d] = f + 1;
        }
      }
      for (std::size_t d = 0; d < buckets; ++d) {  // partial lines, in bucket order
        std::copy_n(buf_k + d * L, fill[d], out_k + offset[d]);
        if (pay) std::copy_n(buf_p + d * L, fill[d], out_p + offset[d]);
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
  std::vector<std::uint32_t> counts = count_ids_per_chunk(
      ex, name, "bucket_counts", bucket, p, chunk, "partition_stable", "bucket");
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
