// The `distance_map_reflect` node: see distance_map_reflect.h.
#include "raster/distance_map_reflect.h"

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "core/sampling.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {

namespace {

// A glossy lobe is searched along several directions, not along R alone: across a wide lobe
// the parallax differs, and one search along R draws the edge of whatever it finds as sharp as
// a mirror would, where the lobe blurs it (SURVEY §4.2 reads the hit's prefiltered colour, which
// blurs the colour but not the edge). The lobe is split into options.lobe_directions sub-lobes
// of half its angle: their axes are a fixed Hamersley set of a Phong lobe of exponent 4n/3 and
// each is read at exponent 4n, so the widths add up to the lobe's (Phong lobes of exponent n
// are close to Gaussians of variance 1/n, and variances add). Lobes narrower than
// kGlossySearchExponent's (under 0.7° at half maximum) are searched along R only.
constexpr float kGlossySearchExponent = 1e4f;

}  // namespace

ImageRGBA distance_map_reflect(par::Executor& executor, const GBuffer& g,
                               const EnvironmentMap& env, const ReflectorMaps& maps,
                               const DistanceSearchOptions& options, DistanceReflectStats* stats,
                               FallbackMask* fallbacks) {
  constexpr std::size_t kChunk = 2048;
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  std::vector<DistanceReflectStats> per_chunk((out.size() + kChunk - 1) / kChunk);
  executor.parallel_for("distance_map_reflect.search", out.size(), kChunk,
                        [&](std::size_t begin, std::size_t end) {
    DistanceReflectStats& st = per_chunk[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      const std::uint32_t object = g.object.pixels[i];
      const int m = object < maps.map_of_object.size() ? maps.map_of_object[object] : -1;
      const glm::vec3 x = g.position.pixels[i];
      // Radiance arriving along direction d from x: searched in the object's map, or the
      // environment (at infinity) for objects without one.
      const glm::vec3 n = g.normal.pixels[i];
      const auto search = [&](const glm::vec3& d, float exponent) {
        const DistanceSearchResult hit = search_distance_map(maps.cubes[m], x, d, options);
        ++st.searches;
        st.lookups += hit.lookups;
        st.bracketed += hit.bracketed;
        st.missed += !std::isfinite(hit.d);
        return maps.maps[m].radiance(glm::normalize(hit.direction), exponent);
      };
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        if (m < 0) return env.radiance(d, exponent);
        const int directions = options.lobe_directions;
        if (directions <= 1 || !(exponent < kGlossySearchExponent)) return search(d, exponent);
        const Onb frame(d);
        glm::vec3 sum(0.0f);
        int used = 0;
        for (int k = 0; k < directions; ++k) {
          const glm::vec3 dk = frame.to_world(sample_phong_lobe(
              hamersley(static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(directions)), exponent * (4.0f / 3.0f)));
          if (glm::dot(dk, n) <= 0.0f) continue;  // below the surface: no light arrives from there
          sum += search(dk, 4.0f * exponent);
          ++used;
        }
        return used > 0 ? sum / float(used) : search(d, exponent);
      };
      const std::uint64_t missed_before = st.missed;
      const glm::vec3 radiance = specular_radiance(s, n, g.view_direction(i), lookup);
      out.pixels[i] = glm::vec4(radiance, 1.0f);
      if (fallbacks && st.missed > missed_before) fallbacks->mark(i, Fallback::search_missed);
    }
  });
  if (stats)
    for (const DistanceReflectStats& c : per_chunk) {
      stats->searches += c.searches;
      stats->lookups += c.lookups;
      stats->bracketed += c.bracketed;
      stats->missed += c.missed;
    }
  return out;
}

ImageRGBA DistanceMapReflectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                            const EnvironmentMap& environment,
                                            const ReflectorMaps& maps) const {
  DistanceReflectStats st;
  FallbackMask fallbacks = c.capturing() ? FallbackMask(gbuffer.width, gbuffer.height) : FallbackMask();
  ImageRGBA specular = distance_map_reflect(c.executor(), gbuffer, environment, maps, search, &st, &fallbacks);
  c.publish("fallback", std::move(fallbacks));
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("bracketed", st.bracketed);
  c.count("fallback_search_missed", st.missed);
  return specular;
}

}  // namespace speculum::raster
