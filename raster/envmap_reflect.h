// The `envmap_reflect` node: SURVEY §3.1 environment mapping — each specular sample looks
// up the environment cube along its mirror direction R (glossy: the prefiltered level of
// its Phong lobe) and, for refractors, along the refracted direction T (single interface),
// weighted by Schlick's Fresnel (SURVEY eq.2). No parallax: exact only for an environment
// at infinity, which is the technique's known limitation.
#pragma once

#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"

namespace speculum::raster {

// The specular layer: F·L(R) (+ (1−F)·base·L(T) for refractors); zero on diffuse samples.
// A sample of a reflector with its own dynamic map in `reflectors` (may be null) looks up
// that map, any other the environment.
ImageRGBA envmap_reflect(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                         const ReflectorMaps* reflectors = nullptr);
// composite(direct, envmap_reflect(g, env)) written over `direct` (the same bytes, without
// the specular layer's image): the cube faces' shading.
void envmap_reflect_onto(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env, ImageRGBA& direct);

// Pass "envmap_reflect": the specular layer from the reflectors' cube maps or the environment.
struct EnvmapReflectPass {
  static constexpr const char* description =
      "Looks up the reflected (or refracted) direction in the reflector's own cube map, or the "
      "environment, weighted by Schlick Fresnel; no parallax, exact only for a distant "
      "environment (SURVEY §3.1, eq.2).";
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const EnvironmentMap& environment,
                       const ReflectorMaps* maps) const;
};

// The fallback of techniques that do not follow refraction (yu-lod traces reflections only):
// refractor samples get the light along R and T as envmap_reflect computes them — from the
// refractor's own cube map in `refractors` when it has one, else the environment — every
// other sample 0.
ImageRGBA refractor_environment(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                                const ReflectorMaps* refractors = nullptr);

// Pass "refractor_environment".
struct RefractorEnvironmentPass {
  static constexpr const char* description =
      "Refractor samples only: the refractor's own cube map (or the environment) along the "
      "reflected and refracted directions, Fresnel-weighted (SURVEY §3.1) — the documented "
      "fallback of a technique that traces reflections only, so glass is never black.";
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const EnvironmentMap& environment,
                       const ReflectorMaps* refractor_maps) const;
};

}  // namespace speculum::raster
