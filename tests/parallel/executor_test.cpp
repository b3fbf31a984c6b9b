// Executor: fixed chunking, chunk-order reduction, named launch records, thread settings.
#include "parallel/executor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "parallel/compact.h"
#include "parallel/scan.h"

namespace speculum::par {
namespace {

TEST(Executor, ChunksCoverRangeExactlyOnce) {
  for (int threads : {1, 2, 8}) {
    Executor ex(threads);
    for (std::size_t n : {0u, 1u, 999u, 1000u, 1001u, 12345u}) {
      std::vector<int> hits(n, 0);
      ex.parallel_for("cover", n, 1000, [&](std::size_t b, std::size_t e) {
        ASSERT_EQ(b % 1000, 0u);
        ASSERT_LE(e - b, 1000u);
        for (std::size_t i = b; i < e; ++i) ++hits[i];
      });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i], 1) << i;
    }
  }
}

TEST(Executor, ReduceIsChunkOrderedAndThreadIndependent) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> d(-1e6f, 1e6f);
  std::vector<float> x(100003);
  for (auto& v : x) v = d(rng);
  auto sum_with = [&](int threads) {
    Executor ex(threads);
    return ex.parallel_reduce(
        "sum", x.size(), 4096, 0.f,
        [&](std::size_t b, std::size_t e) {
          float s = 0.f;
          for (std::size_t i = b; i < e; ++i) s += x[i];
          return s;
        },
        [](float a, float b) { return a + b; });
  };
  // Serial oracle with the same association: chunk sums folded in chunk order.
  float oracle = 0.f;
  for (std::size_t b = 0; b < x.size(); b += 4096) {
    float s = 0.f;
    for (std::size_t i = b; i < std::min(x.size(), b + 4096); ++i) s += x[i];
    oracle += s;
  }
  for (int t : {1, 2, 8}) EXPECT_EQ(std::bit_cast<std::uint32_t>(sum_with(t)), std::bit_cast<std::uint32_t>(oracle)) << t;
  Executor ex(2);
  EXPECT_EQ(ex.parallel_reduce("empty", 0, 16, 5, [](auto, auto) { return 1; }, std::plus<>()), 5);
}

TEST(Executor, RecordsNamedLaunchesWithScope) {
  Executor ex(2);
  ex.clear_launches();
  ex.parallel_for("alpha", 10, 3, [](auto, auto) {});
  {
    LaunchScope scope("node-x");
    ex.parallel_for("beta", 100, 7, [](auto, auto) {});
  }
  const auto l = ex.launches();
  ASSERT_EQ(l.size(), 2u);
  EXPECT_EQ(l[0].name, "alpha");
  EXPECT_EQ(l[0].chunks, 4u);
  EXPECT_EQ(l[0].elements, 10u);
  EXPECT_EQ(l[0].scope, "");
  EXPECT_EQ(l[1].name, "beta");
  EXPECT_EQ(l[1].chunks, 15u);
  EXPECT_EQ(l[1].scope, "node-x");
  EXPECT_GE(l[1].start_ns, l[0].start_ns);
  EXPECT_EQ(LaunchScope::current(), "");
}

TEST(Executor, ThreadSettings) {
  EXPECT_GE(Executor(0).threads(), 1);
  EXPECT_TRUE(Executor(1).synchronous());
  EXPECT_EQ(Executor(3).threads(), 3);
  EXPECT_THROW(Executor(-1), std::invalid_argument);
  // Synchronous mode runs chunks in order on the calling thread.
  Executor ex(1);
  std::vector<std::size_t> seen;
  ex.parallel_for("order", 50, 8, [&](std::size_t b, std::size_t) { seen.push_back(b); });
  EXPECT_EQ(seen, (std::vector<std::size_t>{0, 8, 16, 24, 32, 40, 48}));
  EXPECT_EQ(ex.run([] { return 42; }), 42);
  EXPECT_EQ(Executor(2).run([] { return 7; }), 7);
}

// More threads than cores really run: eight chunks that each wait (bounded) until all eight
// have started can only all see eight if eight threads run at once. TBB caps its workers at
// the core count unless the executor lifts the cap (executor.h).
TEST(Executor, OversubscribedExecutorRunsThatManyThreads) {
  constexpr int kThreads = 8;
  Executor ex(kThreads);
  std::atomic<int> started{0};
  std::vector<int> saw(kThreads, 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  ex.parallel_for("rendezvous", kThreads, 1, [&](std::size_t b, std::size_t) {
    started.fetch_add(1);
    while (started.load() < kThreads && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    saw[b] = started.load();
  });
  EXPECT_EQ(saw, std::vector<int>(kThreads, kThreads));
}

// The chained scan and scatter compaction run one task per worker, but their launch records
// (what `profile` and the trace show) name the data: n elements in its fixed chunks, the same
// for every thread count.
TEST(Executor, ChainedPassRecordsItsDataNotItsWorkers) {
  const std::size_t n = 3 * kScanChunk + 5;
  std::vector<std::uint32_t> in(n, 1u), out(n);
  std::vector<std::uint8_t> keep(n, 1);
  for (int threads : {1, 2, 8}) {
    SCOPED_TRACE(threads);
    Executor ex(threads);
    exclusive_scan(ex, "scan", std::span<const std::uint32_t>(in), std::span(out));
    compact_scatter(ex, "compact", std::span<const std::uint8_t>(keep), std::span(out));
    const auto launches = ex.launches();
    ASSERT_EQ(launches.size(), 2u);
    EXPECT_EQ(launches[0].name, "scan/chained_scan");
    EXPECT_EQ(launches[0].elements, n);
    EXPECT_EQ(launches[0].chunks, Executor::chunk_count(n, kScanChunk));
    EXPECT_EQ(launches[1].name, "compact/chained_scatter");
    EXPECT_EQ(launches[1].elements, n);
    EXPECT_EQ(launches[1].chunks, Executor::chunk_count(n, kCompactChunk));
  }
}

// Writes 64 KiB of this thread's stack below the caller's frame with plain stores, as any
// later call does: it covers the frames a finished launch used.
[[gnu::noinline]] void overwrite_stack_below() {
  unsigned char block[64 * 1024];
  std::fill(std::begin(block), std::end(block), 0x5a);
  asm volatile("" : : "r"(block) : "memory");  // keep the stores
}

// Regression for ThreadSanitizer (the test itself cannot fail without it): a worker that
// finishes a launch's last chunk writes TBB's join counter, which lived on the launcher's
// stack (tbb::parallel_for's wait node); the launcher's wait is in uninstrumented libtbb,
// so reusing that stack afterwards was reported as a race. Chunk 0 (run by the launcher)
// waits until chunk 1 runs elsewhere; chunk 1 then finishes last. If no worker shows up
// within a second (a loaded machine), the round simply does not exercise the case.
TEST(Executor, LauncherStackIsReusableAfterAWorkerFinishesLast) {
  Executor ex(2);
  for (int round = 0; round < 8; ++round) {
    std::atomic<bool> second_started{false};
    std::vector<int> hits(2, 0);
    ex.parallel_for("worker-finishes-last", 2, 1, [&](std::size_t b, std::size_t) {
      if (b == 1) {
        second_started.store(true);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      } else {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
        while (!second_started.load() && std::chrono::steady_clock::now() < deadline)
          std::this_thread::yield();
      }
      hits[b] = 1;
    });
    overwrite_stack_below();
    EXPECT_EQ(hits, (std::vector<int>{1, 1})) << round;
  }
}

}  // namespace
}  // namespace speculum::par
