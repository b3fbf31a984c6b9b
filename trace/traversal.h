// Ray queries against the BVH (trace/bvh.h) and the all-pairs oracle: closest hit and any
// hit, single rays and SoA ray streams traversed in fixed chunks. Stacks have a fixed size;
// an overflow drops the deepest pending node and is counted (bounded work per element:
// docs/architecture.md, "Stream constraints"). Ties in t go to the lower triangle index,
// so every structure returns the oracle's (t, triangle) bit for bit.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "core/camera_rays.h"
#include "parallel/executor.h"
#include "trace/bvh.h"

namespace speculum::trace {

constexpr std::uint32_t kNoHit = 0xffffffffu;
constexpr int kTraversalStackSize = 128;

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;          // barycentrics of the triangle's 2nd and 3rd vertex
  std::uint32_t triangle = kNoHit;   // original triangle index
  bool hit() const { return triangle != kNoHit; }
};

// Integer counters, summed in chunk order by the stream kernels.
struct TraversalCounters {
  std::uint64_t rays = 0;
  std::uint64_t nodes_visited = 0;
  std::uint64_t triangle_tests = 0;
  std::uint64_t stack_overflows = 0;
  void add(const TraversalCounters& o) {
    rays += o.rays;
    nodes_visited += o.nodes_visited;
    triangle_tests += o.triangle_tests;
    stack_overflows += o.stack_overflows;
  }
};

// 8-wide layout, stack-based, nearest child first.
Hit closest_hit(const Bvh& bvh, const Ray& ray, TraversalCounters* counters = nullptr);
bool any_hit(const Bvh& bvh, const Ray& ray, TraversalCounters* counters = nullptr);
// closest_hit with a smaller stack (1..kTraversalStackSize), so tests can drive the
// overflow path: entries that do not fit are dropped and counted.
Hit closest_hit_limited_stack(const Bvh& bvh, const Ray& ray, int stack_limit,
                              TraversalCounters* counters = nullptr);

// Threaded layout, stackless, fixed depth-first order.
Hit closest_hit_threaded(const Bvh& bvh, const Ray& ray, TraversalCounters* counters = nullptr);

// Every ray against every triangle (the test oracle).
Hit closest_hit_oracle(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                       const Ray& ray);
bool any_hit_oracle(const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices,
                    const Ray& ray);

// Rays as structure of arrays.
struct RayStream {
  std::vector<float> ox, oy, oz, dx, dy, dz, tmin, tmax;
  std::size_t size() const { return ox.size(); }
  // Inline so the SPRY reader (trace/ray_file.cpp) stands alone, as its fuzzer builds it.
  void resize(std::size_t n) {
    for (auto* v : {&ox, &oy, &oz, &dx, &dy, &dz, &tmin, &tmax}) v->resize(n);
  }
  void set(std::size_t i, const Ray& r);
  Ray get(std::size_t i) const;
};

struct HitStream {
  std::vector<float> t, u, v;
  std::vector<std::uint32_t> triangle;
  void resize(std::size_t n);
};

constexpr std::size_t kRayChunk = 256;

// Closest hits for a stream, chunks of kRayChunk rays on the executor (kernel "trace_closest").
void closest_hit_stream(const Bvh& bvh, const RayStream& rays, HitStream& hits, par::Executor& executor,
                        TraversalCounters* counters = nullptr);

}  // namespace speculum::trace
