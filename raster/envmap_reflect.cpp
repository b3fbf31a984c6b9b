// The `envmap_reflect` node: see envmap_reflect.h.
#include "raster/envmap_reflect.h"

#include <glm/geometric.hpp>

#include "core/optics.h"

namespace speculum::raster {
namespace {

template <class MapOf>
ImageRGBA reflect_with(par::Executor& executor, const GBuffer& g, const MapOf& map_of) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  executor.parallel_for("envmap_reflect.lookup", out.size(), 4096,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface.pixels[i];
      if (!is_specular(s)) continue;
      const glm::vec3 v = g.view_direction(i), incident = -v;
      glm::vec3 n = g.normal.pixels[i];
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        return map_of(g.object.pixels[i]).radiance(d, exponent);
      };
      glm::vec3 radiance;
      if (s.is_refractor()) {
        // Entering when the normal faces the viewer; leaving flips n and the index ratio.
        const bool entering = glm::dot(n, v) >= 0.0f;
        if (!entering) n = -n;
        const float nu = entering ? s.ior : 1.0f / s.ior;
        const glm::vec3 r = reflect(incident, n);
        glm::vec3 t;
        const float cos_i = glm::dot(n, v);
        if (refract(incident, n, nu, t)) {
          // Schlick with F0 of the interface; past the critical angle F = 1 (TIR).
          const float f = fresnel_schlick(cos_i, fresnel_f0(nu));
          radiance = f * lookup(r, 1e6f) + (1.0f - f) * s.base_color * lookup(t, 1e6f);
        } else {
          radiance = lookup(r, 1e6f);
        }
      } else {
        const glm::vec3 r = reflect(incident, n);
        radiance = specular_fresnel(s, glm::dot(n, v)) * lookup(r, s.phong_exponent);
      }
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
  });
}

}  // namespace speculum::raster
