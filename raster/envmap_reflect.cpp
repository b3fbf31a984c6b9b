// The `envmap_reflect` node: see envmap_reflect.h.
#include "raster/envmap_reflect.h"

#include <glm/geometric.hpp>

#include "core/fallback_mask.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {
namespace {

// Every sample i of `g`: shaded(i, radiance) with the radiance along R (and T) from
// map_of(object) where takes(surface), else unshaded(i).
template <class MapOf, class Takes, class Shaded, class Unshaded>
void reflect_with(par::Executor& executor, const GBuffer& g, const MapOf& map_of, const Takes& takes,
                  const Shaded& shaded, const Unshaded& unshaded) {
  executor.parallel_for("envmap_reflect.lookup", g.object.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    // Consecutive samples reading one map have up to eight lookups made together
    // (radiance8, each with radiance's bits), then each sample's radiance from its own.
    constexpr int kBatch = 8;
    SpecularLookups plan[kBatch] = {};
    std::size_t sample[kBatch];
    glm::vec3 direction[kBatch], found[kBatch];
    float exponent[kBatch];
    int samples = 0, lookups = 0;
    const EnvironmentMap* batch_map = nullptr;
    const auto flush = [&] {
      if (samples == 0) return;
      batch_map->radiance8(direction, exponent, lookups, found);
      for (int k = 0, next = 0; k < samples; next += plan[k].count, ++k) shaded(sample[k], plan[k].radiance(found + next));
      samples = lookups = 0;
    };
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i) || !takes(g.surface[i])) {
        unshaded(i);
        continue;
      }
      const SpecularLookups lookup(g.surface[i], g.normal.pixels[i], g.view_direction(i));
      const EnvironmentMap& map = map_of(g.object.pixels[i]);
      if (&map != batch_map || lookups + lookup.count > kBatch) flush();
      batch_map = &map;
      for (int k = 0; k < lookup.count; ++k)
        direction[lookups] = lookup.direction[k], exponent[lookups] = lookup.exponent[k], ++lookups;
      plan[samples] = lookup;
      sample[samples++] = i;
    }
    flush();
  });
}

template <class MapOf, class Takes>
ImageRGBA reflect_with(par::Executor& executor, const GBuffer& g, const MapOf& map_of, const Takes& takes) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  reflect_with(
      executor, g, map_of, takes, [&](std::size_t i, const glm::vec3& radiance) { out.pixels[i] = glm::vec4(radiance, 1.0f); },
      [](std::size_t) {});
  return out;
}

// Each sample's map, or the environment.
auto own_map_or(const EnvironmentMap& env, const ReflectorMaps* reflectors) {
  return [&env, reflectors](std::uint32_t object) -> const EnvironmentMap& {
    const EnvironmentMap* own = reflectors ? reflectors->for_object(object) : nullptr;
    return own ? *own : env;
  };
}

}  // namespace

ImageRGBA envmap_reflect(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                         const ReflectorMaps* reflectors) {
  return reflect_with(executor, g, own_map_or(env, reflectors), [](const SurfaceParams& s) { return is_specular(s); });
}

void envmap_reflect_onto(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env, ImageRGBA& direct) {
  // composite's sum, direct + specular with the specular layer 0 where nothing is reflected.
  reflect_with(
      executor, g, own_map_or(env, nullptr), [](const SurfaceParams& s) { return is_specular(s); },
      [&](std::size_t i, const glm::vec3& radiance) {
        direct.pixels[i] = glm::vec4(glm::vec3(direct.pixels[i]) + radiance, 1.0f);
      },
      [&](std::size_t i) { direct.pixels[i] = glm::vec4(glm::vec3(direct.pixels[i]) + glm::vec3(0.0f), 1.0f); });
}

ImageRGBA refractor_environment(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                                const ReflectorMaps* refractors) {
  return reflect_with(executor, g, own_map_or(env, refractors), [](const SurfaceParams& s) { return s.is_refractor(); });
}

ImageRGBA RefractorEnvironmentPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                               const EnvironmentMap& environment,
                                               const ReflectorMaps* refractor_maps) const {
  std::uint64_t refractor_samples = 0;
  FallbackMask fallbacks = c.capturing() ? FallbackMask(gbuffer.width, gbuffer.height) : FallbackMask();
  for (std::size_t i = 0; i < gbuffer.surface.size(); ++i)
    if (gbuffer.covered(i) && gbuffer.surface[i].is_refractor()) {
      ++refractor_samples;
      fallbacks.mark(i, Fallback::refractor_environment);
    }
  c.count("fallback_refractor_environment", refractor_samples);
  c.publish("fallback", std::move(fallbacks));
  return refractor_environment(c.executor(), gbuffer, environment, refractor_maps);
}

ImageRGBA EnvmapReflectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                       const EnvironmentMap& environment,
                                       const ReflectorMaps* maps) const {
  return envmap_reflect(c.executor(), gbuffer, environment, maps);
}

}  // namespace speculum::raster
