// The `distance_map_reflect` node: see distance_map_reflect.h.
#include "raster/distance_map_reflect.h"

#include <vector>

#include <glm/geometric.hpp>

#include "core/optics.h"

namespace speculum::raster {

ImageRGBA distance_map_reflect(par::Executor& executor, const GBuffer& g,
                               const EnvironmentMap& env, const ReflectorMaps& maps,
                               const DistanceSearchOptions& options, DistanceReflectStats* stats) {
  constexpr std::size_t kChunk = 2048;
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  std::vector<DistanceReflectStats> per_chunk((out.size() + kChunk - 1) / kChunk);
  executor.parallel_for("distance_map_reflect.search", out.size(), kChunk,
                        [&](std::size_t begin, std::size_t end) {
    DistanceReflectStats& st = per_chunk[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface.pixels[i];
      if (!is_specular(s)) continue;
      const std::uint32_t object = g.object.pixels[i];
      const int m = object < maps.map_of_object.size() ? maps.map_of_object[object] : -1;
      const glm::vec3 x = g.position.pixels[i];
      // Radiance arriving along direction d from x: searched in the object's map, or the
      // environment (at infinity) for objects without one.
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        if (m < 0) return env.radiance(d, exponent);
        const DistanceSearchResult hit = search_distance_map(maps.cubes[m], x, d, options);
        ++st.searches;
        st.lookups += hit.lookups;
        st.bracketed += hit.bracketed;
        return maps.maps[m].radiance(glm::normalize(hit.direction), exponent);
      };
      const glm::vec3 v = g.view_direction(i), incident = -v;
      glm::vec3 n = g.normal.pixels[i];
      glm::vec3 radiance;
      if (s.is_refractor()) {
        const bool entering = glm::dot(n, v) >= 0.0f;
        if (!entering) n = -n;
        const float nu = entering ? s.ior : 1.0f / s.ior;
        const glm::vec3 r = reflect(incident, n);
        glm::vec3 t;
        if (refract(incident, n, nu, t)) {
          const float f = fresnel_schlick(glm::dot(n, v), fresnel_f0(nu));
          radiance = f * lookup(r, 1e6f) + (1.0f - f) * s.base_color * lookup(t, 1e6f);
        } else {
          radiance = lookup(r, 1e6f);  // total internal reflection
        }
      } else {
        const glm::vec3 r = reflect(incident, n);
        radiance = specular_fresnel(s, glm::dot(n, v)) * lookup(r, s.phong_exponent);
      }
      out.pixels[i] = glm::vec4(radiance, 1.0f);
    }
  });
  if (stats)
    for (const DistanceReflectStats& c : per_chunk) {
      stats->searches += c.searches;
      stats->lookups += c.lookups;
      stats->bracketed += c.bracketed;
    }
  return out;
}

}  // namespace speculum::raster
