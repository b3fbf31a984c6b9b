// Closest-hit traversal of 8-ray packets for coherent rays (primary, mirror): the packet
// walks the 8-wide BVH once, testing each node's 8 child boxes against interval bounds of
// the packet's origins and reciprocal directions (one vector test for all rays, Wald et
// al. "Ray tracing deformable scenes using dynamic BVHs" 2007 §4 interval arithmetic),
// then tests each leaf box per ray and the leaf's triangles only for the rays inside it.
// Incoherent packets (mixed direction signs or a wide spread) fall back to single rays.
// Results equal closest_hit (and the oracle) bit for bit.
#pragma once

#include <cstdint>

#include "core/camera_rays.h"
#include "parallel/executor.h"
#include "trace/bvh.h"
#include "trace/traversal.h"

namespace speculum::trace {

constexpr int kPacketSize = 8;

// Closest hits of rays[0, count), count in 1..kPacketSize, traced as one packet when they
// are coherent (else one by one). Returns true when the packet path was taken.
bool closest_hit_packet(const Bvh& bvh, const Ray* rays, int count, Hit* out, TraversalCounters* counters = nullptr);

// Closest hits for a stream: consecutive groups of kPacketSize rays (stream order) are
// packets; chunks of kRayChunk rays on the executor (kernel "trace_closest_packets").
// Same hits as closest_hit_stream for any thread count.
void closest_hit_stream_packets(const Bvh& bvh, const RayStream& rays, HitStream& hits, par::Executor& executor,
                                TraversalCounters* counters = nullptr);

}  // namespace speculum::trace
