// The `envmap_reflect` node: see envmap_reflect.h.
#include "raster/envmap_reflect.h"

#include <glm/geometric.hpp>

#include "core/fallback_mask.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {
namespace {

template <class MapOf, class Takes>
ImageRGBA reflect_with(par::Executor& executor, const GBuffer& g, const MapOf& map_of, const Takes& takes) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  executor.parallel_for("envmap_reflect.lookup", out.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!takes(s)) continue;
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        return map_of(g.object.pixels[i]).radiance(d, exponent);
      };
      const glm::vec3 radiance =
          specular_radiance(s, g.normal.pixels[i], g.view_direction(i), lookup);
      out.pixels[i] = glm::vec4(radiance, 1.0f);
    }
  });
  return out;
}

}  // namespace

ImageRGBA envmap_reflect(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                         const ReflectorMaps* reflectors) {
  return reflect_with(executor, g, [&](std::uint32_t object) -> const EnvironmentMap& {
    const EnvironmentMap* own = reflectors ? reflectors->for_object(object) : nullptr;
    return own ? *own : env;
  }, [](const SurfaceParams& s) { return is_specular(s); });
}

ImageRGBA refractor_environment(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                                const ReflectorMaps* refractors) {
  return reflect_with(executor, g, [&](std::uint32_t object) -> const EnvironmentMap& {
    const EnvironmentMap* own = refractors ? refractors->for_object(object) : nullptr;
    return own ? *own : env;
  }, [](const SurfaceParams& s) { return s.is_refractor(); });
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
