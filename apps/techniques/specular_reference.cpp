// The specular-reference technique's recipe: the feed-forward techniques' own G-buffer and
// direct light, with the specular layer computed exactly — reflected/refracted rays traced
// through the BVH to the closest hit, each hit shaded exactly as direct_light shades a visible
// surface (shadow maps, SH ambient; the environment map on a miss) — what the feed-forward
// techniques' reflected images hold — to `bounces` specular bounces; glossy lobes sampled to
// convergence. Against it, a technique's error on specular pixels is its own
// approximation of the specular term, free of the differences of shadow maps and sampling
// that dominate the frame error against `reference` (the way SOFF §5 measured against a ray
// tracer with the same shading). See recipes.h.
#include <algorithm>
#include <string>
#include <vector>

#include "apps/techniques/frame_passes.h"
#include "apps/techniques/gbuffer_rays.h"
#include "apps/techniques/recipes.h"
#include "core/ray_offset.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "raster/direct_light.h"
#include "trace/bvh.h"
#include "trace/hit_surface.h"
#include "trace/secondary_rays.h"
#include "trace/traversal.h"

namespace speculum::pipeline {

namespace {

// Generation `sample` of the glossy lobes: one GGX visible-normal sample per glossy pixel
// (Cranley-Patterson-rotated Hammersley, so every pixel's N samples stratify the lobe),
// weighted F(V·H) G2/G1 / N — the estimator the reference tracer uses (core/brdf.h).
trace::SecondaryRays glossy_generation(par::Executor& ex, const raster::GBuffer& g, int sample, int samples,
                                       std::uint32_t seed) {
  trace::SecondaryRays out = trace::empty_generation(g.width, g.height);
  const std::size_t n = out.active.size();
  ex.parallel_for("glossy_lobe_rays", n, 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (s.is_refractor() || !s.is_glossy_lobe()) continue;
      const glm::vec2 u = rotate_unit_square(hamersley(std::uint32_t(sample), std::uint32_t(samples)),
                                             random_float2(std::uint32_t(i), 0, 0, seed));
      const LobeSample lobe = sample_specular_lobe(s, g.normal.pixels[i], g.view_direction(i), u);
      if (lobe.weight == glm::vec3(0.0f)) continue;  // below the horizon: contributes 0
      Ray r;
      r.origin = offset_ray_origin(g.position.pixels[i], g.normal.pixels[i]);
      r.direction = lobe.direction;
      out.rays.set(i, r);
      out.active[i] = 1;
      out.weight[i] = lobe.weight / float(samples);
    }
  });
  trace::count_active(out);
  return out;
}

// A generation's hits shaded exactly as direct_light shades a G-buffer sample
// (raster::shade_surface) and a miss as the environment map gives it, weighted and added to
// `out`: the hit shading of the feed-forward techniques' reflected images, so only the ray
// differs. Kernel "specular_shade_hits".
void shade_hits_like_direct_light(par::Executor& ex, const Scene& scene, const trace::SecondaryRays& gen,
                                  const trace::HitStream& hits, const raster::ShadowMaps& shadows,
                                  const raster::EnvironmentMap& env, ImageRGBA& out) {
  ex.parallel_for("specular_shade_hits", gen.active.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!gen.active[i]) continue;
      const glm::vec3 dir = glm::normalize(gen.rays.get(i).direction);
      glm::vec3 radiance(0.0f);
      if (hits.triangle[i] == trace::kNoHit) {
        radiance = env.radiance(dir, 1e6f);
      } else {
        const trace::HitSurface hs =
            trace::hit_surface(scene, trace::Hit{hits.t[i], hits.u[i], hits.v[i], hits.triangle[i]}, dir);
        radiance = raster::shade_surface(scene, hs.s, hs.p, hs.n, -dir, shadows, env);
      }
      out.pixels[i] += glm::vec4(gen.weight[i] * radiance, 0.0f);
    }
  });
}

// Pass "specular_trace": the exact specular layer (width·k × height·k, like the G-buffer).
struct SpecularTracePass {
  static constexpr const char* description =
      "Exact specular layer: one reflected/refracted ray per mirror or refractor pixel and N GGX "
      "visible-normal samples per glossy pixel, traced through the BVH to the closest hit, hits "
      "shaded as direct_light shades (shadow maps, SH ambient), followed for the given bounces.";
  const Scene* scene = nullptr;
  int bounces = 1;
  int glossy_samples = 256;
  std::uint32_t seed = 0;
  void parameters(par::Params& p) const { p.set("bounces", bounces).set("glossy_samples", glossy_samples); }

  ImageRGBA operator()(par::NodeContext& c, const raster::GBuffer& g, const raster::ShadowMaps& shadows,
                       const raster::EnvironmentMap& env) const {
    par::Executor& ex = c.executor();
    const trace::Bvh bvh = trace::Bvh::build(scene->mesh, ex);
    ImageRGBA out(g.width, g.height, glm::vec4(0.0f));
    std::uint64_t rays = 0;
    // Follows one first generation through its bounces, adding the shaded hits to `out`.
    auto follow = [&](trace::SecondaryRays gen) {
      for (int b = 1; b <= bounces && gen.count > 0; ++b) {
        rays += gen.count;
        trace::HitStream hits;
        trace::closest_hit_stream(bvh, gen.rays, hits, ex);
        shade_hits_like_direct_light(ex, *scene, gen, hits, shadows, env, out);
        if (b < bounces) gen = trace::bounce_rays(ex, *scene, gen, hits);
      }
    };
    // Mirrors and refractors: the one exact ray of secondary_rays (glossy pixels excluded:
    // their lobe is sampled below).
    trace::SecondaryRays first = trace::secondary_rays(ex, g.position, g.normal, g.surface, g.object, g.eye);
    for (std::size_t i = 0; i < first.active.size(); ++i) {
      const SurfaceParams& s = g.surface[i];
      if (first.active[i] && !s.is_refractor() && s.is_glossy_lobe()) first.active[i] = 0, --first.count;
    }
    follow(std::move(first));
    for (int k = 0; k < glossy_samples; ++k) follow(glossy_generation(ex, g, k, glossy_samples, seed));
    c.count("rays", double(rays));
    return out;
  }
};

}  // namespace

FrameOutputs add_specular_reference_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const SurfaceResources s = add_surface_passes(g, scene, f);
  SpecularTracePass pass{scene, std::max(1, f.bounces), static_cast<int>(f.param("glossy_samples")), f.seed};
  auto specular = g.add("specular_trace", pass, s.gbuffer, s.shadow_maps, s.environment);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
