// The `distance_map_reflect` node: see distance_map_reflect.h.
#include "raster/distance_map_reflect.h"

#include <vector>

#include <glm/geometric.hpp>

#include "raster/specular_radiance.h"

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
      const glm::vec3 radiance =
          specular_radiance(s, g.normal.pixels[i], g.view_direction(i), lookup);
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

ImageRGBA DistanceMapReflectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                            const EnvironmentMap& environment,
                                            const ReflectorMaps& maps) const {
  DistanceReflectStats st;
  ImageRGBA specular = distance_map_reflect(c.executor(), gbuffer, environment, maps, search, &st);
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("bracketed", st.bracketed);
  return specular;
}

}  // namespace speculum::raster
