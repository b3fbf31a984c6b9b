// Fork/join on oneTBB with the happens-before edges ThreadSanitizer cannot see (executor.h,
// graph.cpp). The annotations compile to nothing unless built with -fsanitize=thread;
// ForkJoinTask is then a plain forwarder. tests/tsan.supp names this file.
#pragma once

#include <cstddef>
#include <type_traits>

#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#if defined(__SANITIZE_THREAD__)
// ThreadSanitizer's annotation entry points (libtsan). Debian's libtbb.so is not
// instrumented, so TSan cannot see the happens-before edges of TBB's fork/join; we state
// them ourselves at every launch (see ForkJoinSync).
extern "C" void __tsan_acquire(void* addr);
extern "C" void __tsan_release(void* addr);
#endif

namespace speculum::par {

// The happens-before edges of one fork/join, stated to ThreadSanitizer (no code otherwise).
// fork(): the launching thread publishes its writes; enter(): a task starts after them;
// leave(): a task's writes are published to the join; join(): the launcher, after TBB's
// wait returns, sees every task's writes. Two separate sync addresses, so tasks of one
// launch get no edge between each other (a race between two chunks is still reported).
//
// What leave()/join() cannot cover: after a task's body returns, TBB's task epilogue (header
// code, instrumented) still decrements the join counter, which lives in the launcher's
// frame. tbb::task_group reads that counter with an acquire load in its destructor (header
// code too), which gives TSan the real edge, so the launcher may reuse its stack afterwards.
// tbb::parallel_for keeps its counter in a stack node that only libtbb reads: a launcher
// reusing that stack was reported as racing with the last worker's decrement. So every
// launch here is a tbb::task_group (fork_join_chunks), never tbb::parallel_for.
class ForkJoinSync {
 public:
  // Scope guards: leave()/join() also on the exceptional path.
  struct LeaveOnExit {
    ForkJoinSync& sync;
    ~LeaveOnExit() { sync.leave(); }
  };
  struct JoinOnExit {
    ForkJoinSync& sync;
    ~JoinOnExit() { sync.join(); }
  };
#if defined(__SANITIZE_THREAD__)
  void fork() { __tsan_release(&fork_); }
  void enter() { __tsan_acquire(&fork_); }
  void leave() { __tsan_release(&join_); }
  void join() { __tsan_acquire(&join_); }

 private:
  char fork_ = 0;
  char join_ = 0;
#else
  void fork() {}
  void enter() {}
  void leave() {}
  void join() {}
#endif
};

// The callable handed to TBB for one task: pointers to the launch's sync and to the real
// body (which stays on the launcher's stack), and a range [begin, end) passed to bodies
// that take two indices (chunk ranges) or its begin to bodies that take one (the graph's
// node number). TBB copies it on one thread and runs the copy on another, an edge TSan
// cannot see; so the fields are copied and read with relaxed atomics (plain moves in
// machine code), the only accesses before enter() makes the launcher's writes visible.
template <class F>
class ForkJoinTask {
 public:
  ForkJoinTask(ForkJoinSync& sync, F& f, std::size_t begin = 0, std::size_t end = 0)
      : sync_(&sync), f_(&f), begin_(begin), end_(end) {}
  ForkJoinTask(const ForkJoinTask& other) {
    __atomic_store_n(&sync_, __atomic_load_n(&other.sync_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
    __atomic_store_n(&f_, __atomic_load_n(&other.f_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
    __atomic_store_n(&begin_, __atomic_load_n(&other.begin_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
    __atomic_store_n(&end_, __atomic_load_n(&other.end_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
  }
  ForkJoinTask& operator=(const ForkJoinTask&) = delete;
  void operator()() const {
    ForkJoinSync* sync = __atomic_load_n(&sync_, __ATOMIC_RELAXED);
    sync->enter();
    ForkJoinSync::LeaveOnExit leave{*sync};
    F& f = *__atomic_load_n(&f_, __ATOMIC_RELAXED);
    const std::size_t begin = __atomic_load_n(&begin_, __ATOMIC_RELAXED);
    if constexpr (std::is_invocable_v<F&, std::size_t, std::size_t>)
      f(begin, __atomic_load_n(&end_, __ATOMIC_RELAXED));
    else
      f(begin);
  }

 private:
  ForkJoinSync* sync_;
  F* f_;
  std::size_t begin_;
  std::size_t end_;
};

// Runs chunk_body(c) for every c in [0, chunks) on the current task arena and returns when
// all have finished. The caller also fork()s `sync` before and join()s it after, on its own
// thread (the arena's execute may hand this call to a worker). The range is halved
// recursively and the upper halves are spawned, like tbb::simple_partitioner with grain 1,
// so idle threads steal large pieces first. Spawning tasks do not fork(): a worker
// publishing its own writes to later tasks would hide races between chunks. Which thread
// runs which chunk never matters to the results (chunk boundaries are fixed by the caller).
template <class ChunkBody>
void fork_join_chunks(ForkJoinSync& sync, std::size_t chunks, ChunkBody& chunk_body) {
  if (chunks == 0) return;
  tbb::task_group group;
  struct Splitter {
    tbb::task_group& group;
    ForkJoinSync& sync;
    ChunkBody& chunk_body;
    void operator()(std::size_t begin, std::size_t end) {
      while (end - begin > 1) {
        const std::size_t mid = begin + (end - begin) / 2;
        group.run(ForkJoinTask<Splitter>(sync, *this, mid, end));
        end = mid;
      }
      chunk_body(begin);
    }
  } split{group, sync, chunk_body};
  // Publishes the group's construction (its wait counter, which every task's epilogue
  // decrements) and anything else this thread wrote; fork() may be called more than once.
  sync.fork();
  // The root runs on this thread (run_and_wait does not copy or spawn it); rethrows the
  // first exception of any chunk once all spawned tasks have finished.
  // Isolated: while this thread waits for stolen chunks it runs only this launch's tasks.
  // Otherwise it could pick up another graph node (a whole pass) in the wait, and this
  // launch, and the node that issued it, would end only when that pass does: their
  // recorded wall times would include its work.
  tbb::this_task_arena::isolate([&] { group.run_and_wait(ForkJoinTask<Splitter>(sync, split, 0, chunks)); });
}  // ~task_group acquires TBB's join counter: the edge leave()/join() cannot state (above)

}  // namespace speculum::par
