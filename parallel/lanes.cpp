// The process-wide default lane width set by `--lanes W` (see lanes.h).
#include "parallel/lanes.h"

#include <atomic>

namespace speculum::par {

namespace {
std::atomic<int> g_default_lanes{kNativeLanes};
}

int default_lanes() { return g_default_lanes.load(std::memory_order_relaxed); }

void set_default_lanes(int w) {
  if (w == 0) w = kNativeLanes;
  if (!is_supported_lane_width(w))
    throw std::invalid_argument("unsupported lane width " + std::to_string(w) +
                                " (use 0 = native, 1, 4, 8 or 16)");
  // Relaxed: a configuration value set before work is launched; launches synchronize.
  g_default_lanes.store(w, std::memory_order_relaxed);
}

}  // namespace speculum::par
