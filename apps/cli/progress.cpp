// The stderr progress bar: see progress.h.
#include "apps/cli/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "parallel/executor.h"

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

namespace {
// 1234 -> "1234", 12345 -> "12.3k", 1.5e6 -> "1.5M".
std::string short_count(double v) {
  char s[32];
  if (v < 1e4) std::snprintf(s, sizeof s, "%.0f", v);
  else if (v < 1e6) std::snprintf(s, sizeof s, "%.1fk", v / 1e3);
  else if (v < 1e9) std::snprintf(s, sizeof s, "%.1fM", v / 1e6);
  else std::snprintf(s, sizeof s, "%.1fG", v / 1e9);
  return s;
}
}  // namespace

std::string Progress::line_locked(double seconds) const {
  // The share of the launched work done counts as that part of the current step.
  const std::uint64_t in_flight = work_launched_ - work_base_;
  const double inner = in_flight == 0 || done_ >= total_
                           ? 0.0
                           : static_cast<double>(work_done_ - work_base_) / static_cast<double>(in_flight);
  const double fraction =
      total_ == 0 ? 1.0
                  : std::min(1.0, (static_cast<double>(done_) + inner) / static_cast<double>(total_));
  const int filled = static_cast<int>(fraction * kBarWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kBarWidth, '.');
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, "] %zu/%zu %5.1fs ", done_, total_, seconds);
  std::string detail = detail_.substr(0, 40);
  if (in_flight > 0 && work_done_ < work_launched_) {
    // "reference_render 42% 12.3k/s ETA 9s": the running launches, their rate, the time left.
    char work[96];
    const double rate = rate_t1_ > rate_t0_ ? static_cast<double>(rate_d1_ - rate_d0_) / (rate_t1_ - rate_t0_) : 0;
    const double left = static_cast<double>(work_launched_ - work_done_);
    if (rate > 0)
      std::snprintf(work, sizeof work, " %.0f%% %s/s ETA %.0fs", 100.0 * inner, short_count(rate).c_str(),
                    std::ceil(left / rate));
    else
      std::snprintf(work, sizeof work, " %.0f%%", 100.0 * inner);
    detail = launch_.substr(0, 40 - std::min<std::size_t>(40, std::strlen(work))) + work;
  }
  // Trailing spaces overwrite what a longer previous detail left on the line.
  return label_ + " [" + bar + numbers + detail + std::string(detail.size() < 40 ? 40 - detail.size() : 0, ' ');
}

void Progress::step(std::string_view detail) {
  std::lock_guard lock(mutex_);
  ++done_;
  if (!detail.empty()) detail_ = std::string(detail);
  draw_locked();
}

void Progress::work(std::string_view launch, std::uint64_t done, std::uint64_t launched) {
  std::lock_guard lock(mutex_);
  if (done < work_done_ || launched < work_launched_ || done > launched) return;  // not ours
  const double t = elapsed();
  // Idle (everything launched is done): the next launches start a new share.
  if (done == launched) work_base_ = done;
  launch_ = std::string(launch);
  work_done_ = done;
  work_launched_ = launched;
  // The rate over the last 2-4 seconds: the newer sample moves every 2 seconds.
  if (t - rate_t1_ >= 2.0) {
    rate_t0_ = rate_t1_, rate_d0_ = rate_d1_;
    rate_t1_ = t, rate_d1_ = done;
  }
  draw_locked();
}

void Progress::draw_locked() {
  if (!sink_ || finished_) return;
  const double t = elapsed();
  if (t < delay_ || t - last_draw_ < kRedrawSeconds) return;
  last_draw_ = t;
  drawn_ = true;
  std::string line = "\r";  // appended, not "\r" + ...: GCC 12's -Wrestrict misfires on that
  line += line_locked(t);
  sink_(line);
}

void Progress::finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (!sink_ || !drawn_) return;
  std::string line = "\r";
  line += line_locked(elapsed());
  line += '\n';
  sink_(line);
}

void Progress::clear() {
  std::lock_guard lock(mutex_);
  if (!sink_ || !drawn_ || finished_) return;
  sink_("\r\033[K");
  last_draw_ = -1.0;  // the next step redraws at once
}

WorkPoller::WorkPoller(const par::Executor& executor, Progress& progress)
    : thread_([this, &executor, &progress] {
        std::unique_lock lock(mutex_);
        while (!wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stop_; })) {
          const par::WorkCount w = executor.work();
          progress.work(w.launch, w.done, w.launched);
        }
      }) {}

WorkPoller::~WorkPoller() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

}  // namespace speculum::cli
