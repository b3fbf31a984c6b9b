// Fork/join happens-before edges for ThreadSanitizer around TBB launches (executor.h,
// graph.cpp). The annotations compile to nothing unless built with -fsanitize=thread;
// ForkJoinTask is then a two-pointer forwarder. tests/tsan.supp names this file.
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

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

// The callable handed to TBB for one launch: pointers to the launch's sync and to the real
// body (which stays on the launcher's stack), and an index passed to bodies that take one
// first (the graph's node number). TBB copies it on one thread and runs the copy
// on another, an edge TSan cannot see; so the pointers are copied and read with relaxed
// atomics (plain moves in machine code), the only accesses before enter() makes the
// launcher's writes visible.
template <class F>
class ForkJoinTask {
 public:
  ForkJoinTask(ForkJoinSync& sync, F& f, std::size_t index = 0)
      : sync_(&sync), f_(&f), index_(index) {}
  ForkJoinTask(const ForkJoinTask& other) {
    __atomic_store_n(&sync_, __atomic_load_n(&other.sync_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
    __atomic_store_n(&f_, __atomic_load_n(&other.f_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
    __atomic_store_n(&index_, __atomic_load_n(&other.index_, __ATOMIC_RELAXED), __ATOMIC_RELAXED);
  }
  ForkJoinTask& operator=(const ForkJoinTask&) = delete;
  template <class... Args>
  void operator()(Args&&... args) const {
    ForkJoinSync* sync = __atomic_load_n(&sync_, __ATOMIC_RELAXED);
    sync->enter();
    ForkJoinSync::LeaveOnExit leave{*sync};
    F& f = *__atomic_load_n(&f_, __ATOMIC_RELAXED);
    if constexpr (std::is_invocable_v<F&, std::size_t, Args...>)
      f(__atomic_load_n(&index_, __ATOMIC_RELAXED), std::forward<Args>(args)...);
    else
      f(std::forward<Args>(args)...);
  }

 private:
  ForkJoinSync* sync_;
  F* f_;
  std::size_t index_;
};

}  // namespace speculum::par
