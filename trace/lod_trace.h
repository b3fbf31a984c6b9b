// The `lod_trace` node of YU §3.3: stackless traversal of the threaded BVH that stops
// descending at an inner node whose box subtends at most α² times the ray's solid angle
// (eq.7, Ω_box ≤ α² Ω_s with Ω_box of eq.6), intersects that node's approximate geometry
// (trace/lod_bvh.h) and follows its miss link. LOD off is an explicit switch: then the
// traversal is closest_hit_threaded's, with the same hits bit for bit.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "parallel/executor.h"
#include "trace/lod_bvh.h"
#include "trace/traversal.h"

namespace speculum::trace {

struct LodOptions {
  bool enabled = false;  // false: LOD off (the plain threaded traversal)
  float alpha = 1.0f;    // eq.7 threshold, YU uses 1..10
};

struct LodHit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;
  std::uint32_t triangle = kNoHit;  // a full-resolution triangle (original index), or
  std::uint32_t proxy = kNoHit;     // the LOD node whose approximate geometry was hit
  bool hit() const { return triangle != kNoHit || proxy != kNoHit; }
};

struct LodCounters {
  TraversalCounters traversal;     // rays, nodes visited, triangle tests
  std::uint64_t lod_stops = 0;     // eq.7 passed: a proxy was intersected instead of a subtree
  std::uint64_t proxy_hits = 0;    // rays whose closest hit is a proxy
  void add(const LodCounters& o) {
    traversal.add(o.traversal);
    lod_stops += o.lod_stops;
    proxy_hits += o.proxy_hits;
  }
};

// One ray with solid angle `solid_angle` (Ω_s of eq.5). Only nodes with a quad proxy stop
// (a non-planar node has no faithful two-triangle approximation: it always descends), and a
// box that contains the ray origin is never approximated (eq.6 has no meaning there).
LodHit closest_hit_lod(const Bvh& bvh, const LodBvh& lod, const Ray& ray, float solid_angle,
                       const LodOptions& options, LodCounters* counters = nullptr);

// Kernel "lod_trace": chunks of kRayChunk rays; counters summed in chunk order.
void closest_hit_lod_stream(const Bvh& bvh, const LodBvh& lod, const RayStream& rays,
                            const std::vector<float>& solid_angle, const LodOptions& options,
                            std::vector<LodHit>& hits, par::Executor& executor,
                            LodCounters* counters = nullptr);

}  // namespace speculum::trace
