// The reference tracer: the ground truth every technique is compared with (an error figure
// per technique against it, on the same scene and camera). Primary visibility; direct
// light from every punctual light with traced shadow rays; Whitted recursion for mirrors
// and smooth refractors (exact dielectric Fresnel, total internal reflection) to a depth
// limit; glossy reflection by importance sampling the normalized Phong lobe (YU eq.4, one
// lobe sample per path sample); environment on miss; optionally environment light on
// diffuse surfaces (cosine samples, occluded by geometry, no interreflection). Shading
// follows core/shading.h. Random numbers are keyed by (pixel, sample, dimension, seed), so
// the image is bit-identical for any thread count; the error falls like 1/sqrt(spp).
#pragma once

#include <cstdint>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "trace/bvh.h"

namespace speculum::trace {

struct ReferenceOptions {
  int width = 512;
  int height = 512;
  int spp = 64;                     // path samples per pixel
  int max_depth = 8;                // specular bounces (mirror, glossy, refraction)
  std::uint32_t seed = 1;
  bool pixel_jitter = false;        // false: every sample through the pixel centre, as the
                                    // rasterizer samples; true: box-filtered pixel area
  bool environment_lighting = true; // diffuse surfaces lit by the (occluded) environment
  // Caustics by forward light tracing (trace/light_tracer.h): photons per light and caustic
  // generator; 0 leaves them out (camera paths alone cannot reach a point light through a
  // mirror or a refractor). Seen after a specular bounce they come from a photon map of up
  // to 2^20 photons per light and generator (trace/photon_map.h).
  std::uint64_t caustic_photons = 0;
};

// Counters of one render (integers, summed in chunk order).
struct ReferenceStats {
  std::uint64_t camera_rays = 0, shadow_rays = 0, specular_rays = 0;
  std::uint64_t below_horizon = 0;   // glossy lobe samples under the surface: contribute 0
  std::uint64_t depth_limited = 0;   // specular paths cut by max_depth
  std::uint64_t stack_overflows = 0;
  std::uint64_t caustic_photons = 0, caustic_splats = 0;  // light tracing (caustic_photons > 0)
};

// Renders with a BVH built from scene.mesh on the executor (kernel "reference_render").
// Throws InputError for a degenerate camera or size.
ImageRGBA render_reference(const Scene& scene, const Camera& camera, const ReferenceOptions& options,
                           par::Executor& executor, ReferenceStats* stats = nullptr);
// The same with a prebuilt BVH over scene.mesh.
ImageRGBA render_reference(const Scene& scene, const Bvh& bvh, const Camera& camera,
                           const ReferenceOptions& options, par::Executor& executor,
                           ReferenceStats* stats = nullptr);

// Pass "reference_trace": the whole frame's linear radiance by the reference tracer.
struct ReferencePass {
  static constexpr const char* description =
      "Ground truth: ray tracing in the original geometry on the BVH, with camera, shadow and "
      "specular/glossy rays and spp jittered samples per pixel (SURVEY §2), plus caustics of "
      "punctual lights by forward light tracing through mirrors and refractors (SURVEY §6).";
  const Scene* scene = nullptr;
  Camera camera;
  ReferenceOptions options;
  void parameters(par::Params& p) const {
    p.set("spp", options.spp).set("seed", options.seed).set("caustic_photons", static_cast<double>(options.caustic_photons));
  }
  ImageRGBA operator()(par::NodeContext& c) const;
};

}  // namespace speculum::trace
