// Lanes<W>: every width agrees bit for bit with the W=1 scalar reference.
#include "parallel/lanes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace speculum::par {
namespace {

std::vector<float> test_floats(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(-100.f, 100.f);
  std::vector<float> v(n);
  for (auto& x : v) x = d(rng);
  // Awkward values: signed zeros, NaN, infinities, denormals, ties.
  const float special[] = {0.f, -0.f, std::numeric_limits<float>::quiet_NaN(),
                           std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(),
                           std::numeric_limits<float>::denorm_min(), 1.f, 1.f};
  for (std::size_t i = 0; i < std::size(special) && i * 7 < n; ++i) v[i * 7] = special[i];
  return v;
}

// A width-generic kernel exercising most operations; output per element plus a stream sum.
template <int W>
float kernel(const std::vector<float>& a, const std::vector<float>& b,
             const std::vector<std::int32_t>& idx, std::vector<float>& out) {
  using L = Lanes<W>;
  float sum = 0.f;
  const std::size_t n = a.size();
  for (std::size_t i = 0; i < n; i += W) {
    const int count = int(std::min<std::size_t>(W, n - i));
    const auto active = L::first_n(count);
    const auto x = L::load_partial(a.data() + i, count);
    const auto y = L::load_partial(b.data() + i, count, 1.f);
    const auto k = L::load_partial(idx.data() + i, count);
    const auto g = L::gather(a.data(), k, active, 0.f);
    auto r = L::min(x, y) * 3.f + L::max(x, g) - L::sqrt(L::abs(y)) / (L::abs(x) + 1.f);
    r = L::select(x < y, r, L::map(x, [](float v) { return std::exp(v * 0.01f); }));
    L::store_partial(r, out.data() + i, count);
    sum = L::accumulate(sum, r, active);
  }
  return sum;
}

TEST(Lanes, EveryWidthMatchesScalarBits) {
  for (std::size_t n : {0u, 1u, 7u, 33u, 1001u}) {
    const auto a = test_floats(n, 1), b = test_floats(n, 2);
    std::vector<std::int32_t> idx(n);
    for (std::size_t i = 0; i < n; ++i) idx[i] = std::int32_t((i * 7919) % n);
    std::vector<float> ref(n);
    const float ref_sum = kernel<1>(a, b, idx, ref);
    for (int w : {4, 8, 16}) {
      std::vector<float> out(n);
      const float sum = dispatch_lanes(w, [&](auto lw) { return kernel<lw.value>(a, b, idx, out); });
      EXPECT_EQ(std::bit_cast<std::uint32_t>(sum), std::bit_cast<std::uint32_t>(ref_sum))
          << "n=" << n << " W=" << w;
      EXPECT_EQ(0, n == 0 ? 0 : std::memcmp(out.data(), ref.data(), n * sizeof(float))) << "n=" << n << " W=" << w;
    }
  }
}

TEST(Lanes, SerialAccumulateEqualsScalarLoop) {
  const auto a = test_floats(1000, 3);
  float serial = 0.f;
  for (std::size_t i = 1; i < a.size(); ++i) serial += std::isfinite(a[i]) ? a[i] : 0.f;
  std::vector<float> clean(a.begin() + 1, a.end());
  for (auto& x : clean) if (!std::isfinite(x)) x = 0.f;
  dispatch_lanes(8, [&](auto lw) {
    using L = Lanes<lw.value>;
    float acc = 0.f;
    for (std::size_t i = 0; i < clean.size(); i += L::width) {
      const int c = int(std::min<std::size_t>(L::width, clean.size() - i));
      acc = L::accumulate(acc, L::load_partial(clean.data() + i, c), L::first_n(c));
    }
    EXPECT_EQ(acc, serial);
  });
}

TEST(Lanes, HorizontalOps) {
  using L = Lanes<8>;
  const float v[8] = {5, 3, -2, 7, -2, 9, 0, 1};
  const auto x = L::load(v);
  EXPECT_EQ(L::hmin(x), -2.f);
  EXPECT_EQ(L::hmax(x), 9.f);
  EXPECT_EQ(L::argmin(x), 2);  // tie with lane 4: lowest lane wins
  EXPECT_EQ(L::hadd(x), 21.f);
  EXPECT_EQ(L::count(x > 0.f), 5);
  EXPECT_TRUE(L::any(x > 8.f));
  EXPECT_FALSE(L::all(x > -2.f));
  EXPECT_TRUE(L::none(x > 9.f));
  EXPECT_EQ(L::first_active(x < 0.f), 2);
  EXPECT_EQ(L::first_active(x > 100.f), -1);
  const auto i = L::iota(10);
  EXPECT_EQ(int(i[0]), 10);
  EXPECT_EQ(int(i[7]), 17);
  alignas(64) float buf[8];
  L::store_aligned(x, buf);
  EXPECT_EQ(0, std::memcmp(buf, v, sizeof v));
  float part[8] = {};
  L::store_masked(x, part, x > 4.f);
  EXPECT_EQ(part[0], 5.f);
  EXPECT_EQ(part[1], 0.f);
  EXPECT_EQ(part[5], 9.f);
}

TEST(Lanes, DispatchAndResolve) {
  EXPECT_EQ(dispatch_lanes(0, [](auto w) { return int(w.value); }), kNativeLanes);
  for (int w : {1, 4, 8, 16}) EXPECT_EQ(dispatch_lanes(w, [](auto lw) { return int(lw.value); }), w);
  EXPECT_THROW(dispatch_lanes(3, [](auto) { return 0; }), std::invalid_argument);
  EXPECT_THROW(dispatch_lanes(32, [](auto) { return 0; }), std::invalid_argument);
  EXPECT_EQ(resolve_lane_width(0), kNativeLanes);
  for (int w : {1, 4, 8, 16}) EXPECT_EQ(resolve_lane_width(w), w);
  for (int bad : {-4, -1, 2, 5, 12, 32}) EXPECT_THROW(resolve_lane_width(bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace speculum::par
