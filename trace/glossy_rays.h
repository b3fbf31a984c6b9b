// The `glossy_rays` node of YU §3.2: for every glossy (or mirror) G-buffer sample, N
// reflected rays importance-sampled from the normalized Phong lobe about R (eq.4) with a
// per-pixel rotated 2-D Hamersley set, and each ray's solid angle Ω_s = 1/(N p) (eq.5).
// Each ray carries the weight w = f cos / p of the glTF BRDF's specular lobe (core/brdf.h),
// and the pixel's reflection is the self-normalized estimate E(F0) Σ w L / Σ w, where
// E(F0) is the lobe's directional albedo (specular_reflectance): it converges to the same
// integral ∫ f L cos the reference tracer samples, returns exactly E L under a uniform
// environment (as the prefiltered techniques do), and does not darken when a few rays miss
// the GGX lobe's long tails. A share kDefensiveShare of the rays is drawn from the cosine
// lobe about N instead (p is the mixture's pdf), so that w stays bounded in those tails.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/shading.h"
#include "core/surface_plane.h"
#include "parallel/executor.h"
#include "trace/traversal.h"

namespace speculum::trace {

struct GlossyRayOptions {
  int rays_per_pixel = 30;  // N
  std::uint32_t seed = 0;   // keys the per-pixel Cranley–Patterson rotation
};

// Rays of pixel k (k-th glossy pixel) occupy slots [k N, k N + N).
struct GlossyRays {
  int width = 0, height = 0;
  int rays_per_pixel = 0;
  std::vector<std::uint32_t> pixel;  // glossy pixel indices, ascending
  std::vector<glm::vec3> albedo;     // per glossy pixel: E(F0) = specular_reflectance(N·V)
  std::vector<glm::vec3> weight;     // per ray: f cos / p (mirror: Schlick F); 0 inactive
  RayStream rays;                    // below-horizon samples are inactive (tmin > tmax)
  std::vector<float> solid_angle;    // Ω_s per ray, eq.5 (0 for inactive rays)
  std::uint64_t below_horizon = 0;   // samples rejected: they contribute 0 (shading.h model)
  std::size_t ray_count() const { return rays.size(); }
};

// The surfaces this node traces: opaque samples with a mirror or glossy Phong lobe.
inline bool traces_glossy(const SurfaceParams& s) {
  return !s.is_refractor() && (s.is_mirror_lobe() || s.is_glossy_lobe());
}

// Solid angle of one of N samples of the Phong lobe (exponent n) at polar cosine cos_theta
// about R (YU eq.5). Its mean over the lobe's samples is 2π/N: the pdf is normalized over the
// hemisphere about R (YU §3.2 states 4π/N, which would need a pdf over the whole sphere).
float sample_solid_angle(float cos_theta, float exponent, int n);

// Share of a glossy pixel's rays drawn from the cosine lobe about N (see the top comment);
// mirrors (a delta lobe) use none.
constexpr float kDefensiveShare = 0.1f;
// The pdf of the mixture at a direction with cos_r = R·d and cos_n = N·d.
float glossy_mixture_pdf(float cos_r, float cos_n, float exponent);

// Kernel "glossy_rays". Buffers are the G-buffer's (world positions, unit shading normals,
// surface parameters, object ids with kNoId for background); eye is the camera position.
// Throws InputError when the buffers' sizes differ or rays_per_pixel is outside 1..4096.
GlossyRays generate_glossy_rays(par::Executor& executor, const Buffer2D<glm::vec3>& positions,
                                const Buffer2D<glm::vec3>& normals,
                                const SurfacePlane& surface, const IdBuffer& object,
                                const glm::vec3& eye, const GlossyRayOptions& options);

}  // namespace speculum::trace
