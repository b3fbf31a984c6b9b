#include "parallel/executor.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "parallel/lanes.h"

namespace speculum::par {

namespace {
int resolve_threads(int threads) {
  if (threads < 0)
    throw std::invalid_argument("thread count must be >= 0 (0: all cores), got " +
                                std::to_string(threads));
  if (threads > 0) return threads;
  // The arena's default concurrency respects the process affinity mask and cgroup limits,
  // which hardware_concurrency() does not.
  return std::max(1, tbb::this_task_arena::max_concurrency());
}
}  // namespace

Executor::Executor(int threads, int lanes)
    : threads_(resolve_threads(threads)),
      lanes_(resolve_lane_width(lanes)),
      epoch_(std::chrono::steady_clock::now()) {
  if (threads_ > tbb::info::default_concurrency())
    oversubscribe_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                           std::size_t(threads_));
  if (threads_ > 1) arena_ = std::make_unique<tbb::task_arena>(threads_);
}

void Executor::set_lanes(int lanes) { lanes_ = resolve_lane_width(lanes); }

std::vector<LaunchRecord> Executor::launches() const {
  std::lock_guard lock(records_mutex_);
  return records_;
}

void Executor::clear_launches() {
  std::lock_guard lock(records_mutex_);
  records_.clear();
}

void Executor::begin_launch(std::string_view name, std::size_t n) {
  std::lock_guard lock(records_mutex_);  // once per launch, not per chunk
  work_launched_.fetch_add(n, std::memory_order_relaxed);
  last_launch_.assign(name);
}

WorkCount Executor::work() const {
  std::lock_guard lock(records_mutex_);
  WorkCount w;
  // done first: a launch that begins in between only raises `launched`, so done <= launched.
  w.done = work_done_.load(std::memory_order_relaxed);
  w.launched = work_launched_.load(std::memory_order_relaxed);
  w.launch = last_launch_;
  return w;
}

void Executor::record(std::string_view name, std::size_t n, std::size_t chunks,
                      std::int64_t start, std::int64_t duration) {
  if (!recording_) return;
  std::lock_guard lock(records_mutex_);
  records_.push_back({std::string(name), n, chunks, start, duration, LaunchScope::current()});
}

}  // namespace speculum::par
