// Exclusive and inclusive scan over the Executor in one pass over memory (single-pass
// chained scan with decoupled look-back, DESIGN.md "Stream constraints"): each fixed chunk
// is reduced, gets its offset from the prefixes its predecessors publish, and is scanned
// again from cache; big outputs go out with streaming stores. The association (chunk sums
// folded in chunk order from init) is fixed, so results are the same for any thread count,
// lane width and timing, floats included.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <vector>

#include "parallel/scan_kernels.h"
#include "parallel/stream.h"

namespace speculum::par {

namespace detail {

// Outputs at least this large bypass the caches (streaming stores): they cannot stay cached
// for the next kernel anyway, and a cached store would first read every output line from
// memory (read-for-ownership), a third memory stream beside the input read and the write.
inline constexpr std::size_t kScanStreamingBytes = std::size_t(8) << 20;

// What chunk c publishes: first its sum (state kSum), then its inclusive prefix, init ⊕
// every element up to the chunk's end (state kPrefix). A cache line each, so a thread
// polling a link reads a line only its owner writes.
template <class T>
struct alignas(64) ScanLink {
  static constexpr std::uint32_t kNone = 0, kSum = 1, kPrefix = 2;
  std::atomic<std::uint32_t> state{kNone};
  T sum{};
  T prefix{};
};

// Polls before a thread gives up waiting for a predecessor's sum and computes it itself
// (about the time one chunk's reduction takes): a descheduled thread on an oversubscribed
// machine then costs one extra chunk read, not a time slice.
inline constexpr unsigned kScanPatience = 1024;

// Offset of chunk c (the inclusive prefix of chunk c-1) by decoupled look-back: walk back
// over published sums, or sums this thread computes itself, to the nearest published prefix
// (or init before chunk 0), then fold forward. The fold is the same left fold in chunk order
// as a serial pass, (((init ⊕ s0) ⊕ s1) ⊕ ...), whichever prefix it starts from, so the
// offset has the same bits for any timing. `sums` is the caller's scratch.
// In place (`may_compute` false) a missing sum is awaited instead: its owner may publish it
// and start overwriting the chunk's input while this thread would still be reading it.
template <class T, class Op, class SumOf>
T look_back(const ScanLink<T>* links, std::size_t c, T init, Op& op, SumOf&& sum_of,
            bool may_compute, std::vector<T>& sums) {
  sums.clear();
  T base = init;
  for (std::size_t j = c; j-- > 0;) {
    std::uint32_t s = links[j].state.load(std::memory_order_acquire);
    for (unsigned spin = 0; s == ScanLink<T>::kNone && (spin < kScanPatience || !may_compute); ++spin) {
      if (spin < kScanPatience) scan_kernels::cpu_relax();
      else std::this_thread::yield();  // the owner sums without waiting on anyone: it will publish
      s = links[j].state.load(std::memory_order_acquire);
    }
    if (s == ScanLink<T>::kPrefix) {
      base = links[j].prefix;
      break;
    }
    sums.push_back(s == ScanLink<T>::kSum ? links[j].sum : sum_of(j));
  }
  for (std::size_t k = sums.size(); k-- > 0;) base = op(base, sums[k]);
  return base;
}

template <int W, bool Inclusive, class T, class Op>
T scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init, Op op,
       std::size_t chunk) {
  const std::size_t n = in.size();
  if (out.size() < n) throw std::invalid_argument("scan: output shorter than input");
  if (chunk == 0) chunk = 1;
  const std::size_t chunks = Executor::chunk_count(n, chunk);
  if (chunks == 0) return init;
  const bool streaming = n * sizeof(T) >= kScanStreamingBytes;
  const T* const src = in.data();
  T* const dst = out.data();
  auto sum_of = [&](std::size_t c) {
    const std::size_t b = c * chunk;
    return scan_kernels::chunk_sum<W>(src + b, std::min(n, b + chunk) - b, op);
  };
  std::unique_ptr<ScanLink<T>[]> links(new ScanLink<T>[chunks]);
  // Chunks are handed out in index order, so a chunk's predecessors are usually done or in
  // flight on another thread, and the look-back stops after one or two links; out of place,
  // no thread ever blocks on another (a missing sum is computed, not awaited).
  const auto addr = [](const T* p) { return reinterpret_cast<std::uintptr_t>(p); };
  const bool in_place = addr(src) < addr(dst + n) && addr(dst) < addr(src + n);
  std::atomic<std::size_t> next{0};
  const std::size_t workers = std::min<std::size_t>(std::size_t(ex.threads()), chunks);
  ex.parallel_for(launch_name(name, "chained_scan"), workers, 1, [&](std::size_t, std::size_t) {
    std::vector<T> sums;
    for (;;) {
      const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
      if (c >= chunks) return;
      ScanLink<T>& link = links[c];
      link.sum = sum_of(c);
      link.state.store(ScanLink<T>::kSum, std::memory_order_release);
      const T offset = look_back(links.get(), c, init, op, sum_of, !in_place, sums);
      link.prefix = op(offset, link.sum);
      link.state.store(ScanLink<T>::kPrefix, std::memory_order_release);
      // With chunks taken in turn, this thread's next chunk is most likely c + workers: the
      // kernel prefetches it while it scans (a prefetch reads nothing in the memory model, so
      // a wrong guess only wastes bandwidth).
      const std::size_t b = c * chunk, guess = std::min(n, (c + workers) * chunk);
      scan_kernels::chunk_scan<W, Inclusive>(src + b, dst + b, std::min(n, b + chunk) - b, offset, op,
                                          streaming, src + guess, std::min(n, guess + chunk) - guess);
    }
  });
  return links[chunks - 1].prefix;
}

// W = 0: the width `--lanes` chose (default_lanes()).
template <int W, bool Inclusive, class T, class Op>
T scan_at_width(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out, T init,
                Op op, std::size_t chunk) {
  if constexpr (W == 0) {
    return dispatch_lanes(default_lanes(), [&](auto w) {
      return scan<decltype(w)::value, Inclusive>(ex, name, in, out, init, op, chunk);
    });
  } else {
    return scan<W, Inclusive>(ex, name, in, out, init, op, chunk);
  }
}
}  // namespace detail

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i-1]; returns the total init ⊕ in[0..n). out may alias in.
// W: lane width of the kernels (1, 4, 8, 16; 0 = default_lanes()); the bits do not depend on it.
template <int W = 0, class T, class Op = std::plus<T>>
T exclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kStreamChunk) {
  return detail::scan_at_width<W, false>(ex, name, in, out, init, op, chunk);
}

// out[i] = init ⊕ in[0] ⊕ ... ⊕ in[i]; returns the total. out may alias in.
template <int W = 0, class T, class Op = std::plus<T>>
T inclusive_scan(Executor& ex, std::string_view name, std::span<const T> in, std::span<T> out,
                 T init = T{}, Op op = {}, std::size_t chunk = kStreamChunk) {
  return detail::scan_at_width<W, true>(ex, name, in, out, init, op, chunk);
}

}  // namespace speculum::par
