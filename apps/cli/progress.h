// A progress bar on stderr for renders and experiments that take longer than a second:
// silent when stderr is not a terminal or with --quiet; thread-safe.
//   Progress p("yu-fig9", rows, global.quiet);
//   for (...) { ...; p.step(); }       // or p.step("row 3") to show what just finished
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <string>
#include <string_view>

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
};

}  // namespace speculum::cli
