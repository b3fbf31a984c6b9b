// The single-pass chained form shared by the scan and the scatter compaction: each chunk
// computes its sum and publishes it, finds its offset by decoupled look-back over what its
// predecessors published, publishes its inclusive prefix, and then does its own output work
// from that offset — one launch, each input chunk read from memory once. The offset is the
// serial left fold of the chunk sums in chunk order, so it has the same bits for any thread
// count, schedule and timing.
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

// What chunk c publishes: that a thread has taken it (kClaimed), then its sum (kSum), then
// its inclusive prefix, init ⊕ every element up to the chunk's end (kPrefix). A cache line
// each, so a thread polling a link reads a line only its owner writes.
template <class T>
struct alignas(64) ScanLink {
  static constexpr std::uint32_t kFree = 0, kClaimed = 1, kSum = 2, kPrefix = 3;
  std::atomic<std::uint32_t> state{kFree};
  T sum{};
  T prefix{};
  // Takes the chunk if no thread has: exactly one caller gets true.
  bool claim() {
    std::uint32_t expected = kFree;
    return state.load(std::memory_order_relaxed) == kFree &&
           state.compare_exchange_strong(expected, kClaimed, std::memory_order_acq_rel);
  }
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
// A predecessor no thread has taken (its worker is descheduled or has not started) is taken
// here and done whole by take(j), which publishes its prefix: waiting for it could wait
// forever, and computing only its sum would read it twice. A predecessor being summed is
// awaited for kScanPatience polls and then summed here too (`may_compute`); in place
// (`may_compute` false) it is awaited however long it takes: its owner may publish the sum
// and start overwriting the chunk's input while this thread would still be reading it.
// Waits end: the owner of a claimed chunk is summing it or doing a lower chunk, and waits
// only on chunks below that (chained_pass).
template <class T, class Op, class SumOf, class Take>
T look_back(ScanLink<T>* links, std::size_t c, T init, Op& op, SumOf&& sum_of, bool may_compute,
            std::vector<T>& sums, Take&& take) {
  using Link = ScanLink<T>;
  sums.clear();
  T base = init;
  for (std::size_t j = c; j-- > 0;) {
    std::uint32_t s = links[j].state.load(std::memory_order_acquire);
    if (s == Link::kFree && links[j].claim()) {
      take(j);
      s = links[j].state.load(std::memory_order_acquire);  // kPrefix
    }
    bool compute = false;
    for (unsigned spin = 0; s < Link::kSum; ++spin) {
      if (spin < kScanPatience) {
        scan_kernels::cpu_relax();
      } else if (may_compute) {
        compute = true;
        break;
      } else {
        std::this_thread::yield();  // the owner waits only on lower chunks: it will publish
      }
      s = links[j].state.load(std::memory_order_acquire);
    }
    if (s == Link::kPrefix) {
      base = links[j].prefix;
      break;
    }
    sums.push_back(compute ? sum_of(j) : links[j].sum);
  }
  for (std::size_t k = sums.size(); k-- > 0;) base = op(base, sums[k]);
  return base;
}

}  // namespace detail

// finish's `next` when the calling thread has no next chunk to sum.
inline constexpr std::size_t kNoChunk = ~std::size_t(0);

// Runs the chained pass over the `chunks` chunks of `n` elements as one launch
// "<name>/<phase>" (recorded with n and chunks, whatever the thread count): for every chunk
// c its ⊕-sum, then finish(c, offset, sum, next) with offset = init ⊕ sums of chunks [0, c)
// and sum = the chunk's sum. Returns init ⊕ every sum (init when chunks == 0).
// Worker w does chunks w, w + workers, w + 2·workers, ... in order. Before finishing chunk c
// it claims its next one, c + workers, and finish returns that chunk's sum (`next`;
// kNoChunk when there is none, and then finish returns anything): a scan reduces its next
// chunk while it writes this one, so the next chunk's read from memory overlaps this one's
// writes, as a copy's do. The pass publishes that sum at once, a round before the next
// chunk's own look-back needs it. The first chunk of each worker, and any chunk whose worker
// has not reached it (taken by a look-back that needs it, or by a worker that has run out of
// chunks), gets its sum from sum_of(c), which look-back also calls for a slow predecessor
// when may_compute. Both ways must give the same bits.
// may_compute false (in place): a slow predecessor's sum is awaited, never computed (see
// look_back). Waits end: a thread waits only on chunks below the one it is doing, and the
// chunk it has claimed ahead gets its sum as soon as that one is done.
template <class T, class Op, class SumOf, class Finish>
T chained_pass(Executor& ex, std::string_view name, std::string_view phase, std::size_t n, std::size_t chunks,
               T init, Op& op, SumOf&& sum_of, bool may_compute, Finish&& finish) {
  if (chunks == 0) return init;
  using Link = detail::ScanLink<T>;
  std::unique_ptr<Link[]> links(new Link[chunks]);
  const std::size_t workers = std::min<std::size_t>(std::size_t(ex.threads()), chunks);
  // Does chunk c, which this thread has claimed (its sum already published when `summed`);
  // with `chain`, claims c + workers too and publishes its sum, and returns whether it did.
  // `sums` is look-back scratch: one per worker, reused for every chunk it does; a
  // predecessor taken inside a look-back (rare: its worker is behind) gets its own, since the
  // outer look-back still holds its sums.
  auto process = [&](auto& self, std::size_t c, bool summed, bool chain, std::vector<T>& sums) -> bool {
    Link& link = links[c];
    if (!summed) {
      link.sum = sum_of(c);
      link.state.store(Link::kSum, std::memory_order_release);
    }
    const T offset = detail::look_back(links.get(), c, init, op, sum_of, may_compute, sums, [&](std::size_t j) {
      std::vector<T> inner;
      self(self, j, false, false, inner);
    });
    link.prefix = op(offset, link.sum);
    link.state.store(Link::kPrefix, std::memory_order_release);
    const std::size_t next = c + workers;
    const bool chained = chain && next < chunks && links[next].claim();
    const T next_sum = finish(c, offset, link.sum, chained ? next : kNoChunk);
    if (chained) {
      links[next].sum = next_sum;
      links[next].state.store(Link::kSum, std::memory_order_release);
    }
    return chained;
  };
  ex.run_workers(launch_name(name, phase), workers, n, chunks, [&](std::size_t w) {
    std::vector<T> sums;
    bool summed = false;  // this worker has claimed chunk c and published its sum
    for (std::size_t c = w; c < chunks; c += workers)
      summed = (summed || links[c].claim()) && process(process, c, summed, true, sums);
    for (std::size_t c = 0; c < chunks; ++c)  // chunks of workers that are behind
      if (links[c].claim()) process(process, c, false, false, sums);
  });
  return links[chunks - 1].prefix;
}

}  // namespace speculum::par
