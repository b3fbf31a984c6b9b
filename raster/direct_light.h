// The `direct_light` node: radiance of every G-buffer sample from the scene's punctual
// lights (core/shading.h model, shadowed by filtered shadow maps), ambient light from the
// environment's SH irradiance, emission, and the environment behind empty samples.
#pragma once

#include <vector>

#include "core/scene.h"
#include "core/shading.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

// The radiance a surface point sends towards v (unit, towards the viewer): emission, every
// light × its shadow-map visibility, the environment's SH irradiance on the diffuse lobe and,
// on surfaces too rough for a reflection pass, the prefiltered environment along R
// (core/shading.h). n is the unit shading normal, turned here to face v. What direct_light
// computes for each G-buffer sample, and what a traced hit gets when it must be shaded the
// same way.
glm::vec3 shade_surface(const Scene& scene, const SurfaceParams& s, const glm::vec3& p, glm::vec3 n,
                        const glm::vec3& v, const std::vector<ShadowMap>& shadows, const EnvironmentMap& env);

// shade_surface for the many points of one pass: each light's constants computed once
// (core/shading.h LightSampler) and each point's viewer terms once for all lights
// (core/brdf.h BrdfAtView); operator() gives shade_surface's bits.
class SurfaceShader {
 public:
  SurfaceShader(const Scene& scene, const std::vector<ShadowMap>& shadows, const EnvironmentMap& env);
  glm::vec3 operator()(const SurfaceParams& s, const glm::vec3& p, glm::vec3 n, const glm::vec3& v) const;
  // The same for `count` (1..8) points, out[j] for s[j], p[j], n[j], v[j]: each light's
  // shadow tests of the points it reaches in one ShadowMap::visibility_lanes call.
  void shade8(const SurfaceParams* const* s, const glm::vec3* p, const glm::vec3* n, const glm::vec3* v, int count,
              glm::vec3* out) const;
  // The samples i in [begin, end) of `g` with wanted(i): each covered one shaded (eight at a
  // time through shade8) and handed to shaded(i, radiance), each empty one to empty(i).
  template <class Wanted, class Shaded, class Empty>
  void shade_samples(const GBuffer& g, std::size_t begin, std::size_t end, const Wanted& wanted,
                     const Shaded& shaded, const Empty& empty) const {
    std::size_t batch[8];
    int count = 0;
    const auto shade_batch = [&] {
      const SurfaceParams* s[8];
      glm::vec3 p[8], n[8], v[8], radiance[8];
      for (int j = 0; j < count; ++j) {
        const std::size_t i = batch[j];
        s[j] = &g.surface[i], p[j] = g.position.pixels[i], n[j] = g.normal.pixels[i], v[j] = g.view_direction(i);
      }
      shade8(s, p, n, v, count, radiance);
      for (int j = 0; j < count; ++j) shaded(batch[j], radiance[j]);
      count = 0;
    };
    for (std::size_t i = begin; i < end; ++i) {
      if (!wanted(i)) continue;
      if (!g.covered(i)) {
        empty(i);
        continue;
      }
      batch[count++] = i;
      if (count == 8) shade_batch();
    }
    if (count > 0) shade_batch();
  }

 private:
  const Scene* scene_;
  const std::vector<ShadowMap>* shadows_;
  const EnvironmentMap* env_;
  std::vector<LightSampler> lights_;
};

// `camera` is the one the G-buffer was rendered with (for background directions).
// `shadows` may be empty: lights are then unshadowed. `read` (may be null) flags the samples
// wanted; the others are left black (the texels of a cube face no reader reaches).
ImageRGBA direct_light(par::Executor& executor, const Scene& scene, const GBuffer& g,
                       const Camera& camera, const std::vector<ShadowMap>& shadows,
                       const EnvironmentMap& env, const std::vector<std::uint8_t>* read = nullptr);

// Pass "direct_light": the diffuse and glossy response to every light, plus ambient.
struct DirectLightPass {
  static constexpr const char* description =
      "Direct light from every scene light with shadow-map visibility, plus SH ambient from the "
      "environment, with the one shading model shared with the reference (SURVEY §3.1 diffuse part).";
  const Scene* scene = nullptr;
  Camera camera;
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const ShadowMaps& shadows,
                       const EnvironmentMap& environment) const;
};

}  // namespace speculum::raster
