// Closest-hit traversal of 8- or 16-ray packets for coherent rays (primary, mirror): the packet
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

constexpr int kPacketSize = 8;      // rays per packet of a stream in stream order
constexpr int kMaxPacketSize = 16;  // rays per packet of an image (4x4 pixel tiles)

// Closest hits of rays[0, count), count in 1..kMaxPacketSize, traced as one packet when they
// are coherent (else one by one). Returns true when the packet path was taken.
bool closest_hit_packet(const Bvh& bvh, const Ray* rays, int count, Hit* out, TraversalCounters* counters = nullptr);

// Closest hits for a stream: consecutive groups of kPacketSize rays (stream order) are
// packets; or, when image_width > 0 divides the ray count (the rays are a camera image, one
// per pixel, row-major), 4x4 pixel tiles of 16 rays are, as rtcIntersect16 is fed: neighbouring
// pixels share more of their node path than a run of 8 in a row, and one interval test per
// node serves 16 rays. Chunks of kRayChunk rays on the executor (kernel
// "trace_closest_packets"). A refused (incoherent) packet sends the next few packets of its
// chunk to single rays without the coherence test. Same hits as closest_hit_stream for any
// grouping and thread count.
void closest_hit_stream_packets(const Bvh& bvh, const RayStream& rays, HitStream& hits, par::Executor& executor,
                                TraversalCounters* counters = nullptr, int image_width = 0);

}  // namespace speculum::trace
