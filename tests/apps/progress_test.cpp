// The progress bar (apps/cli/progress.h): silent before its delay, every step counted when many
// threads step at once, one final newline, and the drawn count never goes backwards.
#include <algorithm>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "apps/cli/progress.h"

namespace speculum::cli {
namespace {

struct Captured {
  std::mutex mutex;
  std::vector<std::string> writes;
  Progress::Sink sink() {
    return [this](std::string_view s) {
      std::lock_guard lock(mutex);
      writes.emplace_back(s);
    };
  }
};

// The "done" number of a drawn line "label [###...] done/total ...".
std::size_t drawn_done(const std::string& line) {
  const auto close = line.find("] ");
  return std::stoul(line.substr(close + 2));
}

TEST(Progress, SilentBeforeTheDelay) {
  Captured out;
  {
    Progress p("quick", 10, out.sink(), 3600.0);
    for (int i = 0; i < 10; ++i) p.step("x");
    EXPECT_EQ(p.done(), 10u);
  }
  EXPECT_TRUE(out.writes.empty());
}

TEST(Progress, ClearErasesTheDrawnBarAndTheNextStepRedrawsIt) {
  Captured out;
  Progress p("rows", 3, out.sink(), 0.0);
  p.clear();  // nothing drawn yet: nothing to erase
  EXPECT_TRUE(out.writes.empty());
  p.step();
  ASSERT_EQ(out.writes.size(), 1u);
  p.clear();
  ASSERT_EQ(out.writes.size(), 2u);
  EXPECT_EQ(out.writes.back(), "\r\033[K");
  p.step();  // redraws at once after a clear
  ASSERT_EQ(out.writes.size(), 3u);
  EXPECT_EQ(drawn_done(out.writes.back().substr(1)), 2u);
  p.step();
  p.finish();
  EXPECT_EQ(drawn_done(out.writes.back().substr(1)), 3u);
  p.clear();  // finished: the final line stays
  EXPECT_EQ(out.writes.back().back(), '\n');
}

TEST(Progress, ConcurrentStepsAreAllCountedAndDrawnMonotonically) {
  Captured out;
  constexpr int kThreads = 4, kSteps = 2500;
  {
    Progress p("many", kThreads * kSteps, out.sink(), 0.0);
    std::vector<std::thread> threads;
    for (int t = 0; t < kThreads; ++t)
      threads.emplace_back([&p, t] {
        for (int i = 0; i < kSteps; ++i) p.step("thread " + std::to_string(t));
      });
    for (auto& th : threads) th.join();
    EXPECT_EQ(p.done(), std::size_t(kThreads * kSteps));
    EXPECT_NE(p.line().find("10000/10000"), std::string::npos) << p.line();
  }
  ASSERT_FALSE(out.writes.empty());
  std::size_t previous = 0, newlines = 0;
  for (const auto& w : out.writes) {
    ASSERT_EQ(w.front(), '\r');
    const std::size_t done = drawn_done(w);
    EXPECT_GE(done, previous);
    previous = done;
    newlines += std::count(w.begin(), w.end(), '\n');
  }
  EXPECT_EQ(newlines, 1u);  // finish() from the destructor, once
  EXPECT_EQ(out.writes.back().back(), '\n');
  EXPECT_NE(out.writes.back().find("10000/10000"), std::string::npos);
}

TEST(Progress, QuietOrNotATerminalDrawsNothingButStillCounts) {
  Progress p("quiet", 3, /*quiet=*/true);
  p.step();
  p.step("b");
  EXPECT_EQ(p.done(), 2u);
  EXPECT_NE(p.line().find("2/3"), std::string::npos);
  EXPECT_NE(p.line().find(" b"), std::string::npos);
}

}  // namespace
}  // namespace speculum::cli
