// Forward light (particle) tracing of caustics for the reference tracer. A camera path can
// never find a point or directional light through a mirror or a refractor (the light is a
// point of zero solid angle behind a delta lobe), so the paths light → specular chain →
// surface → eye are traced from the light instead (SURVEY §6: caustics are light that
// specular surfaces concentrate on diffuse ones). Photons are aimed at each caustic generator
// (an object whose material is a mirror or a refractor) through the cone of its bounding
// sphere, follow reflection, refraction with exact Fresnel and total internal reflection, and
// are connected to the camera at every non-delta surface they reach (light tracing: each
// arrival adds its radiance f·Φ·cosθ_x/(r² A_pixel cos³θ_c) to the pixel it projects to).
// Only paths with at least one specular bounce are traced, so nothing the camera paths
// already count (direct light through shadow rays) is counted twice.
//
// Determinism: photon i of (light, generator) draws its random numbers from the
// counter-based hash keyed by (i, light·G + generator, dimension, seed); photons run in
// fixed chunks, each chunk collects its own splats, and the splats are added to the image
// serially in chunk order, so the image is the same bytes for any thread count.
//
// The arrivals also feed the reference's photon map (trace/photon_map.h), which gives the
// caustics a camera path sees after a specular bounce (in a mirror, through glass): a
// direct connection to the eye cannot pass a delta surface. Not traced: glossy (non-delta)
// surfaces as caustic generators, and environment light.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "trace/bvh.h"

namespace speculum::trace {

struct PhotonOptions {
  std::uint64_t photons = 1 << 16;  // per light and caustic generator
  int max_depth = 8;                // specular bounces followed
  std::uint32_t seed = 1;
};

// A caustic generator: an object with a mirror or refractor material and the bounding
// sphere photons are aimed at.
struct CausticGenerator {
  std::uint32_t object = 0;
  glm::vec3 center{0.0f};
  float radius = 0.0f;
};
std::vector<CausticGenerator> caustic_generators(const Scene& scene);

// One photon arrival at a surface after at least one specular bounce.
struct PhotonHit {
  glm::vec3 p{0.0f};
  glm::vec3 ng{0.0f, 1.0f, 0.0f};  // geometric normal, facing the arriving photon
  glm::vec3 wi{0.0f, 1.0f, 0.0f};  // unit, from p back along the photon's last segment
  glm::vec3 flux{0.0f};            // W (linear RGB): the photon's power on arrival
  std::uint32_t triangle = 0;
  std::uint32_t bounces = 0;       // specular bounces before this arrival
};

struct PhotonStats {
  std::uint64_t photons = 0;       // emitted towards generators
  std::uint64_t generator_hits = 0;  // photons whose first hit is their generator
  std::uint64_t arrivals = 0;      // arrivals at non-delta surfaces
  std::uint64_t splats = 0;        // arrivals that reached a pixel (visible to the camera)
  std::uint64_t depth_limited = 0;
};

// Every arrival of the photons of every light × generator, in photon order (for tests and
// density estimates). Kernel "caustic_photons".
std::vector<PhotonHit> trace_caustic_photons(const Scene& scene, const Bvh& bvh, const PhotonOptions& options,
                                             par::Executor& executor, PhotonStats* stats = nullptr);

// The caustic radiance seen by `camera` (width × height, pixel-area averages), by light
// tracing: kernel "caustic_light_trace". Added to the camera paths' image it completes the
// reference.
ImageRGBA render_caustics(const Scene& scene, const Bvh& bvh, const Camera& camera, int width, int height,
                          const PhotonOptions& options, par::Executor& executor, PhotonStats* stats = nullptr);

}  // namespace speculum::trace
