// Both compactions against a sequential filter: every size class, every ratio 0..100 %,
// block sizes s, 1/2/8 threads, kernel lane widths W = 1, 4, 8, 16; and the ROGER Fig.4.8
// golden vector (s=16).
#include "parallel/compact.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <initializer_list>
#include <string>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

std::vector<std::uint32_t> serial_filter(const std::vector<std::uint8_t>& keep) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) out.push_back(std::uint32_t(i));
  return out;
}

std::vector<std::uint32_t> run_scatter(Executor& ex, const std::vector<std::uint8_t>& keep) {
  std::vector<std::uint32_t> out(keep.size());
  out.resize(compact_scatter(ex, "compact", keep, out));
  return out;
}
std::vector<std::uint32_t> run_hier(Executor& ex, const std::vector<std::uint8_t>& keep, std::size_t s) {
  std::vector<std::uint32_t> out(keep.size());
  out.resize(compact_hierarchical(ex, "compact_h", keep, out, s));
  return out;
}

// ROGER Fig.4.8 (s = 16), exactly, at every kernel width W: the within-block step's prefix
// sums and reduced blocks, then the whole compaction with its block displacements.
TEST(Compact, RogerFig48GoldenVector) {
  const std::string blocks = "43X192XX7X6X58X5" "431X2X6XX7X98XX5" "X87XX235XXX6XX1X" "1XXX45X7X6X8329X";
  std::vector<std::uint8_t> keep;
  for (char c : blocks) keep.push_back(c != 'X');
  const char* psums[] = {"0011112334455566", "0001122344555677", "1112333345667889", "0123334455666667"};
  const char* reduced[] = {"4319276585", "431267985", "8723561", "145768329"};
  for_each_lane_width([&](auto w) {
    constexpr int W = w.value;
    for (int b = 0; b < 4; ++b) {
      std::vector<std::uint32_t> psum(16), out(16);
      std::uint64_t steps = 0;
      const auto c = compact_block_gather<W>(std::span(keep).subspan(b * 16, 16), psum, out, steps);
      std::string p, r;
      for (auto v : psum) p += char('0' + v);
      for (std::size_t k = 0; k < c; ++k) r += blocks[b * 16 + out[k]];
      EXPECT_EQ(p, psums[b]) << "W=" << W;
      EXPECT_EQ(r, reduced[b]) << "W=" << W;
    }
    for (int t : kThreadCounts) {
      std::vector<std::uint32_t> out(64);
      HierarchicalCompactStats stats;
      const auto n = compact_hierarchical<W>(executor(t), "fig48", keep, out, 16, nullptr, &stats);
      std::string joined;
      for (std::size_t k = 0; k < n; ++k) {
        // Block displacements in output order: 0, 10, 19, 26.
        if (k == 10 || k == 19 || k == 26) joined += '|';
        joined += blocks[out[k]];
      }
      EXPECT_EQ(joined, "4319276585|431267985|8723561|145768329") << "W=" << W << " t=" << t;
      EXPECT_EQ(stats.blocks, 4u);
    }
  });
}

TEST(Compact, BothFormsEqualSequentialFilterForEverySize) {
  for (std::size_t n : sizes()) {
    for (int percent : {0, 3, 50, 97, 100}) {
      const auto keep = flags(n, percent, n);
      const auto ref = serial_filter(keep);
      for (int t : kThreadCounts) {
        EXPECT_EQ(run_scatter(executor(t), keep), ref) << n << " " << percent << "% t=" << t;
        for (std::size_t s : {1u, 16u, 64u, 1000u})
          EXPECT_EQ(run_hier(executor(t), keep, s), ref) << n << " " << percent << "% s=" << s << " t=" << t;
      }
    }
  }
}

// 16M flags at a middle ratio and at the ends, both forms, 1/2/8 threads × W = 1, 4, 8, 16
// (the serial filter is the reference, so every thread count and width gives the same indices).
TEST(Compact, SixteenMillion) {
  const std::size_t n = kLargeSize + 5;
  for (int percent : {37, 0, 100}) {
    const auto keep = flags(n, percent, 5);
    const auto ref = serial_filter(keep);
    std::vector<std::uint32_t> out, scratch;
    for (int t : kThreadCounts)
      for_each_lane_width([&](auto w) {
        constexpr int W = w.value;
        out.assign(n, 0xdeadbeefu);
        ASSERT_EQ(compact_scatter<W>(executor(t), "s16M", keep, out), ref.size()) << percent << "% t=" << t << " W=" << W;
        ASSERT_TRUE(std::equal(ref.begin(), ref.end(), out.begin())) << percent << "% t=" << t << " W=" << W;
        out.assign(n, 0xdeadbeefu);
        ASSERT_EQ(compact_hierarchical<W>(executor(t), "h16M", keep, out, 64, &scratch), ref.size())
            << percent << "% t=" << t << " W=" << W;
        ASSERT_TRUE(std::equal(ref.begin(), ref.end(), out.begin())) << percent << "% t=" << t << " W=" << W;
      });
  }
}

// Flags made by a width-generic kernel, then compacted: identical for every W and thread
// count (every W gives the same bits: docs/architecture.md, "Determinism").
template <int W>
std::vector<std::uint32_t> cull_kernel(Executor& ex, const std::vector<float>& d) {
  using L = Lanes<W>;
  std::vector<std::uint8_t> keep(d.size());
  map_lanes<W>(ex, "cull", d.size(), [&](std::size_t i, auto active) {
    const int c = L::count(active);
    const auto v = L::load_partial(d.data() + i, c);
    const auto on = L::sqrt(v) * 0.5f + v < 0.6f;
    for (int k = 0; k < c; ++k) keep[i + k] = on[k];
  });
  std::vector<std::uint32_t> out(d.size());
  out.resize(compact_hierarchical(ex, "cull_compact", keep, out, 32));
  return out;
}

TEST(Compact, LaneWidthsAndThreadsGiveIdenticalResults) {
  std::vector<float> d(30001);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = unit_float(i);
  const auto ref = cull_kernel<1>(executor(1), d);
  EXPECT_GT(ref.size(), 0u);
  EXPECT_LT(ref.size(), d.size());
  for (int t : kThreadCounts)
    for (int w : {1, 4, 8, 16})
      EXPECT_EQ(dispatch_lanes(w, [&](auto lw) { return cull_kernel<lw.value>(executor(t), d); }), ref)
          << "W=" << w << " t=" << t;
}

// Every kernel width W = 1, 4, 8, 16 (instantiated here, not taken from --lanes) at 1, 2 and 8
// threads gives the serial filter's indices: every size class and ratio, both forms, and the
// same search_steps for every W (probes per output slot do not depend on W).
TEST(Compact, EveryKernelWidthAndThreadCountEqualsSerial) {
  for (std::size_t n : sizes()) {
    for (int percent : {0, 3, 50, 97, 100}) {
      const auto keep = flags(n, percent, n + 7);
      const auto ref = serial_filter(keep);
      for (std::size_t s : {1u, 16u, 64u}) {
        std::uint64_t ref_steps = 0;
        for (int w : kLaneWidths)
          for (int t : kThreadCounts) {
            std::vector<std::uint32_t> out(n, 0xdeadbeefu);
            HierarchicalCompactStats stats;
            const auto kept = dispatch_lanes(w, [&](auto lw) {
              return compact_hierarchical<lw.value>(executor(t), "compact_hw", keep, out, s, nullptr, &stats);
            });
            out.resize(kept);
            ASSERT_EQ(out, ref) << n << " " << percent << "% s=" << s << " W=" << w << " t=" << t;
            if (w == 1 && t == 1) ref_steps = stats.search_steps;
            ASSERT_EQ(stats.search_steps, ref_steps) << n << " " << percent << "% s=" << s << " W=" << w << " t=" << t;
          }
      }
      for (int w : kLaneWidths)
        for (int t : kThreadCounts) {
          std::vector<std::uint32_t> out(n, 0xdeadbeefu);
          out.resize(dispatch_lanes(w, [&](auto lw) { return compact_scatter<lw.value>(executor(t), "compact_w", keep, out); }));
          ASSERT_EQ(out, ref) << n << " " << percent << "% W=" << w << " t=" << t;
          // Small chunks: many chunks whose output ranges are shorter than a 32-flag step.
          out.assign(n, 0xdeadbeefu);
          out.resize(dispatch_lanes(w, [&](auto lw) { return compact_scatter<lw.value>(executor(t), "compact_w", keep, out, 37); }));
          ASSERT_EQ(out, ref) << n << " " << percent << "% W=" << w << " t=" << t << " chunk=37";
        }
    }
  }
}

// Every integer percentage 0..100 % at size n, every kernel width W × 1/2/8 threads: the
// scatter form at its default chunk and the hierarchical form at each block size s, both
// against the serial filter.
void check_every_ratio(std::size_t n, std::initializer_list<std::size_t> block_sizes) {
  std::vector<std::uint32_t> out;
  for (int percent = 0; percent <= 100; percent += kPercentStep) {
    const auto keep = flags(n, percent, n + std::size_t(percent));
    const auto ref = serial_filter(keep);
    for (int w : kLaneWidths)
      for (int t : kThreadCounts) {
        out.assign(n, 0xdeadbeefu);
        out.resize(dispatch_lanes(w, [&](auto lw) { return compact_scatter<lw.value>(executor(t), "ratio_w", keep, out); }));
        ASSERT_EQ(out, ref) << n << " " << percent << "% W=" << w << " t=" << t;
        for (std::size_t s : block_sizes) {
          out.assign(n, 0xdeadbeefu);
          out.resize(dispatch_lanes(w, [&](auto lw) {
            return compact_hierarchical<lw.value>(executor(t), "ratio_hw", keep, out, s);
          }));
          ASSERT_EQ(out, ref) << n << " " << percent << "% s=" << s << " W=" << w << " t=" << t;
        }
      }
  }
}

// One chunk of either form (4099 < kStreamChunk), with a short tail block for every s.
TEST(Compact, EveryRatioAtEveryKernelWidth) { check_every_ratio(4099, {8, 16, 32, 64, 128, 256, 512, 1024}); }

// Three chunks of the chained scatter (the last holds 5 flags), so every ratio also runs the
// look-back between chunks; for the hierarchical form 32 block_reduce launch chunks of
// kStreamChunk flags (s = 64 divides it; s = 1000 makes launch chunks of 16 blocks that do
// not line up with them) and, above ~3 % kept, several concatenate chunks.
TEST(Compact, EveryRatioAcrossChunksAtEveryKernelWidth) { check_every_ratio(2 * kCompactChunk + 5, {64, 1000}); }

// An output span shorter than the input takes the count-first path: exactly the kept count
// fits, one slot less throws before anything is written (the span keeps its contents).
TEST(Compact, ScatterIntoExactlySizedOrShortOutput) {
  for (std::size_t n : {std::size_t(100), 3 * kStreamChunk + 11})
    for (int percent : {1, 50, 99}) {
      const auto keep = flags(n, percent, n + std::size_t(percent));
      const auto ref = serial_filter(keep);
      for (int t : kThreadCounts)
        for_each_lane_width([&](auto w) {
          std::vector<std::uint32_t> exact(ref.size(), 0xdeadbeefu);
          ASSERT_EQ(compact_scatter<w.value>(executor(t), "exact", keep, exact), ref.size());
          ASSERT_EQ(exact, ref) << n << " " << percent << "% W=" << w.value << " t=" << t;
          std::vector<std::uint32_t> short_by_one(ref.size() - 1, 7u);
          EXPECT_THROW(compact_scatter<w.value>(executor(t), "short", keep, short_by_one), std::invalid_argument);
          EXPECT_TRUE(std::all_of(short_by_one.begin(), short_by_one.end(), [](auto v) { return v == 7u; }));
        });
    }
}

TEST(Compact, RejectsBadArguments) {
  std::vector<std::uint8_t> keep = {1, 1, 1};
  std::vector<std::uint32_t> small(2);
  EXPECT_THROW(compact_scatter(executor(1), "c", keep, small), std::invalid_argument);
  EXPECT_THROW(compact_hierarchical(executor(1), "c", keep, small, 4), std::invalid_argument);
  EXPECT_THROW(compact_hierarchical(executor(1), "c", keep, small, 0), std::invalid_argument);
}

}  // namespace
}  // namespace speculum::par
