// The executor: named, timed data-parallel launches on oneTBB over fixed-size chunks.
// Chunk boundaries never depend on the thread count, so any kernel whose chunks write
// disjoint outputs is deterministic for every thread count (docs/architecture.md,
// "Determinism").
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "parallel/fork_join.h"
#include "parallel/interrupt.h"

namespace speculum::par {

// One named kernel launch, as the profiler and `inspect` show it.
struct LaunchRecord {
  std::string name;
  std::size_t elements = 0;
  std::size_t chunks = 0;
  std::int64_t start_ns = 0;  // since the executor's epoch
  std::int64_t duration_ns = 0;
  std::string scope;  // the graph node that issued it ("" outside a graph)
};

// Work counted by an executor since it was made, in elements (pixels, rays, ...) of its
// launches: what a progress bar polls while a long launch runs. Both counts only grow, and
// `done` reaches `launched` when every launch has finished.
struct WorkCount {
  std::uint64_t launched = 0;  // elements of every launch begun
  std::uint64_t done = 0;      // elements of finished chunks
  std::string launch;          // the name of the launch begun last
};

// Names the graph node running on this thread, so launches can be attributed to it in
// traces. Set by the graph around each node's execute(); nested scopes restore the outer.
class LaunchScope {
 public:
  explicit LaunchScope(std::string name) : previous_(std::move(current())) {
    current() = std::move(name);
  }
  ~LaunchScope() { current() = std::move(previous_); }
  LaunchScope(const LaunchScope&) = delete;
  LaunchScope& operator=(const LaunchScope&) = delete;
  static std::string& current() {
    thread_local std::string name;
    return name;
  }

 private:
  std::string previous_;
};

class Executor {
 public:
  // threads == 0: all hardware threads; threads == 1: synchronous, in chunk order, on the
  // calling thread (the debugging mode). threads < 0 throws std::invalid_argument. More
  // threads than cores is allowed and really runs that many (oversubscribed: a way to shake
  // out ordering bugs); results never depend on it.
  // lanes: the lane width W (1, 4, 8 or 16; 0 = the build's native widest, kNativeLanes in
  // lanes.h) at which the primitives not given an explicit W run on this executor
  // (`--lanes W`); any other value throws std::invalid_argument. Results never depend on it
  // either, and executors of different widths may run side by side.
  explicit Executor(int threads = 0, int lanes = 0);

  // Number of chunks parallel_for(n, chunk) uses; chunk 0 is treated as 1.
  static std::size_t chunk_count(std::size_t n, std::size_t chunk) {
    if (chunk == 0) chunk = 1;
    return (n + chunk - 1) / chunk;
  }

  int threads() const { return threads_; }
  bool synchronous() const { return threads_ == 1; }

  // The resolved lane width: 1, 4, 8 or 16, never 0.
  int lanes() const { return lanes_; }
  // Same rules as the constructor's `lanes`. Call it before launching work: kernels read the
  // width when they start, without synchronization.
  void set_lanes(int lanes);

  // Calls body(begin, end) for each chunk [c*chunk, min(n, (c+1)*chunk)).
  template <class Body>
  void parallel_for(std::string_view name, std::size_t n, std::size_t chunk, Body&& body) {
    if (chunk == 0) chunk = 1;
    const std::size_t chunks = chunk_count(n, chunk);
    auto run_chunk = [&](std::size_t c) {
      // Ctrl-C: the remaining chunks are skipped and launch() throws Interrupted.
      if (interrupted()) return;
      const std::size_t begin = c * chunk;
      const std::size_t end = begin + chunk < n ? begin + chunk : n;
      body(begin, end);
      // One relaxed add per chunk (never per element): the progress bar's count.
      work_done_.fetch_add(end - begin, std::memory_order_relaxed);
    };
    launch(name, n, chunks, chunks, run_chunk, false);
  }

  // Calls body(w) for each w in [0, workers) at once, for a kernel whose workers claim the
  // data's chunks themselves in a fixed order (chained_pass.h); the record names the data
  // (`n` elements in `chunks` chunks), not the thread-dependent worker count.
  template <class Body>
  void run_workers(std::string_view name, std::size_t workers, std::size_t n, std::size_t chunks,
                   Body&& body) {
    // The workers claim chunks themselves, so the work counts as done when they all end.
    launch(name, n, chunks, workers, body, true);
  }

  // Deterministic reduction: partial = chunk_fn(begin, end) per fixed chunk (in parallel),
  // then result = combine(...combine(combine(identity, p0), p1)..., pk) serially in chunk
  // order. The result is therefore the same for every thread count even for floats.
  template <class T, class ChunkFn, class Combine>
  T parallel_reduce(std::string_view name, std::size_t n, std::size_t chunk, T identity,
                    ChunkFn&& chunk_fn, Combine&& combine) {
    if (chunk == 0) chunk = 1;
    struct Slot { T value; };  // not std::vector<bool>: chunks write their slots concurrently
    std::vector<Slot> partial(chunk_count(n, chunk), Slot{identity});
    parallel_for(name, n, chunk, [&](std::size_t begin, std::size_t end) {
      partial[begin / chunk].value = chunk_fn(begin, end);
    });
    T result = std::move(identity);
    for (auto& p : partial) result = combine(std::move(result), std::move(p.value));
    return result;
  }

  // Runs f inside this executor's arena (so nested TBB work obeys the thread limit).
  template <class F>
  decltype(auto) run(F&& f) {
    if (synchronous()) return std::forward<F>(f)();
    ForkJoinSync sync;  // the arena may run f on one of its own threads
    sync.fork();
    ForkJoinSync::JoinOnExit join{sync};
    return arena_->execute([&]() -> decltype(auto) {
      sync.enter();
      ForkJoinSync::LeaveOnExit leave{sync};
      return std::forward<F>(f)();
    });
  }

  // Launch records since the last clear; recording is on by default and cheap.
  std::vector<LaunchRecord> launches() const;
  void clear_launches();
  void set_recording(bool on) { recording_ = on; }

  // The work counts so far; safe from any thread while launches run (a progress poller).
  WorkCount work() const;

  std::int64_t now_ns() const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now() - epoch_)
        .count();
  }

 private:
  // Runs task(t) for t in [0, tasks) and records the launch as `n` elements in `chunks`.
  // `done_at_end`: count the n elements done when the launch ends (else the tasks count them).
  // Throws Interrupted, before starting or after the tasks, once Ctrl-C was pressed.
  template <class Task>
  void launch(std::string_view name, std::size_t n, std::size_t chunks, std::size_t tasks, Task& task,
              bool done_at_end) {
    throw_if_interrupted();
    begin_launch(name, n);
    const auto t0 = now_ns();
    if (synchronous() || tasks <= 1) {
      for (std::size_t t = 0; t < tasks; ++t) task(t);
    } else {
      // A task_group fork/join, not tbb::parallel_for: see fork_join.h for why.
      ForkJoinSync sync;  // per launch
      sync.fork();  // after everything the tasks read is written
      ForkJoinSync::JoinOnExit join{sync};
      arena_->execute([&] { fork_join_chunks(sync, tasks, task); });
    }
    record(name, n, chunks, t0, now_ns() - t0);
    if (done_at_end) work_done_.fetch_add(n, std::memory_order_relaxed);
    throw_if_interrupted();
  }

  void begin_launch(std::string_view name, std::size_t n);
  void record(std::string_view name, std::size_t n, std::size_t chunks, std::int64_t start,
              std::int64_t duration);

  int threads_;
  int lanes_;
  // Raises TBB's process-wide worker limit (default: the core count) while an executor asks
  // for more threads than cores, so `--threads 8` on 2 cores really runs 8 threads.
  std::unique_ptr<tbb::global_control> oversubscribe_;
  std::unique_ptr<tbb::task_arena> arena_;
  std::chrono::steady_clock::time_point epoch_;
  bool recording_ = true;
  mutable std::mutex records_mutex_;
  std::vector<LaunchRecord> records_;
  std::atomic<std::uint64_t> work_launched_{0};
  std::atomic<std::uint64_t> work_done_{0};
  std::string last_launch_;  // guarded by records_mutex_
};

}  // namespace speculum::par
