// Secondary ray generations for the ray-hierarchy technique (ROGER §3.3.1 steps 2 and 5,
// §3.3.5): one reflected or refracted ray per specular pixel of a G-buffer, the next bounce
// from the closest hits, shadow rays reversed to start at a point light, and the shading
// of a generation's hits with the shared model (core/shading.h). Kernels over core types
// only (no raster/ types), so the recipe in apps/ wires them to the G-buffer.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "core/shading.h"
#include "core/surface_plane.h"
#include "parallel/executor.h"
#include "trace/hit_surface.h"
#include "trace/traversal.h"

namespace speculum::trace {

// One generation of rays on the pixel grid (row-major width × height): pixel i carries a
// ray when active[i]; weight[i] is the factor its radiance is multiplied by in the pixel
// (Fresnel × the throughput of earlier bounces).
struct SecondaryRays {
  int width = 0, height = 0;
  RayStream rays;
  std::vector<std::uint8_t> active;
  std::vector<glm::vec3> weight;
  std::uint64_t count = 0;  // active rays
};

// A generation of width × height pixels with no active ray (zero weights, count 0).
SecondaryRays empty_generation(int width, int height);
// Sets g.count to the number of active rays.
void count_active(SecondaryRays& g);

// The surfaces that get a secondary ray: mirror and glossy lobes (roughness <
// kGlossyRoughness) and refractors (the test raster::is_specular uses).
inline bool has_secondary_ray(const SurfaceParams& s) {
  return s.is_refractor() || s.roughness < kGlossyRoughness;
}

// From G-buffer planes (object id kNoId = background): mirror/glossy pixels get the mirror
// ray R = reflect(V, N) with weight specular_reflectance (Schlick F; a glossy lobe's albedo
// E); glossy surfaces trace the lobe's axis only (no lobe sampling). Refractors get the refracted ray with weight
// transmission (1 - F) base_color (exact dielectric Fresnel), or the reflected ray with
// weight transmission on total internal reflection; their Fresnel-reflected part is not
// traced (one ray per pixel). Kernel "secondary_rays".
SecondaryRays secondary_rays(par::Executor& executor, const Buffer2D<glm::vec3>& position,
                             const Buffer2D<glm::vec3>& normal, const SurfacePlane& surface,
                             const IdBuffer& object, const glm::vec3& eye);

// The next generation: every hit on a specular surface spawns its reflected/refracted ray
// (the same rules as secondary_rays), weight multiplied. Kernel "bounce_rays".
SecondaryRays bounce_rays(par::Executor& executor, const Scene& scene, const SecondaryRays& in,
                          const HitStream& hits);

// Shadow rays towards `light` for the hits of `gen` the light can reach: for point and spot
// lights reversed, starting at the light and ending just before the surface point
// (origin = light, direction = point - light, t in [0, 1 - 1e-4]), so every ray of the
// hierarchy shares one origin (ROGER §3.3.5); directional lights get forward rays from the
// surface. Kernel "shadow_rays".
SecondaryRays shadow_rays(par::Executor& executor, const Scene& scene, const Light& light,
                          const SecondaryRays& gen, const HitStream& hits);

// Radiance of generation `gen` per pixel, added to `out` (width × height): weight × (the
// environment on a miss; emission + every light's shade_light where unshadowed otherwise).
// shadow_hits[l] are the closest hits of shadow_rays(..., lights[l], ...): a hit = shadowed.
// Kernel "shade_hits".
void shade_hits(par::Executor& executor, const Scene& scene, const SecondaryRays& gen, const HitStream& hits,
                const std::vector<HitStream>& shadow_hits, ImageRGBA& out);

// The fallback where the depth is exhausted: `gen` are the continuations that would be
// traced next (bounce_rays of the last generation); each adds weight × the environment along
// its direction to `out`, so a mirror, glossy or glass surface at the end of the chain shows
// the environment it would reflect or transmit rather than its black diffuse shading.
// Kernel "environment_fallback".
void add_environment_fallback(par::Executor& executor, const Scene& scene, const SecondaryRays& gen, ImageRGBA& out);

}  // namespace speculum::trace
