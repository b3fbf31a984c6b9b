// map, map_lanes, gather, reduce, scans and SoA streams against serial references, for
// every size class and 1/2/8 threads.
#include "parallel/scan.h"
#include "parallel/stream.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <memory>
#include <numeric>
#include <span>
#include <thread>
#include <type_traits>
#include <utility>

#include "primitive_test_util.h"

namespace speculum::par {
namespace {
using namespace test;

TEST(Stream, MapGatherMatchSerial) {
  for (std::size_t n : sizes()) {
    std::vector<float> in(n);
    for (std::size_t i = 0; i < n; ++i) in[i] = unit_float(i);
    std::vector<std::uint32_t> idx(n);
    for (std::size_t i = 0; i < n; ++i) idx[i] = hash32(i + 99) % n;
    for (int t : kThreadCounts) {
      std::vector<float> sq(n), g(n);
      map(executor(t), "square", std::span<const float>(in), std::span(sq), [](float x) { return x * x; });
      gather(executor(t), "gather", std::span<const float>(in), std::span<const std::uint32_t>(idx), std::span(g));
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(sq[i], in[i] * in[i]);
        ASSERT_EQ(g[i], in[idx[i]]);
      }
    }
  }
}

TEST(Stream, IntegerScansAndReduceEqualSerialForEveryWidthAndThreadCount) {
  for (std::size_t n : sizes()) {
    std::vector<std::uint32_t> in(n);
    for (std::size_t i = 0; i < n; ++i) in[i] = hash32(i) % 1000;
    std::vector<std::uint32_t> ex_ref(n), in_ref(n);
    std::exclusive_scan(in.begin(), in.end(), ex_ref.begin(), 5u);
    std::inclusive_scan(in.begin(), in.end(), in_ref.begin(), std::plus<>(), 5u);
    const std::uint32_t total = std::accumulate(in.begin(), in.end(), 5u);
    for (int t : kThreadCounts) {
      for_each_lane_width([&](auto w) {
        constexpr int W = w.value;
        std::vector<std::uint32_t> a(n), b(in);
        EXPECT_EQ(exclusive_scan<W>(executor(t), "ex", std::span<const std::uint32_t>(in), std::span(a), 5u), total);
        EXPECT_EQ(inclusive_scan<W>(executor(t), "in", std::span<const std::uint32_t>(b), std::span(b), 5u), total);
        EXPECT_EQ(a, ex_ref) << n << " " << t << " W=" << W;
        EXPECT_EQ(b, in_ref) << n << " " << t << " W=" << W;  // in place
      });
      // reduce() needs a true identity (it seeds every chunk with it).
      EXPECT_EQ(reduce(executor(t), "sum", std::span<const std::uint32_t>(in), 0u, std::plus<>()), total - 5u);
      auto mx = reduce(executor(t), "max", std::span<const std::uint32_t>(in), 0u,
                       [](std::uint32_t x, std::uint32_t y) { return std::max(x, y); });
      EXPECT_EQ(mx, n ? *std::max_element(in.begin(), in.end()) : 0u);
    }
  }
}

TEST(Stream, FloatScanAndReduceBitIdenticalAcrossThreads) {
  const std::size_t n = 3 * kStreamChunk + 17;
  std::vector<float> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = unit_float(i) * 1000.f - 500.f;
  // Oracle: the documented association (chunk folds, then chunk sums in order).
  float oracle = 0.f;
  for (std::size_t b = 0; b < n; b += kStreamChunk) {
    float s = 0.f;
    for (std::size_t i = b; i < std::min(n, b + kStreamChunk); ++i) s += in[i];
    oracle += s;
  }
  std::vector<float> ref;
  for (int t : kThreadCounts) {
    const float r = reduce(executor(t), "sum", std::span<const float>(in), 0.f, std::plus<>());
    EXPECT_EQ(std::bit_cast<std::uint32_t>(r), std::bit_cast<std::uint32_t>(oracle));
    std::vector<float> out(n);
    inclusive_scan(executor(t), "scan", std::span<const float>(in), std::span(out));
    if (ref.empty()) ref = out;
    EXPECT_EQ(0, n == 0 ? 0 : std::memcmp(out.data(), ref.data(), n * sizeof(float))) << t;
  }
}

// 10 MiB of floats (past scan.h's streaming-store threshold, many look-backs): results
// equal the documented association bit for bit (chunk sums folded in order, each chunk
// scanned from its offset), for every thread count.
TEST(Stream, FloatScanAcrossTilesMatchesChunkAssociation) {
  const std::size_t n = (std::size_t(5) << 19) + 77;  // 10 MiB of floats
  std::vector<float> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = unit_float(i) * 10.f - 3.f;
  std::vector<float> oracle(n);
  float running = 1.5f;
  for (std::size_t b = 0; b < n; b += kScanChunk) {
    const std::size_t e = std::min(n, b + kScanChunk);
    float sum = in[b];
    for (std::size_t i = b + 1; i < e; ++i) sum += in[i];
    float acc = running;
    for (std::size_t i = b; i < e; ++i) oracle[i] = acc += in[i];
    running += sum;
  }
  for (int t : kThreadCounts) {
    for_each_lane_width([&](auto w) {
      std::vector<float> out(n);
      const float total = inclusive_scan<w.value>(executor(t), "scan_tiles", std::span<const float>(in),
                                                  std::span(out), 1.5f);
      EXPECT_EQ(std::bit_cast<std::uint32_t>(total), std::bit_cast<std::uint32_t>(running)) << t;
      ASSERT_EQ(0, std::memcmp(out.data(), oracle.data(), n * sizeof(float))) << t << " W=" << w.value;
    });
  }
}

// 16M u32 (the streaming-store path): exclusive and inclusive, 1/2/8 threads × every lane
// width, into an output one element off line alignment (unaligned head and tail per chunk)
// and in place.
TEST(Stream, Scan16MEverySpanWidthAndThreadCount) {
  const std::size_t n = kLargeSize;
  std::vector<std::uint32_t> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = hash32(i) & 1023;
  std::vector<std::uint32_t> ex_ref(n), in_ref(n);
  std::exclusive_scan(in.begin(), in.end(), ex_ref.begin(), 3u);
  std::inclusive_scan(in.begin(), in.end(), in_ref.begin(), std::plus<>(), 3u);
  const std::uint32_t total = in_ref.back();
  std::vector<std::uint32_t> buf(n + 1);
  for (int t : kThreadCounts) {
    for_each_lane_width([&](auto w) {
      constexpr int W = w.value;
      const std::span<std::uint32_t> shifted(buf.data() + 1, n);
      std::fill(buf.begin(), buf.end(), 0u);
      EXPECT_EQ(exclusive_scan<W>(executor(t), "ex16M", std::span<const std::uint32_t>(in), shifted, 3u), total);
      ASSERT_TRUE(std::equal(shifted.begin(), shifted.end(), ex_ref.begin())) << t << " W=" << W;
      std::vector<std::uint32_t> b(in);
      EXPECT_EQ(inclusive_scan<W>(executor(t), "in16M", std::span<const std::uint32_t>(b), std::span(b), 3u), total);
      ASSERT_TRUE(b == in_ref) << t << " W=" << W;
    });
  }
}

// Types and operators off the SIMD path, past the streaming threshold: u64 sums (generic
// streaming stores), signed 32-bit sums (SIMD), and a u32 max (scalar).
TEST(Stream, ScansOffTheSimdPathEqualSerial) {
  const std::size_t n = (std::size_t(9) << 20) / 8 + 5;  // > 8 MiB of u64
  std::vector<std::uint64_t> in64(n);
  for (std::size_t i = 0; i < n; ++i) in64[i] = std::uint64_t(hash32(i)) << 20 | hash32(i + n);
  std::vector<std::uint64_t> ref64(n);
  std::inclusive_scan(in64.begin(), in64.end(), ref64.begin(), std::plus<>(), std::uint64_t(7));
  const std::size_t m = std::size_t(3) << 20;  // 12 MiB of 32-bit values
  std::vector<std::int32_t> ins(m);
  for (std::size_t i = 0; i < m; ++i) ins[i] = std::int32_t(hash32(i) % 2001) - 1000;
  std::vector<std::int32_t> refs(m);
  std::exclusive_scan(ins.begin(), ins.end(), refs.begin(), -5);
  std::vector<std::uint32_t> inu(m), refmax(m);
  for (std::size_t i = 0; i < m; ++i) inu[i] = hash32(i * 3);
  auto max_op = [](std::uint32_t x, std::uint32_t y) { return std::max(x, y); };
  std::inclusive_scan(inu.begin(), inu.end(), refmax.begin(), max_op, 0u);
  for (int t : kThreadCounts) {
    std::vector<std::uint64_t> out64(n);
    EXPECT_EQ(inclusive_scan<1>(executor(t), "u64", std::span<const std::uint64_t>(in64), std::span(out64),
                             std::uint64_t(7)), ref64.back());
    ASSERT_TRUE(out64 == ref64) << t;
    std::vector<std::int32_t> outs(m);
    exclusive_scan(executor(t), "i32", std::span<const std::int32_t>(ins), std::span(outs), -5);
    ASSERT_TRUE(outs == refs) << t;
    std::vector<std::uint32_t> outmax(m);
    EXPECT_EQ(inclusive_scan(executor(t), "max", std::span<const std::uint32_t>(inu), std::span(outmax), 0u,
                             max_op), refmax.back());
    ASSERT_TRUE(outmax == refmax) << t;
  }
}

// The chunk kernel scans its chunk and returns the sum of the thread's next chunk, which it
// reads during the scan (scan_kernels.h): both checked against serial references at every
// width, for chunks shorter and longer than a step, an output off its 64-byte line (the
// streaming head), a shorter next chunk (the last one) and none, with and without streaming.
TEST(Stream, ChunkScanSumsTheNextChunkAtEveryWidth) {
  constexpr std::size_t kMax = 5000;
  std::vector<std::uint32_t> in(kMax), next(kMax);
  for (std::size_t i = 0; i < kMax; ++i) {
    in[i] = hash32(i);
    next[i] = hash32(i + kMax);
  }
  alignas(64) static std::uint32_t out[kMax + 16];
  std::vector<std::uint32_t> ref(kMax);
  std::plus<std::uint32_t> op;
  for_each_lane_width([&](auto w) {
    constexpr int W = decltype(w)::value;
    for (std::size_t m : {std::size_t(1), std::size_t(15), std::size_t(33), std::size_t(4096), std::size_t(4999)})
      for (std::size_t next_m : {std::size_t(0), std::size_t(1), m / 3 + 1, m})
        for (std::size_t shift : {std::size_t(0), std::size_t(5)})
          for (bool streaming : {false, true})
            for (bool inclusive : {false, true}) {
              std::uint32_t* o = out + shift;
              const std::uint32_t* nx = next_m == 0 ? nullptr : next.data();
              const std::uint32_t sum = inclusive
                  ? scan_kernels::chunk_scan<W, true>(in.data(), o, m, 9u, op, streaming, nx, next_m)
                  : scan_kernels::chunk_scan<W, false>(in.data(), o, m, 9u, op, streaming, nx, next_m);
              if (inclusive) std::inclusive_scan(in.begin(), in.begin() + m, ref.begin(), op, 9u);
              else std::exclusive_scan(in.begin(), in.begin() + m, ref.begin(), 9u);
              const auto where = ::testing::Message() << "W=" << W << " m=" << m << " next_m=" << next_m
                                                      << " shift=" << shift << " streaming=" << streaming
                                                      << " inclusive=" << inclusive;
              ASSERT_TRUE(std::equal(ref.begin(), ref.begin() + m, o)) << where;
              ASSERT_EQ(sum, std::accumulate(next.begin(), next.begin() + next_m, 0u)) << where;
            }
  });
  // Off the lane path (a float sum) the next chunk's sum is the serial left fold.
  std::vector<float> fin(100), fnext(37), fout(100);
  for (std::size_t i = 0; i < fin.size(); ++i) fin[i] = unit_float(i);
  for (std::size_t i = 0; i < fnext.size(); ++i) fnext[i] = unit_float(i + 500);
  std::plus<float> fop;
  const float fsum = scan_kernels::chunk_scan<8, true>(fin.data(), fout.data(), fin.size(), 0.5f, fop, false,
                                                       fnext.data(), fnext.size());
  EXPECT_EQ(std::bit_cast<std::uint32_t>(fsum),
            std::bit_cast<std::uint32_t>(std::accumulate(fnext.begin() + 1, fnext.end(), fnext[0])));
}

// The look-back gives the serial left fold's bits whatever the predecessors have published:
// nothing yet (the sum is computed here), a sum, or a prefix (where the walk stops); a
// predecessor no thread has taken is taken and done whole (take), never summed twice.
TEST(Stream, ScanLookBackFoldsInChunkOrder) {
  using Link = detail::ScanLink<float>;
  constexpr std::size_t kChunks = 9;
  float sum[kChunks], prefix[kChunks];
  float running = 0.25f;
  for (std::size_t c = 0; c < kChunks; ++c) {
    sum[c] = unit_float(c) * 1000.f - 400.f;
    running += sum[c];
    prefix[c] = running;
  }
  std::plus<float> op;
  std::vector<float> scratch;
  constexpr std::uint32_t F = Link::kFree, C = Link::kClaimed, S = Link::kSum, P = Link::kPrefix;
  const std::uint32_t patterns[][kChunks] = {{C, C, C, C, C, C, C, C, C},
                                              {S, S, S, S, S, S, S, S, S},
                                              {P, C, S, C, P, S, C, S, C},
                                              {P, P, P, P, P, P, P, P, P},
                                              {F, S, F, C, P, F, S, C, F}};
  for (const auto& pattern : patterns) {
    for (std::size_t c = 0; c < kChunks; ++c) {
      std::unique_ptr<Link[]> links(new Link[kChunks]);
      for (std::size_t k = 0; k < kChunks; ++k) {
        links[k].sum = sum[k];
        links[k].prefix = prefix[k];
        links[k].state.store(pattern[k]);
      }
      std::vector<std::size_t> computed, taken;
      auto sum_of = [&](std::size_t k) {
        computed.push_back(k);
        return sum[k];
      };
      auto take = [&](std::size_t k) {  // what chained_pass does: the whole chunk, prefix published
        EXPECT_EQ(links[k].state.load(), Link::kClaimed);
        taken.push_back(k);
        links[k].state.store(Link::kPrefix);
      };
      const float offset = detail::look_back(links.get(), c, 0.25f, op, sum_of, true, scratch, take);
      const float expected = c == 0 ? 0.25f : prefix[c - 1];
      EXPECT_EQ(std::bit_cast<std::uint32_t>(offset), std::bit_cast<std::uint32_t>(expected)) << c;
      // Walking back from c-1: claimed links are summed here, free ones taken, and the walk
      // ends at the first prefix (a taken link publishes one).
      std::vector<std::size_t> want_computed, want_taken;
      for (std::size_t k = c; k-- > 0;) {
        if (pattern[k] == F) {
          want_taken.push_back(k);
          break;
        }
        if (pattern[k] == P) break;
        if (pattern[k] == C) want_computed.push_back(k);
      }
      EXPECT_EQ(computed, want_computed) << c;
      EXPECT_EQ(taken, want_taken) << c;
    }
  }
  // In place a missing sum is awaited, never computed (its owner may already be overwriting
  // the chunk's input): the link is published late by another thread.
  std::unique_ptr<Link[]> links(new Link[kChunks]);
  for (std::size_t c = 0; c < kChunks; ++c) {
    links[c].sum = sum[c];
    links[c].state.store(c == 3 ? C : S);
  }
  std::size_t computed = 0;
  auto sum_of = [&](std::size_t c) {
    ++computed;
    return sum[c];
  };
  std::thread owner([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    links[3].state.store(S, std::memory_order_release);
  });
  const float offset = detail::look_back(links.get(), 6, 0.25f, op, sum_of, false, scratch,
                                         [](std::size_t) { ADD_FAILURE() << "no link is free"; });
  owner.join();
  EXPECT_EQ(std::bit_cast<std::uint32_t>(offset), std::bit_cast<std::uint32_t>(prefix[5]));
  EXPECT_EQ(computed, 0u);
}

TEST(Stream, MapLanesBitIdenticalForEveryWidthAndThreadCount) {
  for (std::size_t n : {0u, 1u, 13u, 12345u}) {
    std::vector<float> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = unit_float(i) * 8.f - 4.f;
    const auto ref = lanes_kernel<1>(executor(1), x);
    for (int t : kThreadCounts)
      for (int w : {1, 4, 8, 16}) {
        const auto y = dispatch_lanes(w, [&](auto lw) { return lanes_kernel<lw.value>(executor(t), x); });
        EXPECT_EQ(0, n == 0 ? 0 : std::memcmp(y.data(), ref.data(), n * sizeof(float))) << n << " W=" << w << " t=" << t;
      }
  }
}

template <class T>
std::vector<T> to_vector(std::span<const T> s) {
  return {s.begin(), s.end()};
}

TEST(Stream, SoaGather) {
  SoaStream<float, std::uint32_t> s;
  s.resize(5);
  for (std::uint32_t i = 0; i < 5; ++i) {
    s.field<0>()[i] = float(i) * 1.5f;
    s.field<1>()[i] = 100 + i;
  }
  const std::vector<std::uint32_t> idx = {4, 0, 2};
  const auto g = s.gather(executor(2), "soa_gather", idx);
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(to_vector(g.field<0>()), (std::vector<float>{6.f, 0.f, 3.f}));
  EXPECT_EQ(to_vector(g.field<1>()), (std::vector<std::uint32_t>{104, 100, 102}));
}

// SoaStream::gather at every size class and 1/2/8 threads against a serial gather of each
// field: fields of three element sizes, an index stream half again as long as the source
// (repeated indices; several gather chunks past kStreamChunk), every field of the result
// of the index stream's length. resize keeps the fields the same length when growing and
// shrinking, and keeps the values below the new length.
TEST(Stream, SoaGatherEverySizeAndThreadCountEqualsSerial) {
  for (std::size_t n : sizes()) {
    SoaStream<float, std::uint64_t, std::uint8_t> s;
    // A field is a fixed-length view: only resize, which resizes every field, changes lengths.
    static_assert(std::is_same_v<decltype(s.field<1>()), std::span<std::uint64_t>>);
    static_assert(std::is_same_v<decltype(std::as_const(s).field<1>()), std::span<const std::uint64_t>>);
    s.resize(n + 3);
    s.resize(n);
    ASSERT_EQ(s.size(), n);
    ASSERT_EQ(s.field<1>().size(), n);
    ASSERT_EQ(s.field<2>().size(), n);
    std::vector<float> a(n);
    std::vector<std::uint64_t> b(n);
    std::vector<std::uint8_t> c(n);
    for (std::size_t i = 0; i < n; ++i) {
      a[i] = s.field<0>()[i] = unit_float(i);
      b[i] = s.field<1>()[i] = std::uint64_t(hash32(i + 1)) << 32 | hash32(i + 2);
      c[i] = s.field<2>()[i] = std::uint8_t(hash32(i + 3));
    }
    const std::size_t m = n ? n + n / 2 : 0;
    std::vector<std::uint32_t> idx(m);
    for (std::size_t k = 0; k < m; ++k) idx[k] = hash32(k * 7 + 5) % std::uint32_t(n);
    std::vector<float> ga(m);
    std::vector<std::uint64_t> gb(m);
    std::vector<std::uint8_t> gc(m);
    for (std::size_t k = 0; k < m; ++k) {
      ga[k] = a[idx[k]];
      gb[k] = b[idx[k]];
      gc[k] = c[idx[k]];
    }
    for (int t : kThreadCounts) {
      const auto g = s.gather(executor(t), "soa_gather", idx);
      ASSERT_EQ(g.size(), m) << n << " t=" << t;
      EXPECT_EQ(to_vector(g.field<0>()), ga) << n << " t=" << t;
      EXPECT_EQ(to_vector(g.field<1>()), gb) << n << " t=" << t;
      EXPECT_EQ(to_vector(g.field<2>()), gc) << n << " t=" << t;
    }
    // Shrinking keeps the leading elements of every field.
    s.resize(n / 2);
    ASSERT_EQ(s.field<2>().size(), n / 2);
    EXPECT_TRUE(std::equal(c.begin(), c.begin() + std::ptrdiff_t(n / 2), s.field<2>().begin())) << n;
    EXPECT_TRUE(std::equal(b.begin(), b.begin() + std::ptrdiff_t(n / 2), s.field<1>().begin())) << n;
  }
}

}  // namespace
}  // namespace speculum::par
