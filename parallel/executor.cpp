#include "parallel/executor.h"

#include <thread>

namespace speculum::par {

Executor::Executor(int threads)
    : threads_(threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency())),
      epoch_(std::chrono::steady_clock::now()) {
  if (threads_ > 1) arena_ = std::make_unique<tbb::task_arena>(threads_);
}

std::vector<LaunchRecord> Executor::launches() const {
  std::lock_guard lock(records_mutex_);
  return records_;
}

void Executor::clear_launches() {
  std::lock_guard lock(records_mutex_);
  records_.clear();
}

void Executor::record(std::string_view name, std::size_t n, std::size_t chunks,
                      std::int64_t start, std::int64_t duration) {
  if (!recording_) return;
  std::lock_guard lock(records_mutex_);
  records_.push_back({std::string(name), n, chunks, start, duration});
}

}  // namespace speculum::par
