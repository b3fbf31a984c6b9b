// Stable radix sort (partition.h). 32-bit keys: one counting scatter on the most significant
// digit into cache-sized buckets, then each bucket sorted in cache by LSD passes (ROGER §4.5
// bucket sort as the first level). 64-bit keys, and 32-bit keys whose top digit is badly
// skewed: LSD passes over the whole array. A stable sort's output is unique, so every path
// gives the same bytes for any thread count and lane width W. The kernels are written over
// Lanes<W>: digits are extracted W keys at a time, output lines go out as W-lane streaming
// stores; the scatters themselves place elements one by one, in element order.
#include <algorithm>
#include <bit>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "parallel/chunk_counts.h"
#include "parallel/lanes_stream.h"
#include "parallel/partition.h"

namespace speculum::par {

namespace {

constexpr unsigned kMaxDigitBits = 11;  // 2048 buckets: counts and line buffers fit in L2

// f(i, key, digit) for every i in [b, e), in order, with digit = (key >> shift) & mask
// computed for W keys at a time in lanes. (Key may be a packed word: the shift then
// reaches into its key half.)
template <int W, class Key, class F>
[[gnu::always_inline]] inline void for_each_digit(const Key* keys, std::size_t b, std::size_t e,
                                                  unsigned shift, Key mask, F&& f) {
  using V = typename Lanes<W>::template simd<Key>;
  std::size_t i = b;
  // vector_aligned asks for the simd type's alignment: 128 bytes for 16 lanes of 64 bits.
  alignas(stdx::memory_alignment_v<V>) Key digit[W];
  for (; i + W <= e; i += W) {
    // The digits go through a W-word buffer: reading it back costs a load per lane, where
    // extracting lanes from the register costs a shuffle each.
    ((V(keys + i, stdx::element_aligned) >> int(shift)) & V(mask)).copy_to(digit, stdx::vector_aligned);
    for (int j = 0; j < W; ++j) f(i + std::size_t(j), keys[i + std::size_t(j)], std::size_t(digit[j]));
  }
  for (; i < e; ++i) f(i, keys[i], std::size_t((keys[i] >> shift) & mask));
}

// ---------------------------------------------------------------------------------------
// LSD over the whole array (64-bit keys; fallback for skewed 32-bit keys).

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

// OR over i of keys[i] ^ keys[0]: the bits that differ between keys (0: all equal).
template <int W, class Key>
Key varying_bits(Executor& ex, std::string_view name, std::span<const Key> keys, std::size_t chunk) {
  using V = typename Lanes<W>::template simd<Key>;
  const Key first = keys[0];
  return ex.parallel_reduce(
      launch_name(name, "varying_bits"), keys.size(), chunk, Key{0},
      [&](std::size_t b, std::size_t e) {
        V lanes(Key{0});
        std::size_t i = b;
        for (; i + W <= e; i += W) lanes |= V(keys.data() + i, stdx::element_aligned) ^ V(first);
        Key v = 0;
        for (int j = 0; j < W; ++j) v |= Key(lanes[j]);  // OR: any grouping gives the same bits
        for (; i < e; ++i) v |= keys[i] ^ first;
        return v;
      },
      [](Key a, Key b) { return Key(a | b); });
}

// Sorts on bits [lo_bit, lo_bit + bits) only (the others are equal in every key).
template <int W, class Key>
void lsd_sort(Executor& ex, std::string_view name, std::span<Key> keys, std::span<std::uint32_t> payload,
              RadixSortScratch<Key>& s, std::size_t chunk, unsigned lo_bit, unsigned bits) {
  const std::size_t n = keys.size();
  const bool with_payload = !payload.empty();
  const unsigned passes = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
  const unsigned digit_bits = (bits + passes - 1) / passes;
  const std::size_t buckets = std::size_t(1) << digit_bits;
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
      for_each_digit<W>(in_k, b, e, sh, m, [&](std::size_t, Key, std::size_t d) { ++count[d]; });
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
      for_each_digit<W>(in_k, b, e, sh, m, [&](std::size_t i, Key k, std::size_t d) {
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
      });
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

// ---------------------------------------------------------------------------------------
// 32-bit keys: MSD digit scatter, then in-cache LSD per bucket.
//
// Elements travel packed: key << 32 | payload in one u64 (or the bare u32 key without a
// payload), so each scatter step is one store to one place, half the write streams of
// separate key and payload arrays.

template <class E>
struct Packed;
template <>
struct Packed<std::uint64_t> {
  static std::uint64_t pack(std::uint32_t k, const std::uint32_t* p, std::size_t i) {
    return std::uint64_t(k) << 32 | p[i];
  }
  static std::uint32_t key(std::uint64_t e) { return std::uint32_t(e >> 32); }
  static void unpack(std::uint64_t e, std::uint32_t* k, std::uint32_t* p, std::size_t i) {
    k[i] = std::uint32_t(e >> 32);
    p[i] = std::uint32_t(e);
  }
};
template <>
struct Packed<std::uint32_t> {
  static std::uint32_t pack(std::uint32_t k, const std::uint32_t*, std::size_t) { return k; }
  static std::uint32_t key(std::uint32_t e) { return e; }
  static void unpack(std::uint32_t e, std::uint32_t* k, std::uint32_t*, std::size_t i) { k[i] = e; }
};

// A bucket larger than this is not sorted in cache: the whole sort goes LSD instead (a
// skewed top digit would otherwise leave one thread sorting most of the array).
constexpr std::size_t kMaxLocalBucket = std::size_t(1) << 18;

// Sorted outputs at least this large are written with streaming stores (unpack_bucket).
constexpr std::size_t kStreamingBytes = std::size_t(8) << 20;

// Per-thread buffers of the 32-bit path: one 64-byte line per top-digit bucket for the
// write-combining scatter, and the ping-pong array and digit counts of a bucket's sort.
template <class E>
struct ThreadBuffers {
  struct FreeLines {
    void operator()(E* p) const { std::free(p); }
  };
  std::unique_ptr<E, FreeLines> lines;
  std::vector<std::uint32_t> fill;
  std::vector<E> tmp;
  std::vector<std::uint32_t> counts;
  E* line_buffers(std::size_t buckets) {
    if (fill.size() < buckets) {
      lines.reset(static_cast<E*>(std::aligned_alloc(64, buckets * 64)));
      if (!lines) throw std::bad_alloc();
      fill.resize(buckets);
    }
    return lines.get();
  }
};

template <class E>
ThreadBuffers<E>& thread_buffers() {
  thread_local ThreadBuffers<E> t;
  return t;
}

// Writes one full 64-byte line, 64-byte aligned, bypassing the caches (the scatter target
// is not read again before the whole pass is done, so caching it only evicts the sources).
template <int W>
void stream_line(void* dst, const void* src) {
  stream_words<W>(static_cast<const std::uint32_t*>(src), 16, static_cast<std::uint32_t*>(dst));
}

// dst[i] = the high (Key = true) or low 32 bits of src[i], i < m; whole aligned lines of dst
// go out as streaming stores (the sorted output is too big to stay cached, and a cached
// store would first read its line from memory), the unaligned head and tail as plain stores.
template <int W, bool Key>
void stream_halves(const std::uint64_t* src, std::size_t m, std::uint32_t* dst) {
  std::size_t i = to_line(dst, m);
  for (std::size_t j = 0; j < i; ++j) dst[j] = std::uint32_t(Key ? src[j] >> 32 : src[j]);
  const auto* words = reinterpret_cast<const std::uint32_t*>(src);  // low, high, low, high, ...
  for (; i + W <= m; i += W) {
    const auto [low, high] = deinterleave<W>(words + 2 * i);
    stream_store<W>(Key ? high : low, dst + i);
  }
  for (; i < m; ++i) dst[i] = std::uint32_t(Key ? src[i] >> 32 : src[i]);
}

template <int W>
void stream_copy(const std::uint32_t* src, std::size_t m, std::uint32_t* dst) {
  std::size_t i = to_line(dst, m);
  std::copy_n(src, i, dst);
  const std::size_t body = (m - i) / W * W;
  stream_words<W>(src + i, body, dst + i);
  i += body;
  std::copy(src + i, src + m, dst + i);
}

// Writes a sorted bucket out unpacked: keys[i] (and payload[i]) from from[i], i < m.
template <int W, class E>
void unpack_bucket(const E* from, std::size_t m, std::uint32_t* keys, std::uint32_t* payload,
                   bool streaming) {
  if (!streaming) {
    for (std::size_t i = 0; i < m; ++i) Packed<E>::unpack(from[i], keys, payload, i);
    return;
  }
  if constexpr (sizeof(E) == 8) {
    stream_halves<W, true>(from, m, keys);
    stream_halves<W, false>(from, m, payload);
  } else {
    stream_copy<W>(from, m, keys);
  }
}

// Chunk [b, e) of the top-digit scatter into `out` (64-byte aligned). offset[d] = next slot
// of bucket d. Each bucket's line buffer mirrors the line of `out` it is filling, so a
// full line goes out as one aligned streaming store; the first line of a bucket's range
// and its last partial line are written element-wise (they share lines with neighbours).
template <int W, class E>
void top_scatter_chunk(const std::uint32_t* keys, const std::uint32_t* payload, std::size_t b,
                       std::size_t e, unsigned shift, std::uint32_t mask, std::uint32_t* offset,
                       std::size_t buckets, E* out) {
  constexpr std::uint32_t L = 64 / sizeof(E);
  ThreadBuffers<E>& tb = thread_buffers<E>();
  E* const line = tb.line_buffers(buckets);
  std::uint32_t* const fill = tb.fill.data();
  for (std::size_t d = 0; d < buckets; ++d) fill[d] = offset[d] & (L - 1);
  for_each_digit<W>(keys, b, e, shift, mask, [&](std::size_t i, std::uint32_t k, std::size_t d) {
    const std::uint32_t f = fill[d];
    line[d * L + f] = Packed<E>::pack(k, payload, i);
    if (f + 1 == L) {
      const std::uint32_t o = offset[d];
      const std::uint32_t start = o & (L - 1);
      E* const dst = out + (o - start);
      if (start == 0) {
        stream_line<W>(dst, line + d * L);
      } else {
        for (std::uint32_t j = start; j < L; ++j) dst[j] = line[d * L + j];
      }
      offset[d] = o - start + L;
      fill[d] = 0;
    } else {
      fill[d] = f + 1;
    }
  });
  for (std::size_t d = 0; d < buckets; ++d) {
    const std::uint32_t o = offset[d];
    const std::uint32_t start = o & (L - 1);
    for (std::uint32_t j = start; j < fill[d]; ++j) out[o - start + j] = line[d * L + j];
  }
  stream_fence();  // streaming stores are weakly ordered: publish them before the join
}

// Stable sort of one top-digit bucket src[0, m) on key bits [lo_bit, lo_bit + bits) (every
// other bit is equal within the bucket), written unpacked to keys/payload[0, m).
template <int W, class E>
void sort_bucket(E* src, std::size_t m, unsigned lo_bit, unsigned bits, std::uint32_t* keys,
                 std::uint32_t* payload, bool streaming) {
  auto unpack_all = [&](const E* from) { unpack_bucket<W>(from, m, keys, payload, streaming); };
  if (bits == 0 || m <= 1) return unpack_all(src);
  if (m <= 32) {  // insertion sort: stable (moves only past strictly greater keys)
    for (std::size_t i = 1; i < m; ++i) {
      const E x = src[i];
      std::size_t j = i;
      for (; j > 0 && Packed<E>::key(src[j - 1]) > Packed<E>::key(x); --j) src[j] = src[j - 1];
      src[j] = x;
    }
    return unpack_all(src);
  }
  // Digits of at most ~log2(m) + 1 bits: the count tables stay about as small as the bucket.
  const unsigned max_bits =
      std::clamp(unsigned(std::bit_width(m)) + 1, 4u, kMaxDigitBits);
  const unsigned passes = (bits + max_bits - 1) / max_bits;
  const unsigned digit_bits = (bits + passes - 1) / passes;
  const std::size_t radix = std::size_t(1) << digit_bits;
  const std::uint32_t mask = std::uint32_t(radix - 1);
  ThreadBuffers<E>& tb = thread_buffers<E>();
  tb.counts.assign(passes * radix, 0u);
  std::uint32_t* const count = tb.counts.data();
  // One read counts every pass's digit (counts do not depend on the order). The key sits in
  // the high half of a packed word: its digits are digits of the word 32 bits further up.
  constexpr unsigned kKeyShift = sizeof(E) == 8 ? 32 : 0;
  const unsigned s0 = kKeyShift + lo_bit;
  if (passes == 2) {  // the common case (16M uniform keys), unrolled
    std::uint32_t* const c1 = count + radix;
    const unsigned s1 = lo_bit + digit_bits;
    for_each_digit<W>(src, 0, m, s0, E(mask), [&](std::size_t, E x, std::size_t d) {
      ++count[d];
      ++c1[(Packed<E>::key(x) >> s1) & mask];
    });
  } else {
    for_each_digit<W>(src, 0, m, s0, E(mask), [&](std::size_t, E x, std::size_t d) {
      ++count[d];
      const std::uint32_t k = Packed<E>::key(x);
      for (unsigned p = 1; p < passes; ++p) ++count[p * radix + ((k >> (lo_bit + p * digit_bits)) & mask)];
    });
  }
  unsigned active[32];
  unsigned n_active = 0;
  for (unsigned p = 0; p < passes; ++p) {
    std::uint32_t* c = count + p * radix;
    if (std::find(c, c + radix, std::uint32_t(m)) != c + radix) continue;  // digit constant
    std::uint32_t running = 0;
    for (std::size_t d = 0; d < radix; ++d) {
      const std::uint32_t k = c[d];
      c[d] = running;
      running += k;
    }
    active[n_active++] = p;
  }
  if (n_active == 0) return unpack_all(src);
  if (tb.tmp.size() < m) tb.tmp.resize(m);
  E* const tmp = tb.tmp.data();
  // Every pass scatters packed words within cache; the output arrays are then written in
  // order (scattering straight into them would miss on a line of each per store).
  E* cur = src;
  for (unsigned a = 0; a < n_active; ++a) {
    const unsigned shift = lo_bit + active[a] * digit_bits;
    std::uint32_t* const offset = count + active[a] * radix;
    E* const dst = cur == src ? tmp : src;
    for (std::size_t i = 0; i < m; ++i) {
      const E x = cur[i];
      dst[offset[(Packed<E>::key(x) >> shift) & mask]++] = x;
    }
    cur = dst;
  }
  unpack_all(cur);
}

// Top digit [shift, shift + top_bits) of the 32-bit path: buckets of ~8-16K elements on
// average (sorted in L2), and no more than 22 bits left for them (two in-cache passes of
// <= 11 bits): bits [22, 32) for 16M arbitrary 32-bit keys.
struct TopDigit {
  unsigned shift, bits;
};
TopDigit top_digit(std::size_t n, unsigned lo_bit, unsigned bits) {
  const unsigned cache_top = std::clamp(unsigned(std::bit_width(n)), 16u, 26u) - 15;
  const unsigned top = std::min({bits, kMaxDigitBits, std::max(cache_top, bits > 22 ? bits - 22 : 0u)});
  return {lo_bit + bits - top, top};
}

// s.counts already holds the per-chunk counts of the top digit when `counted`.
template <int W, class E>
void msd_sort32(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>& s,
                std::size_t chunk, unsigned lo_bit, unsigned bits, bool counted) {
  const std::size_t n = keys.size();
  const TopDigit top = top_digit(n, lo_bit, bits);
  const unsigned top_bits = top.bits;
  const unsigned local_bits = bits - top_bits;
  const unsigned shift = top.shift;
  const std::size_t buckets = std::size_t(1) << top_bits;
  const std::uint32_t mask = std::uint32_t(buckets - 1);
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  s.counts.resize(chunks * buckets);
  if (!counted) {
    ex.parallel_for(launch_name(name, "top_counts"), n, chunk, [&](std::size_t b, std::size_t e) {
      std::uint32_t* const count = s.counts.data() + (b / chunk) * buckets;
      const std::uint32_t* const in = keys.data();
      const unsigned sh = shift;
      const std::uint32_t m = mask;
      std::fill(count, count + buckets, 0u);
      for_each_digit<W>(in, b, e, sh, m, [&](std::size_t, std::uint32_t, std::size_t d) { ++count[d]; });
    });
  }
  const auto totals = chunk_offsets(s.counts, chunks, buckets);
  if (local_bits > 0 && *std::max_element(totals.begin(), totals.end()) > kMaxLocalBucket)
    return lsd_sort<W>(ex, name, keys, payload, s, chunk, lo_bit, bits);
  std::vector<std::uint32_t> bucket_begin(buckets + 1);
  std::size_t running = 0;
  for (std::size_t d = 0; d < buckets; ++d) {
    bucket_begin[d] = std::uint32_t(running);
    running += totals[d];
  }
  bucket_begin[buckets] = std::uint32_t(running);
  E* const packed = s.packed.reserve<E>(n);
  ex.parallel_for(launch_name(name, "top_scatter"), n, chunk, [&](std::size_t b, std::size_t e) {
    top_scatter_chunk<W, E>(keys.data(), payload.data(), b, e, shift, mask,
                         s.counts.data() + (b / chunk) * buckets, buckets, packed);
  });
  // Fixed groups of buckets per task (uniform keys: ~8 buckets of n / 2048 elements each).
  constexpr std::size_t kBucketsPerTask = 8;
  // Streaming stores measured faster for the key+payload split (two outputs per packed
  // word) but slower for keys alone (a plain copy out of cache): only the former uses them.
  const bool streaming = sizeof(E) == 8 && n * sizeof(E) >= kStreamingBytes;
  ex.parallel_for(launch_name(name, "bucket_sort"), buckets, kBucketsPerTask,
                  [&](std::size_t b0, std::size_t b1) {
                    for (std::size_t d = b0; d < b1; ++d) {
                      const std::size_t first = bucket_begin[d];
                      sort_bucket<W, E>(packed + first, bucket_begin[d + 1] - first, lo_bit, local_bits,
                                     keys.data() + first,
                                     payload.empty() ? nullptr : payload.data() + first, streaming);
                    }
                    if (streaming) stream_fence();
                  });
}

template <int W, class Key>
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
  if constexpr (sizeof(Key) == 4) {
    // One read finds the varying bits and counts the top digit that arbitrary keys of this
    // n get (bits [22, 32) for 16M); the count is redone only if the keys pick another.
    const TopDigit guess = top_digit(n, 0, 32);
    const std::size_t buckets = std::size_t(1) << guess.bits;
    const std::size_t chunks = Executor::chunk_count(n, chunk);
    s.counts.resize(chunks * buckets);
    const Key first = keys[0];
    const Key varying = ex.parallel_reduce(
        launch_name(name, "varying_bits_top_counts"), n, chunk, Key{0},
        [&](std::size_t b, std::size_t e) {
          std::uint32_t* const count = s.counts.data() + (b / chunk) * buckets;
          const std::uint32_t* const in = keys.data();
          const unsigned sh = guess.shift;
          const std::uint32_t m = std::uint32_t(buckets - 1);
          std::fill(count, count + buckets, 0u);
          Key v = 0;
          for_each_digit<W>(in, b, e, sh, m, [&](std::size_t, std::uint32_t k, std::size_t d) {
            v |= k ^ first;
            ++count[d];
          });
          return v;
        },
        [](Key a, Key b) { return Key(a | b); });
    if (varying == 0) return;  // all keys equal: a stable sort leaves everything in place
    const unsigned lo_bit = unsigned(std::countr_zero(varying));
    const unsigned bits = unsigned(std::bit_width(varying)) - lo_bit;
    const TopDigit top = top_digit(n, lo_bit, bits);
    const bool counted = top.shift == guess.shift && top.bits == guess.bits;
    if (with_payload)
      msd_sort32<W, std::uint64_t>(ex, name, keys, payload, s, chunk, lo_bit, bits, counted);
    else
      msd_sort32<W, std::uint32_t>(ex, name, keys, payload, s, chunk, lo_bit, bits, counted);
  } else {
    // Only the bits that differ between keys need sorting: [lowest, highest] varying bit.
    const Key varying = varying_bits<W, Key>(ex, name, keys, chunk);
    if (varying == 0) return;  // all keys equal: a stable sort leaves everything in place
    const unsigned lo_bit = unsigned(std::countr_zero(varying));
    const unsigned bits = unsigned(std::bit_width(varying)) - lo_bit;
    lsd_sort<W>(ex, name, keys, payload, s, chunk, lo_bit, bits);
  }
}

}  // namespace

template <int W>
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>* scratch, std::size_t chunk) {
  radix_sort_impl<W>(ex, name, keys, payload, scratch, chunk);
}

template <int W>
void radix_sort(Executor& ex, std::string_view name, std::span<std::uint64_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint64_t>* scratch, std::size_t chunk) {
  radix_sort_impl<W>(ex, name, keys, payload, scratch, chunk);
}

#define SPECULUM_RADIX_SORT_AT(W)                                                                       \
  template void radix_sort<W>(Executor&, std::string_view, std::span<std::uint32_t>,                    \
                              std::span<std::uint32_t>, RadixSortScratch<std::uint32_t>*, std::size_t); \
  template void radix_sort<W>(Executor&, std::string_view, std::span<std::uint64_t>,                    \
                              std::span<std::uint32_t>, RadixSortScratch<std::uint64_t>*, std::size_t);
SPECULUM_RADIX_SORT_AT(1)
SPECULUM_RADIX_SORT_AT(4)
SPECULUM_RADIX_SORT_AT(8)
SPECULUM_RADIX_SORT_AT(16)
#undef SPECULUM_RADIX_SORT_AT

void radix_sort(Executor& ex, std::string_view name, std::span<std::uint32_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint32_t>* scratch,
                std::size_t chunk) {
  dispatch_lanes(ex.lanes(), [&](auto w) { radix_sort<w.value>(ex, name, keys, payload, scratch, chunk); });
}

void radix_sort(Executor& ex, std::string_view name, std::span<std::uint64_t> keys,
                std::span<std::uint32_t> payload, RadixSortScratch<std::uint64_t>* scratch,
                std::size_t chunk) {
  dispatch_lanes(ex.lanes(), [&](auto w) { radix_sort<w.value>(ex, name, keys, payload, scratch, chunk); });
}

}  // namespace speculum::par
