// Stopping a run early (Ctrl-C). A SIGINT handler may only store to a lock-free atomic, so
// the request is one process-wide flag; the executor reads it before every chunk and after
// every launch, so a run stops at the next chunk boundary and no pass returns a half-made
// result: the launch throws Interrupted instead, which the CLI turns into exit status 130.
#pragma once

#include <atomic>
#include <stdexcept>

namespace speculum::par {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

inline std::atomic<bool> interrupt_requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler stores to it");

// Async-signal-safe.
inline void request_interrupt() { interrupt_requested.store(true, std::memory_order_relaxed); }
inline bool interrupted() { return interrupt_requested.load(std::memory_order_relaxed); }
inline void throw_if_interrupted() {
  if (interrupted()) throw Interrupted();
}

}  // namespace speculum::par
