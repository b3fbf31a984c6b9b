// Stream-primitive benchmarks: scan, both compactions, partition, radix sort and
// reduce at 1M and 16M elements on 1 and 2 threads, each reporting its GB/s beside a memcpy
// of the same traffic measured in the same process; plus the ROGER ch.4 block-size sweep.
// Traffic = bytes the primitive must read + write at minimum; memcpy traffic = 2 × copy size.
// Counters: GBps (primitive), memcpy_GBps (same traffic, same thread count), Mkeys_s.
// BM_StreamCopy (read once, streaming stores) is the ceiling for the scan: its 2T/1T is the
// most any bandwidth-bound one-pass kernel can scale on this machine.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>
#include <vector>

#include <immintrin.h>

#include "parallel/compact.h"
#include "parallel/page_buffer.h"
#include "parallel/partition.h"
#include "parallel/scan.h"
#include "parallel/stream.h"

namespace {
using namespace speculum::par;

// Launch recording off: a benchmark runs a kernel millions of times, and the records (a
// mutex and a string per launch) would grow without bound and be timed with the kernel.
Executor& executor(int threads) {
  static Executor one(1), two(2);
  static const bool quiet = (one.set_recording(false), two.set_recording(false), true);
  (void)quiet;
  return threads == 1 ? one : two;
}

std::uint32_t hash32(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return std::uint32_t((x ^ (x >> 31)) >> 16);
}

// Median-of-5 memcpy bandwidth (read + write bytes per second) for `traffic` bytes of
// traffic, run with the same thread count as the primitive (memcpy split in fixed chunks).
double memcpy_gbps(std::size_t traffic, int threads) {
  const std::size_t bytes = std::max<std::size_t>(traffic / 2, 64);
  static std::vector<char> src, dst;
  if (src.size() < bytes) {
    src.assign(bytes, 1);
    dst.assign(bytes, 0);
  }
  std::vector<double> secs;
  for (int r = 0; r < 5; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    executor(threads).parallel_for("memcpy", bytes, 1 << 20, [&](std::size_t b, std::size_t e) {
      std::memcpy(dst.data() + b, src.data() + b, e - b);
    });
    secs.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::nth_element(secs.begin(), secs.begin() + 2, secs.end());
  return 2.0 * double(bytes) / secs[2] * 1e-9;
}

void report(benchmark::State& state, std::size_t traffic, int threads, std::size_t keys = 0) {
  state.SetBytesProcessed(std::int64_t(state.iterations() * traffic));
  const double mgbps = memcpy_gbps(traffic, threads);
  state.counters["memcpy_GBps"] = mgbps;
  state.counters["GBps"] = benchmark::Counter(double(traffic) * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
  if (keys) state.counters["Mkeys_s"] = benchmark::Counter(double(keys) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
}

void BM_Memcpy(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<std::uint32_t> a(n, 1), b(n);
  for (auto _ : state) {
    executor(threads).parallel_for("memcpy", n, kStreamChunk, [&](std::size_t s, std::size_t e) {
      std::memcpy(b.data() + s, a.data() + s, (e - s) * 4);
    });
    benchmark::DoNotOptimize(b.data());
  }
  state.counters["GBps"] = benchmark::Counter(double(n) * 8e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// The bandwidth ceiling of any one-read-one-write kernel: each element read once and written
// once with streaming (cache-bypassing) stores, as the scan and the radix sort's output do.
// Same traffic convention as BM_Memcpy (8 bytes per u32); compare its 2T/1T with theirs.
void BM_StreamCopy(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  PageBuffer src_buf, dst_buf;  // 64-byte aligned (2 MiB)
  std::uint32_t* const src = src_buf.reserve<std::uint32_t>(n);
  std::uint32_t* const dst = dst_buf.reserve<std::uint32_t>(n);
  std::fill_n(src, n, 1u);
  std::fill_n(dst, n, 0u);
  for (auto _ : state) {
    executor(threads).parallel_for("stream_copy", n, kStreamChunk, [&](std::size_t s, std::size_t e) {
      for (std::size_t i = s; i < e; i += 16) {
        const __m256i a = _mm256_load_si256(reinterpret_cast<const __m256i*>(src + i));
        const __m256i b = _mm256_load_si256(reinterpret_cast<const __m256i*>(src + i + 8));
        _mm256_stream_si256(reinterpret_cast<__m256i*>(dst + i), a);
        _mm256_stream_si256(reinterpret_cast<__m256i*>(dst + i + 8), b);
      }
      _mm_sfence();
    });
    benchmark::DoNotOptimize(dst);
  }
  state.counters["GBps"] = benchmark::Counter(double(n) * 8e-9, benchmark::Counter::kIsIterationInvariantRate);
}

// Args: n, threads, lane width W (8 unless given: the native width of this build).
void BM_ExclusiveScan(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<std::uint32_t> in(n), out(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = hash32(i) & 7;
  dispatch_lanes(state.range(2), [&](auto w) {
    for (auto _ : state) {
      benchmark::DoNotOptimize(exclusive_scan<w.value>(executor(threads), "scan", std::span<const std::uint32_t>(in),
                                                       std::span(out)));
    }
  });
  report(state, n * 8, threads);
}

// In place, as a compaction's offsets or a histogram's bucket starts are scanned.
void BM_InclusiveScan(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<std::uint32_t> data(n);
  for (std::size_t i = 0; i < n; ++i) data[i] = hash32(i) & 7;
  dispatch_lanes(state.range(2), [&](auto w) {
    for (auto _ : state) {  // rescans its own output (wrapping sums): the same work every time
      benchmark::DoNotOptimize(inclusive_scan<w.value>(executor(threads), "scan", std::span<const std::uint32_t>(data),
                                                       std::span(data)));
    }
  });
  report(state, n * 8, threads);
}

void BM_Reduce(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<float> in(n);
  for (std::size_t i = 0; i < n; ++i) in[i] = float(hash32(i) & 255);
  for (auto _ : state)
    benchmark::DoNotOptimize(reduce(executor(threads), "reduce", std::span<const float>(in), 0.f, std::plus<>()));
  report(state, n * 4, threads);
}

std::vector<std::uint8_t> half_flags(std::size_t n) {
  std::vector<std::uint8_t> f(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = hash32(i) & 1;
  return f;
}

// Args: n, threads, lane width W (compact_scatter<W>; 8 = the native width of this build,
// 1 = the scalar reference).
void BM_CompactScatter(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  const auto keep = half_flags(n);
  std::vector<std::uint32_t> out(n);
  std::size_t kept = 0;
  dispatch_lanes(int(state.range(2)), [&](auto w) {
    kept = compact_scatter<w.value>(executor(threads), "compact", keep, out);  // warm-up
    for (auto _ : state)
      benchmark::DoNotOptimize(kept = compact_scatter<w.value>(executor(threads), "compact", keep, out));
  });
  report(state, n + kept * 4, threads);
}

// Args: n, threads, block size s, lane width W.
void BM_CompactHierarchical(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  const std::size_t s = state.range(2);
  const auto keep = half_flags(n);
  std::vector<std::uint32_t> out(n), scratch;
  std::size_t kept = 0;
  dispatch_lanes(int(state.range(3)), [&](auto w) {
    // Warm-up: first touch of out and scratch.
    kept = compact_hierarchical<w.value>(executor(threads), "compact_h", keep, out, s, &scratch);
    for (auto _ : state)
      benchmark::DoNotOptimize(kept = compact_hierarchical<w.value>(executor(threads), "compact_h", keep, out, s, &scratch));
  });
  report(state, n + kept * 4, threads);
}

// Args: n, threads, lane width W.
void BM_Partition(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  const std::uint32_t p = 16;
  std::vector<std::uint32_t> bucket(n), out(n), begin(p + 1);
  for (std::size_t i = 0; i < n; ++i) bucket[i] = hash32(i) % p;
  dispatch_lanes(int(state.range(2)), [&](auto w) {
    for (auto _ : state) {
      partition_stable<w.value>(executor(threads), "partition", bucket, p, out, begin);
      benchmark::DoNotOptimize(out.data());
    }
  });
  report(state, n * 8, threads);
}

// Args: n, threads, lane width W.
void BM_RadixSort32(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<std::uint32_t> original(n), keys(n), payload(n);
  for (std::size_t i = 0; i < n; ++i) original[i] = hash32(i);
  RadixSortScratch<std::uint32_t> scratch;
  dispatch_lanes(state.range(2), [&](auto w) {
    keys = original;  // warm-up: first touch of the scratch buffers (page faults) outside timing
    radix_sort<w.value>(executor(threads), "radix", std::span(keys), std::span(payload), &scratch);
    for (auto _ : state) {
      state.PauseTiming();
      std::copy(original.begin(), original.end(), keys.begin());
      std::iota(payload.begin(), payload.end(), 0u);
      state.ResumeTiming();
      radix_sort<w.value>(executor(threads), "radix", std::span(keys), std::span(payload), &scratch);
      benchmark::DoNotOptimize(keys.data());
    }
  });
  report(state, n * 16, threads, n);  // keys + payload read and written once (minimum)
}

// The same keys without a payload (the keys-only path scatters bare 32-bit keys).
void BM_RadixSort32Keys(benchmark::State& state) {
  const std::size_t n = state.range(0);
  const int threads = int(state.range(1));
  std::vector<std::uint32_t> original(n), keys(n);
  for (std::size_t i = 0; i < n; ++i) original[i] = hash32(i);
  RadixSortScratch<std::uint32_t> scratch;
  keys = original;  // warm-up: first touch of the scratch buffers outside timing
  radix_sort(executor(threads), "radix_keys", std::span(keys), {}, &scratch);
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(original.begin(), original.end(), keys.begin());
    state.ResumeTiming();
    radix_sort(executor(threads), "radix_keys", std::span(keys), {}, &scratch);
    benchmark::DoNotOptimize(keys.data());
  }
  report(state, n * 8, threads, n);  // keys read and written once (minimum)
}

void sizes_threads(benchmark::internal::Benchmark* b) {
  for (long n : {1L << 20, 16L << 20})
    for (long t : {1, 2}) b->Args({n, t});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}

BENCHMARK(BM_Memcpy)->Apply(sizes_threads);
BENCHMARK(BM_StreamCopy)->Apply(sizes_threads);
// Primitives that take a lane width: W = 8, plus W = 1 (the scalar reference), 4 and 16 at
// 16M on one thread.
void lanes_args(benchmark::internal::Benchmark* b) {
  for (long n : {1L << 20, 16L << 20})
    for (long t : {1, 2}) b->Args({n, t, 8});
  for (long w : {1, 4, 16}) b->Args({16L << 20, 1, w});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
}
BENCHMARK(BM_ExclusiveScan)->Apply(lanes_args);
BENCHMARK(BM_InclusiveScan)->Apply(lanes_args);
BENCHMARK(BM_Reduce)->Apply(sizes_threads);
BENCHMARK(BM_CompactScatter)->Apply(lanes_args);
BENCHMARK(BM_CompactHierarchical)->Apply([](benchmark::internal::Benchmark* b) {
  for (long n : {1L << 20, 16L << 20})
    for (long t : {1, 2}) b->Args({n, t, 64, 8});
  for (long w : {1, 4, 16}) b->Args({16L << 20, 1, 64, w});
  // ROGER ch.4 block-size sweep s = 8 ... 1024 at 16M, 2 threads.
  for (long s = 8; s <= 1024; s *= 2) b->Args({16L << 20, 2, s, 8});
  b->Unit(benchmark::kMillisecond)->UseRealTime();
});
BENCHMARK(BM_Partition)->Apply(lanes_args);
BENCHMARK(BM_RadixSort32)->Apply(lanes_args);
BENCHMARK(BM_RadixSort32Keys)->Apply(sizes_threads);

}  // namespace
