// Shared fixtures for the stream-primitive tests: executors at 1, 2 and 8 threads, the
// sizes every primitive is checked at, and a counter-based hash for reproducible data.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "parallel/compact.h"
#include "parallel/executor.h"
#include "parallel/partition.h"
#include "parallel/scan.h"
#include "parallel/segmented.h"
#include "parallel/stream.h"

namespace speculum::par::test {

inline Executor& executor(int threads) {
  static Executor one(1), two(2), eight(8);
  return threads == 1 ? one : threads == 2 ? two : eight;
}
inline constexpr int kThreadCounts[] = {1, 2, 8};

// f(std::integral_constant<int, W>) for every lane width W ∈ {1, 4, 8, 16}: the kernels are
// instantiated at each width in the test binary.
inline constexpr int kLaneWidths[] = {1, 4, 8, 16};
template <class F>
void for_each_lane_width(F&& f) {
  for (int w : kLaneWidths) dispatch_lanes(w, f);
}

// The large size class: 16M elements. Under a sanitizer (SPECULUM_SANITIZED, defined by the
// sanitizer builds) 4M: past every size threshold of parallel/ (streaming stores and uncached
// scans from 8 MiB, many chunks per thread) like 16M, at a quarter of the time, since the
// instrumented loops run 5 to 15 times slower.
#ifdef SPECULUM_SANITIZED
inline constexpr std::size_t kLargeSize = std::size_t(4) << 20;
#else
inline constexpr std::size_t kLargeSize = std::size_t(16) << 20;
#endif

// The kept shares (percent) the ratio sweeps visit: every one from 0 to 100, and every tenth
// under a sanitizer (the sanitizers look for memory and thread errors, which do not depend
// on the exact share; the normal build keeps the exhaustive sweep).
#ifdef SPECULUM_SANITIZED
inline constexpr int kPercentStep = 10;
#else
inline constexpr int kPercentStep = 1;
#endif

// 0, 1, odd, just over a stream, scan, scatter and compaction chunk (16M cases are separate).
inline const std::vector<std::size_t>& sizes() {
  static const std::vector<std::size_t> s = {0, 1, 7, 12345, kStreamChunk + 1, kScanChunk + 1, kScatterChunk + 3,
                                             kCompactChunk + 1};
  return s;
}

inline std::uint32_t hash32(std::uint64_t x) {  // splitmix64 finalizer
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return std::uint32_t((x ^ (x >> 31)) >> 16);
}
inline float unit_float(std::uint64_t i) { return float(hash32(i) >> 8) * (1.f / 16777216.f); }

// A width-generic map_lanes kernel (sqrt, abs, min, multiply-add over W lanes) for the
// lane-width determinism tests: y = sqrt(|x|)·3 + min(x, x²), with min(a, b) = "b < a ? b : a".
template <int W>
std::vector<float> lanes_kernel(Executor& ex, const std::vector<float>& x) {
  using L = Lanes<W>;
  std::vector<float> y(x.size());
  map_lanes<W>(ex, "lanes_kernel", x.size(), [&](std::size_t i, auto active) {
    const int c = L::count(active);
    const auto v = L::load_partial(x.data() + i, c);
    L::store_partial(L::sqrt(L::abs(v)) * 3.f + L::min(v, v * v), y.data() + i, c);
  });
  return y;
}

// Serial segmented min/argmin as parallel/segmented.h documents it: per segment the smallest
// value and the lowest index holding it; NaN never wins; the first non-NaN value claims a
// segment without a winner (so +inf can win); empty segments keep +inf and kNoIndex.
inline void serial_segmented_min(const std::vector<std::uint32_t>& seg, const std::vector<float>& value,
                                 std::uint32_t segments, std::vector<float>& v, std::vector<std::uint32_t>& ix) {
  v.assign(segments, std::numeric_limits<float>::infinity());
  ix.assign(segments, kNoIndex);
  for (std::size_t i = 0; i < seg.size(); ++i)
    if (value[i] < v[seg[i]] || (ix[seg[i]] == kNoIndex && value[i] == v[seg[i]])) {
      v[seg[i]] = value[i];
      ix[seg[i]] = std::uint32_t(i);
    }
}

// keep[i] = 1 with probability percent/100 (exactly 0 % and 100 % at the ends).
inline std::vector<std::uint8_t> flags(std::size_t n, int percent, std::uint64_t seed) {
  std::vector<std::uint8_t> f(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = (hash32(seed * 0x100000001ull + i) % 100) < std::uint32_t(percent);
  return f;
}

}  // namespace speculum::par::test
