// Benchmark ray sets for a camera over a BVH (the Embree comparison of `bench trace`):
// primary (one per pixel, scanline order), reflect-cone30 (per primary hit, the mirror
// direction about the geometric normal perturbed uniformly within a 30° cone) and
// hemisphere (per primary hit, cosine-weighted about the geometric normal). Secondary
// origins are offset along the normal on the incident side.
#pragma once

#include <cstdint>
#include <string>

#include "core/scene.h"
#include "parallel/executor.h"
#include "trace/bvh.h"
#include "trace/traversal.h"

namespace speculum::trace {

enum class RaySetKind { Primary, ReflectCone30, Hemisphere };

// Throws InputError for an unknown name.
RaySetKind parse_ray_set_kind(const std::string& name);

RayStream generate_rays(RaySetKind kind, const Bvh& bvh, const Camera& camera, int width, int height,
                        std::uint32_t seed, par::Executor& executor);

}  // namespace speculum::trace
