// A progress bar on stderr for renders and experiments that take longer than a second:
// silent when stderr is not a terminal or with --quiet; thread-safe.
//   Progress p("yu-fig9", rows, global.quiet);
//   for (...) { ...; p.step(); }       // or p.step("row 3") to show what just finished
// Inside a long step, a poller reports the work of the running launches (Executor::work()):
//   p.work("reference_render", done, launched);   // the bar moves, with a rate and an ETA
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>

namespace speculum::par {
class Executor;
}

namespace speculum::cli {

class Progress {
 public:
  // Receives each redraw (a line starting with '\r', no newline) and the final newline.
  using Sink = std::function<void(std::string_view)>;

  // Draws on stderr only when it is a terminal and `quiet` is false.
  Progress(std::string label, std::size_t total, bool quiet = false);
  // Draws into `sink` (tests; or a caller that owns the terminal). Nothing is drawn before
  // `delay_seconds` have passed, so quick runs stay silent.
  Progress(std::string label, std::size_t total, Sink sink, double delay_seconds = 1.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // One unit done; `detail` (optional) names it on the bar. Safe from any thread.
  void step(std::string_view detail = {});
  // The element counts of the launches under way (both only grow; done <= launched) and the
  // name of the latest: the bar adds the share of the launched work that is done, and the line
  // shows it with the rate over the last seconds and the time left at that rate. Any thread.
  void work(std::string_view launch, std::uint64_t done, std::uint64_t launched);
  // Ends the bar: a last redraw and a newline, only if anything was drawn.
  void finish();
  // Erases the drawn bar from its line (the next step redraws it), so a caller can print a
  // line of its own — e.g. an experiment's table row — on the same terminal.
  void clear();

  std::size_t done() const;
  std::size_t total() const { return total_; }
  // The bar as it would be drawn now (without the leading '\r').
  std::string line() const;

 private:
  std::string line_locked(double elapsed) const;
  void draw_locked();
  double elapsed() const;

  std::string label_;
  std::size_t total_;
  Sink sink_;  // empty: disabled
  double delay_;
  std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;
  std::size_t done_ = 0;
  std::string detail_;
  double last_draw_ = -1.0;
  bool drawn_ = false;
  bool finished_ = false;
  // Work inside the running steps (work()): counts since the poller last saw it idle, and two
  // samples (time, done) a few seconds apart for the rate.
  std::string launch_;
  std::uint64_t work_base_ = 0, work_done_ = 0, work_launched_ = 0;
  double rate_t0_ = 0, rate_t1_ = 0;
  std::uint64_t rate_d0_ = 0, rate_d1_ = 0;
};

// While it lives, a thread reports `executor`'s work counts to `progress` ten times a second,
// so the bar moves inside a long pass. The executor counts per chunk, so this costs the
// render nothing per element and changes no output.
class WorkPoller {
 public:
  WorkPoller(const par::Executor& executor, Progress& progress);
  ~WorkPoller();
  WorkPoller(const WorkPoller&) = delete;
  WorkPoller& operator=(const WorkPoller&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace speculum::cli
