// Layered distance maps (SURVEY §4.5, after UPSK07): the whole scene
// depth-peeled into L cube layers around a reference point o — per texel the k-th nearest
// surface along the texel's direction, with its distance, normal, material and direct-lit
// colour — and a recursive tracer that searches every layer (linear + secant, as in
// distance_map_search.h) for the nearest hit and continues at specular hits.
// Peeling here is a k-buffer: each texel's ray from o keeps the L nearest triangle hits.
#pragma once

#include <array>
#include <vector>

#include "core/fallback_mask.h"
#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"
#include "raster/distance_map_search.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

struct CubeLayer {
  std::array<GBuffer, kCubeFaces> surface;  // position, normal, material, object per texel
  std::array<ImageF, kCubeFaces> distance;  // |y − o|, +inf where the layer is empty
  std::array<ImageRGBA, kCubeFaces> colour; // direct light + ambient towards o
};

struct LayeredDistanceMap {
  int size = 0;
  glm::vec3 centre{0.0f};
  std::vector<CubeLayer> layers;  // layer 0 nearest
};

struct LayeredMapOptions {
  int size = 128;
  int layers = 3;
};

// Peels `options.layers` layers around `centre` and shades each with direct light.
LayeredDistanceMap render_layered_distance_map(par::Executor& executor, const Scene& scene,
                                               const glm::vec3& centre,
                                               const std::vector<ShadowMap>& shadows,
                                               const EnvironmentMap& env,
                                               const LayeredMapOptions& options);

struct LayeredTraceOptions {
  int linear_steps = 16;
  int secant_steps = 4;
  int bounces = 2;              // specular hits followed (1: single reflection)
  float hit_tolerance = 0.03f;  // |1 − |l|/|l'|| accepted after refinement (rejects brackets
                                // that straddle a depth discontinuity of one layer)
};

struct LayeredTraceStats {
  std::uint64_t rays = 0;
  std::uint64_t lookups = 0;
  std::uint64_t misses = 0;  // rays that found no layer hit (environment used)
  std::uint64_t depth_exhausted = 0;  // continuations past the last bounce (environment used)
};

// Radiance arriving at x from direction r (unit) through the layered map.
glm::vec3 trace_layered(const LayeredDistanceMap& map, const EnvironmentMap& env,
                        const glm::vec3& x, const glm::vec3& r, const LayeredTraceOptions& options,
                        int depth, LayeredTraceStats& stats);

// The specular layer of a G-buffer: F · trace_layered along R for specular samples (glossy
// lobes use their mirror direction); refractors add (1 − F) × their tint times the refracted
// ray, traced through the same layers.
// `fallbacks` (may be null or empty) marks the samples whose paths missed or ran out of bounces.
ImageRGBA layered_reflect(par::Executor& executor, const GBuffer& g, const LayeredDistanceMap& map,
                          const EnvironmentMap& env, const LayeredTraceOptions& options,
                          LayeredTraceStats* stats = nullptr, FallbackMask* fallbacks = nullptr);

// Pass "layered_distance_map": the scene peeled into layers around `centre`.
struct LayeredDistanceMapPass {
  static constexpr const char* description =
      "The whole scene depth-peeled into L cube layers (material, distance, normal, direct-lit "
      "colour) around one reference point (SURVEY §4.5).";
  const Scene* scene = nullptr;
  glm::vec3 centre{0.0f};
  LayeredMapOptions options;
  void parameters(par::Params& p) const { p.set("layers", options.layers).set("size", options.size); }
  LayeredDistanceMap operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                const EnvironmentMap& environment) const;
};

// Pass "layered_reflect": the specular layer traced through the layered map.
struct LayeredReflectPass {
  static constexpr const char* description =
      "Recursive tracer: linear + secant search in every layer, nearest hit, continued at "
      "specular hits up to the bounce limit (SURVEY §4.5).";
  LayeredTraceOptions options;
  void parameters(par::Params& p) const {
    p.set("linear_steps", options.linear_steps).set("secant_steps", options.secant_steps)
        .set("bounces", options.bounces);
  }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const LayeredDistanceMap& map,
                       const EnvironmentMap& environment) const;
};

}  // namespace speculum::raster
