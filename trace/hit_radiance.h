// Radiance at the glossy rays' hits (YU §3.4–3.5, eq.8–9) and the `radiance_bake` that feeds
// it. YU filters a radiance texture; for general meshes the pre-filtered radiance is a
// pyramid whose level-0 texels are the triangles (A_texel = the triangle's area) and whose
// coarser levels are the BVH ancestors' area-weighted mean radiance (trace/lod_bvh.h).
// Lighting is baked once per triangle at four points: the lit fraction of every light
// and the occluded environment irradiance (cosine samples), both view-independent; a hit
// then shades exactly at level 0 (the material at the hit's uv, shared model of
// core/shading.h) and blends towards the ancestors as the eq.9 level grows. Glossy/mirror
// surfaces that are hit reflect the environment along R (one bounce: no further tracing).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "trace/bvh.h"
#include "trace/glossy_rays.h"
#include "trace/lod_bvh.h"
#include "trace/lod_trace.h"

namespace speculum::trace {

struct RadianceBakeOptions {
  int environment_samples = 8;  // cosine samples per triangle for the occluded sky (0: none)
  std::uint32_t seed = 0;
};

// Per original triangle.
struct TriangleLighting {
  std::size_t light_count = 0;
  std::vector<float> visibility;                  // [triangle * light_count + light]: lit fraction
  std::vector<glm::vec3> environment_irradiance;  // occluded E from the environment
  // View-independent radiance the LOD levels average: emission + diffuse (lights and sky)
  // + a view-averaged specular F0 E_env / π.
  std::vector<glm::vec3> radiance;
};

// Kernel "radiance_bake": shadow and sky rays from each triangle's bake points.
TriangleLighting bake_triangle_lighting(par::Executor& executor, const Scene& scene, const Bvh& bvh,
                                        const RadianceBakeOptions& options = {});

// YU eq.8: the footprint A = d² Ω_s / cosθ_i of a ray of solid angle Ω_s hitting at distance
// d with incidence cosine cos_incidence (clamped away from 0).
float footprint_area(float distance, float solid_angle, float cos_incidence);
// YU eq.9: l = ½ log2(A / A_texel); ≤ 0 means the finest level.
float mip_level(float footprint, float texel_area);

// Radiance arriving along ray direction `dir` from a hit (a triangle at eq.9 level for the
// footprint, a proxy's filtered radiance, or the environment on a miss).
glm::vec3 hit_radiance(const Scene& scene, const LodBvh& lod, const TriangleLighting& lighting,
                       const glm::vec3& dir, float solid_angle, const LodHit& hit);

struct HitRadianceStats {
  std::uint64_t triangle_hits = 0, proxy_hits = 0, misses = 0;
};

// Kernel "hit_radiance": the specular layer, width × height: per glossy pixel the lobe's
// albedo E × the weighted mean Σ w L / Σ w of its active samples' radiance (glossy_rays.h),
// zero elsewhere.
ImageRGBA glossy_reflection(par::Executor& executor, const Scene& scene, const LodBvh& lod,
                            const TriangleLighting& lighting, const GlossyRays& rays,
                            const std::vector<LodHit>& hits, HitRadianceStats* stats = nullptr);

}  // namespace speculum::trace
