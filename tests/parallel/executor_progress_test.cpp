// The executor's work counts (what the progress bar polls inside a long launch) and Ctrl-C:
// the counts only grow, stay consistent (done <= launched) while chunks finish on any thread,
// advance chunk by chunk inside one launch and reach the launch's element count when it ends;
// an interrupt skips the remaining chunks and the launch throws Interrupted.
#include "parallel/executor.h"

#include <gtest/gtest.h>

#include <atomic>
#include <span>
#include <thread>
#include <vector>

#include "parallel/interrupt.h"
#include "parallel/scan.h"

namespace speculum::par {
namespace {

// Clears the process-wide interrupt flag when a test ends, whatever happens.
struct ClearInterrupt {
  ~ClearInterrupt() { interrupt_requested.store(false); }
};

TEST(ExecutorProgress, CountsAdvanceChunkByChunkInsideALaunch) {
  Executor ex(1);  // synchronous: chunk c runs after exactly c chunks are done
  const std::size_t n = 10'000, chunk = 64;
  std::vector<WorkCount> seen;
  ex.parallel_for("progress", n, chunk, [&](std::size_t, std::size_t) { seen.push_back(ex.work()); });
  ASSERT_EQ(seen.size(), Executor::chunk_count(n, chunk));
  for (std::size_t c = 0; c < seen.size(); ++c) {
    EXPECT_EQ(seen[c].launched, n);
    EXPECT_EQ(seen[c].done, c * chunk);  // inside the launch, not only between launches
    EXPECT_EQ(seen[c].launch, "progress");
  }
  const WorkCount end = ex.work();
  EXPECT_EQ(end.launched, n);
  EXPECT_EQ(end.done, n);
}

TEST(ExecutorProgress, CountsAreMonotonicAndReachTheTotalOnAnyThreadCount) {
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    std::atomic<bool> stop{false};
    std::atomic<int> violations{0};
    std::atomic<std::uint64_t> polls{0};
    // A poller, as the progress bar's: every read must be >= the previous and consistent.
    std::thread poller([&] {
      WorkCount last;
      do {
        const WorkCount w = ex.work();
        if (w.done < last.done || w.launched < last.launched || w.done > w.launched) ++violations;
        last = w;
        ++polls;
      } while (!stop.load());
    });
    std::uint64_t expected = 0;
    for (std::size_t n : {0u, 1u, 1000u, 123'457u}) {
      std::vector<std::uint32_t> out(n);
      ex.parallel_for("fill", n, 256, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) out[i] = static_cast<std::uint32_t>(i * 2654435761u >> 7);
      });
      expected += n;
      EXPECT_EQ(ex.work().done, expected) << threads;
      EXPECT_EQ(ex.work().launched, expected) << threads;
      // A chained scan launches its workers through run_workers: counted when they end.
      std::vector<std::uint32_t> sums(n);
      const WorkCount before = ex.work();
      exclusive_scan(ex, "scan", std::span<const std::uint32_t>(out), std::span<std::uint32_t>(sums));
      const WorkCount after = ex.work();
      EXPECT_GE(after.done, before.done) << threads;
      EXPECT_EQ(after.done, after.launched) << threads;  // every launch finished and counted
      expected = after.done;
    }
    stop.store(true);
    poller.join();
    EXPECT_EQ(violations.load(), 0) << threads;
    EXPECT_GT(polls.load(), 0u);
  }
}

TEST(ExecutorProgress, AnInterruptSkipsTheRemainingChunksAndThrows) {
  ClearInterrupt clear;
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    interrupt_requested.store(false);
    // Requested before the launch: no chunk runs.
    request_interrupt();
    std::atomic<int> ran{0};
    EXPECT_THROW(ex.parallel_for("none", 1000, 10, [&](std::size_t, std::size_t) { ++ran; }), Interrupted);
    EXPECT_EQ(ran.load(), 0);
    interrupt_requested.store(false);
    // Requested by chunk 5 (as a SIGINT arriving meanwhile): the launch still throws, and on
    // one thread no later chunk runs.
    std::atomic<int> after{0};
    EXPECT_THROW(ex.parallel_for("some", 1000, 10,
                                 [&](std::size_t b, std::size_t) {
                                   if (b / 10 == 5) request_interrupt();
                                   if (b / 10 > 5) ++after;
                                 }),
                 Interrupted);
    if (threads == 1) {
      EXPECT_EQ(after.load(), 0);
    }
    interrupt_requested.store(false);
    // Cleared: the executor works as before.
    std::atomic<int> all{0};
    ex.parallel_for("all", 1000, 10, [&](std::size_t, std::size_t) { ++all; });
    EXPECT_EQ(all.load(), 100);
  }
}

}  // namespace
}  // namespace speculum::par
