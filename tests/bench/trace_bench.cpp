// BVH benchmarks: build time and closest-hit throughput (single rays and 8-ray
// packets) for primary and reflect-cone30 rays on UV-spheres in a box room, 1 and 2
// threads. The Embree comparison lives in `speculum bench trace` (same run, same rays);
// these track our own trends.
// Counters: Mrays_s, nodes_per_ray, tris_per_ray.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "core/sampling.h"
#include "core/scene.h"
#include "trace/bvh.h"
#include "trace/packet_traversal.h"
#include "trace/ray_generation.h"
#include "trace/traversal.h"

namespace {
using namespace speculum;

// Launch recording off: a benchmark runs a kernel millions of times, and the records (a
// mutex and a string per launch) would grow without bound and be timed with the kernel.
par::Executor& executor(int threads) {
  static par::Executor one(1), two(2);
  static const bool quiet = (one.set_recording(false), two.set_recording(false), true);
  (void)quiet;
  return threads == 1 ? one : two;
}

// `count` UV-spheres of 2*rings*segs triangles on a grid in a room, as in bench trace.
TriangleMesh spheres_room(int count, int rings, int segs) {
  TriangleMesh m;
  const int grid = static_cast<int>(std::ceil(std::sqrt(double(count))));
  const float half = 10.0f, spacing = 2 * half / grid, radius = 0.45f * spacing;
  for (int s = 0; s < count; ++s) {
    const glm::vec3 c(-half + spacing * (s % grid + 0.5f), -1.0f, -half + spacing * (s / grid + 0.5f));
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int r = 0; r <= rings; ++r)
      for (int k = 0; k <= segs; ++k) {
        const float th = kPi * r / rings, ph = 2 * kPi * k / segs;
        m.positions.push_back(c + radius * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
      }
    for (int r = 0; r < rings; ++r)
      for (int k = 0; k < segs; ++k) {
        const std::uint32_t a = base + r * (segs + 1) + k, b = a + segs + 1;
        m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
      }
  }
  const glm::vec3 lo(-half, -2, -half), hi(half, 6, half);
  const auto b = static_cast<std::uint32_t>(m.positions.size());
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  const std::uint32_t q[6][4] = {{0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : q) m.indices.insert(m.indices.end(), {b + f[0], b + f[1], b + f[2], b + f[0], b + f[2], b + f[3]});
  return m;
}

const TriangleMesh& mesh() {
  static const TriangleMesh m = spheres_room(100, 25, 50);  // ~250K triangles: quick to set up
  return m;
}

Camera camera() {
  Camera c;
  c.eye = {0, 4, 9.5f};
  c.target = {0, 1, 0};
  c.vfov_degrees = 60;
  return c;
}

void BM_BvhBuild(benchmark::State& state) {
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(trace::Bvh::build(mesh(), ex));
  state.counters["Mtris_s"] = benchmark::Counter(double(mesh().triangle_count()) * state.iterations() / 1e6,
                                                 benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BvhBuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ClosestHit(benchmark::State& state) {
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  static const trace::Bvh bvh = trace::Bvh::build(mesh(), executor(2));
  const auto kind = state.range(1) == 0 ? trace::RaySetKind::Primary : trace::RaySetKind::ReflectCone30;
  const trace::RayStream rays = trace::generate_rays(kind, bvh, camera(), 512, 512, 1, executor(2));
  trace::HitStream hits;
  trace::TraversalCounters counters;
  for (auto _ : state) trace::closest_hit_stream(bvh, rays, hits, ex, &counters);
  state.counters["Mrays_s"] = benchmark::Counter(double(rays.size()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
  state.counters["nodes_per_ray"] = double(counters.nodes_visited) / double(counters.rays);
  state.counters["tris_per_ray"] = double(counters.triangle_tests) / double(counters.rays);
  state.SetLabel(state.range(1) == 0 ? "primary" : "reflect-cone30");
}
BENCHMARK(BM_ClosestHit)->Args({1, 0})->Args({2, 0})->Args({1, 1})->Args({2, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

// The same rays through closest_hit_stream_packets (incoherent packets fall back to single rays).
void BM_ClosestHitPackets(benchmark::State& state) {
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  static const trace::Bvh bvh = trace::Bvh::build(mesh(), executor(2));
  const auto kind = state.range(1) == 0 ? trace::RaySetKind::Primary : trace::RaySetKind::ReflectCone30;
  const trace::RayStream rays = trace::generate_rays(kind, bvh, camera(), 512, 512, 1, executor(2));
  trace::HitStream hits;
  for (auto _ : state) trace::closest_hit_stream_packets(bvh, rays, hits, ex);
  state.counters["Mrays_s"] = benchmark::Counter(double(rays.size()) * state.iterations() / 1e6, benchmark::Counter::kIsRate);
  state.SetLabel(state.range(1) == 0 ? "primary" : "reflect-cone30");
}
BENCHMARK(BM_ClosestHitPackets)->Args({1, 0})->Args({2, 0})->Args({1, 1})->Args({2, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
