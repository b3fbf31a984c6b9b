// The single-pass chained form shared by the scan and the scatter compaction (DESIGN.md
// "Stream constraints"): chunks are claimed in index order, each computes its sum and
// publishes it, finds its offset by decoupled look-back over what its predecessors
// published, publishes its inclusive prefix, and then does its own output work from that
// offset — one launch, each input chunk read from memory once. The offset is the serial left
// fold of the chunk sums in chunk order, so it has the same bits for any thread count and
// timing.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string_view>
#include <thread>
#include <vector>

#include "parallel/executor.h"
#include "parallel/scan_kernels.h"
#include "parallel/stream.h"

namespace speculum::par {
namespace detail {

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

}  // namespace detail

// Runs the chained pass over the `chunks` chunks of `n` elements as one launch
// "<name>/<phase>" (recorded with n and chunks, whatever the thread count): for every chunk
// c, sum_of(c) (the chunk's ⊕-sum; called again by look-back for a missing predecessor when
// may_compute), then finish(c, offset, sum, workers) with offset = init ⊕ sums of chunks [0, c)
// and sum = sum_of(c).
// `workers` (the number of threads taking chunks) lets finish guess the chunk this thread
// takes next (c + workers). Returns init ⊕ every sum (init when chunks == 0).
// may_compute false (in place): a missing sum is awaited instead of computed (see look_back).
template <class T, class Op, class SumOf, class Finish>
T chained_pass(Executor& ex, std::string_view name, std::string_view phase, std::size_t n, std::size_t chunks,
               T init, Op& op, SumOf&& sum_of, bool may_compute, Finish&& finish) {
  if (chunks == 0) return init;
  using detail::ScanLink;
  std::unique_ptr<ScanLink<T>[]> links(new ScanLink<T>[chunks]);
  // Chunks are handed out in index order, so a chunk's predecessors are usually done or in
  // flight on another thread, and the look-back stops after one or two links; with
  // may_compute no thread ever blocks on another.
  std::atomic<std::size_t> next{0};
  const std::size_t workers = std::min<std::size_t>(std::size_t(ex.threads()), chunks);
  ex.run_workers(launch_name(name, phase), workers, n, chunks, [&](std::size_t) {
    std::vector<T> sums;
    for (;;) {
      const std::size_t c = next.fetch_add(1, std::memory_order_relaxed);
      if (c >= chunks) return;
      ScanLink<T>& link = links[c];
      link.sum = sum_of(c);
      link.state.store(ScanLink<T>::kSum, std::memory_order_release);
      const T offset = detail::look_back(links.get(), c, init, op, sum_of, may_compute, sums);
      link.prefix = op(offset, link.sum);
      link.state.store(ScanLink<T>::kPrefix, std::memory_order_release);
      finish(c, offset, link.sum, workers);
    }
  });
  return links[chunks - 1].prefix;
}

}  // namespace speculum::par
