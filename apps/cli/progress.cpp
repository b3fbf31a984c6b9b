// The stderr progress bar: see progress.h.
#include "apps/cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace speculum::cli {

namespace {
constexpr double kRedrawSeconds = 0.1;  // at most ten redraws a second
constexpr int kBarWidth = 28;
}  // namespace

Progress::Progress(std::string label, std::size_t total, bool quiet)
    : Progress(std::move(label), total,
               quiet || !::isatty(STDERR_FILENO)
                   ? Sink{}
                   : Sink{[](std::string_view s) {
                       std::fwrite(s.data(), 1, s.size(), stderr);
                       std::fflush(stderr);
                     }}) {}

Progress::Progress(std::string label, std::size_t total, Sink sink, double delay_seconds)
    : label_(std::move(label)),
      total_(total),
      sink_(std::move(sink)),
      delay_(delay_seconds),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::size_t Progress::done() const {
  std::lock_guard lock(mutex_);
  return done_;
}

std::string Progress::line() const {
  std::lock_guard lock(mutex_);
  return line_locked(elapsed());
}

std::string Progress::line_locked(double seconds) const {
  const double fraction =
      total_ == 0 ? 1.0 : std::min(1.0, static_cast<double>(done_) / static_cast<double>(total_));
  const int filled = static_cast<int>(fraction * kBarWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kBarWidth, '.');
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, "] %zu/%zu %5.1fs ", done_, total_, seconds);
  std::string detail = detail_.substr(0, 40);
  // Trailing spaces overwrite what a longer previous detail left on the line.
  return label_ + " [" + bar + numbers + detail + std::string(40 - detail.size(), ' ');
}

void Progress::step(std::string_view detail) {
  std::lock_guard lock(mutex_);
  ++done_;
  if (!detail.empty()) detail_ = std::string(detail);
  if (!sink_ || finished_) return;
  const double t = elapsed();
  if (t < delay_ || t - last_draw_ < kRedrawSeconds) return;
  last_draw_ = t;
  drawn_ = true;
  sink_("\r" + line_locked(t));
}

void Progress::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!sink_ || !drawn_) return;
  sink_("\r" + line_locked(elapsed()) + "\n");
}

void Progress::clear() {
  std::lock_guard lock(mutex_);
  if (!sink_ || !drawn_ || finished_) return;
  sink_("\r\033[K");
  last_draw_ = -1.0;  // the next step redraws at once
}

}  // namespace speculum::cli
