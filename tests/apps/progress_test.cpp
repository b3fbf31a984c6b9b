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

// Work reported inside a step (the executor's counts, polled): the bar fills by the share of
// the launched work done, the line names the launch and its percentage, counts that go
// backwards are ignored, and an idle count (all done) starts the next share afresh.
TEST(Progress, WorkInsideAStepMovesTheBar) {
  Captured out;
  Progress p("render", 2, out.sink(), 0.0);
  const auto filled = [&] {
    const std::string l = p.line();
    return std::count(l.begin(), l.begin() + static_cast<std::ptrdiff_t>(l.find(']')), '#');
  };
  p.work("reference_render", 0, 1000);
  EXPECT_NE(p.line().find("reference_render 0%"), std::string::npos) << p.line();
  EXPECT_EQ(filled(), 0);
  p.work("reference_render", 500, 1000);
  EXPECT_NE(p.line().find("reference_render 50%"), std::string::npos) << p.line();
  EXPECT_EQ(filled(), 7);  // (0 steps + half of one) of 2, on a 28-wide bar
  p.work("reference_render", 400, 1000);  // older than what was seen: ignored
  EXPECT_NE(p.line().find("50%"), std::string::npos) << p.line();
  p.work("reference_render", 1000, 1000);  // idle: no launch under way
  EXPECT_EQ(p.line().find('%'), std::string::npos) << p.line();
  p.step("reference_trace");
  p.work("tonemap", 1000, 3000);  // a new launch of 2000 elements: none done yet
  EXPECT_NE(p.line().find("tonemap 0%"), std::string::npos) << p.line();
  p.work("tonemap", 2000, 3000);
  EXPECT_NE(p.line().find("tonemap 50%"), std::string::npos) << p.line();
  EXPECT_EQ(filled(), 21);  // (1 + 0.5) of 2
  EXPECT_FALSE(out.writes.empty());
}

}  // namespace
}  // namespace speculum::cli
