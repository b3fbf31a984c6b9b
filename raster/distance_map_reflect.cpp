// The `distance_map_reflect` node: see distance_map_reflect.h.
#include "raster/distance_map_reflect.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
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

// Sub-lobe searches handed to a search callback at once.
constexpr int kLobeBatch = 8;

// The radiance arriving along d through a lobe of `exponent` at a sample with normal n, from
// `search(directions, count, exponent, radiance)`: into radiance[j] the radiance one search
// along directions[j] (j < count ≤ kLobeBatch) finds, read through a lobe of that exponent.
// Every user walks the same searches in the same order. `averaged` (may be null) is set to the
// number of searches averaged (0: the value is one search's).
template <class Search>
glm::vec3 searched_lookup(const glm::vec3& n, const glm::vec3& d, float exponent, SubLobeAxes& axes, Search&& search,
                          int* averaged = nullptr) {
  if (averaged) *averaged = 0;
  glm::vec3 along_d;
  const int directions = axes.count();
  if (directions <= 1 || !(exponent < kGlossySearchExponent)) {
    search(&d, 1, exponent, &along_d);
    return along_d;
  }
  const Onb frame(d);
  const glm::vec3* local = axes(exponent);
  glm::vec3 batch[kLobeBatch], found[kLobeBatch];
  int batched = 0;
  glm::vec3 sum(0.0f);
  int used = 0;
  const auto flush = [&] {
    search(batch, batched, 4.0f * exponent, found);
    for (int j = 0; j < batched; ++j) sum += found[j];
    used += batched;
    batched = 0;
  };
  for (int k = 0; k < directions; ++k) {
    const glm::vec3 dk = frame.to_world(local[k]);
    if (glm::dot(dk, n) <= 0.0f) continue;  // below the surface: no light arrives from there
    batch[batched++] = dk;
    if (batched == kLobeBatch) flush();
  }
  if (batched > 0) flush();
  if (used > 0) {
    if (averaged) *averaged = used;
    return sum / float(used);
  }
  search(&d, 1, exponent, &along_d);
  return along_d;
}

// The map of sample i's object (-1: none, the environment instead).
int map_of_sample(const GBuffer& g, const ReflectorMaps& maps, std::size_t i) {
  const std::uint32_t object = g.object.pixels[i];
  return object < maps.map_of_object.size() ? maps.map_of_object[object] : -1;
}

// The searches from points[j] along directions[j], j < count ≤ kLobeBatch, in map m, counted
// in `st`: into found[j] the direction search j reads its colour along. Returns bit j set for
// each search that missed.
unsigned search_counted(const ReflectorMaps& maps, int m, const glm::vec3* points, const glm::vec3* directions,
                        int count, const DistanceSearchOptions& options, DistanceReflectStats& st, glm::vec3* found) {
  DistanceSearchResult hits[kLobeBatch];
  search_distance_map8(maps.cubes[static_cast<std::size_t>(m)], points, directions, count, options, hits);
  unsigned missed = 0;
  for (int j = 0; j < count; ++j) {
    ++st.searches;
    st.lookups += hits[j].lookups;
    st.bracketed += hits[j].bracketed;
    if (!std::isfinite(hits[j].d)) ++st.missed, missed |= 1u << j;
    found[j] = glm::normalize(hits[j].direction);
  }
  return missed;
}

// search_counted from one point x along every direction.
unsigned search_counted(const ReflectorMaps& maps, int m, const glm::vec3& x, const glm::vec3* directions, int count,
                        const DistanceSearchOptions& options, DistanceReflectStats& st, glm::vec3* found) {
  glm::vec3 points[kLobeBatch];
  std::fill(points, points + count, x);
  return search_counted(maps, m, points, directions, count, options, st, found);
}

// The colour the searches found along directions[0..count), read through lobes of exponent
// e: eight lookups at once (radiance8, the bits of one at a time).
void read_colour(const EnvironmentMap& map, const glm::vec3* directions, int count, float e, glm::vec3* radiance) {
  float exponents[kLobeBatch];
  std::fill(exponents, exponents + count, e);
  map.radiance8(directions, exponents, count, radiance);
}

// Chunks' counts summed in chunk order.
void add_stats(DistanceReflectStats& to, const std::vector<DistanceReflectStats>& per_chunk) {
  for (const DistanceReflectStats& c : per_chunk) to += c;
}

// What a node that searches publishes: the samples whose search missed (when inspected) and
// the searches' counters.
void publish_searches(par::NodeContext& c, const DistanceReflectStats& st, FallbackMask&& fallbacks) {
  c.publish("fallback", std::move(fallbacks));
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("bracketed", st.bracketed);
  c.count("fallback_search_missed", st.missed);
}

// Samples per chunk of the searches; distance_map_lookup reads distance_map_search's records
// in the same chunks.
constexpr std::size_t kChunk = 2048;

}  // namespace

const glm::vec3* SubLobeAxes::operator()(float exponent) {
  if (!(exponent == exponent_)) {
    exponent_ = exponent;
    const auto count = static_cast<std::uint32_t>(local_.size());
    for (std::uint32_t k = 0; k < count; ++k)
      local_[k] = sample_phong_lobe(hamersley(k, count), exponent * (4.0f / 3.0f));
  }
  return local_.data();
}

ImageRGBA distance_map_reflect(par::Executor& executor, const GBuffer& g,
                               const EnvironmentMap& env, const ReflectorMaps& maps,
                               const DistanceSearchOptions& options, DistanceReflectStats* stats,
                               FallbackMask* fallbacks) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  std::vector<DistanceReflectStats> per_chunk(par::Executor::chunk_count(out.size(), kChunk));
  executor.parallel_for("distance_map_reflect.search", out.size(), kChunk,
                        [&](std::size_t begin, std::size_t end) {
    DistanceReflectStats& st = per_chunk[begin / kChunk];
    SubLobeAxes axes(options.lobe_directions);
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      const int m = map_of_sample(g, maps, i);
      const glm::vec3 x = g.position.pixels[i], n = g.normal.pixels[i];
      // Radiance arriving along d from x: searched in the object's map, or the environment
      // (at infinity) for objects without one.
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        if (m < 0) return env.radiance(d, exponent);
        return searched_lookup(n, d, exponent, axes,
                               [&](const glm::vec3* dk, int count, float e, glm::vec3* radiance) {
          glm::vec3 found[kLobeBatch];
          search_counted(maps, m, x, dk, count, options, st, found);
          read_colour(maps.maps[m], found, count, e, radiance);
        });
      };
      const std::uint64_t missed_before = st.missed;
      out.pixels[i] = glm::vec4(specular_radiance(s, n, g.view_direction(i), lookup), 1.0f);
      if (fallbacks && st.missed > missed_before) fallbacks->mark(i, Fallback::search_missed);
    }
  });
  if (stats) add_stats(*stats, per_chunk);
  return out;
}

namespace {

// The map sample i of g searches in when its object id is `object` (-1: none: not covered, not
// specular, or no map).
int searched_map(const GBuffer& g, std::uint32_t object, const ReflectorMaps& maps, std::size_t i) {
  if (object == kNoId || !is_specular(g.surface[i])) return -1;
  return object < maps.map_of_object.size() ? maps.map_of_object[object] : -1;
}

// distance_map_search, and distance_map_search_reusing when `earlier_object` is not null: the
// samples searched under both object planes take their directions from `earlier` instead of
// searching again. Each chunk walks `earlier`'s records of the chunk in sample order beside its
// own, so a sample searched only under earlier_object replays its lookups to skip its records.
DistanceSearches search_samples(par::Executor& executor, const GBuffer& g, const ReflectorMaps& maps,
                                const DistanceSearchOptions& options, FallbackMask* fallbacks,
                                std::vector<CubeTileMask>* mark_into, const IdBuffer* earlier_object,
                                const DistanceSearches* earlier) {
  DistanceSearches out;
  const std::size_t n = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  out.found.resize(par::Executor::chunk_count(n, kChunk));
  if (earlier_object && (earlier_object->size() != n || earlier->found.size() != out.found.size()))
    throw std::logic_error("distance_map_search_reusing: the earlier searches are of another G-buffer's size");
  if (!mark_into) out.tiles = tile_masks_for_reads(maps);
  std::vector<CubeTileMask>& tiles = mark_into ? *mark_into : out.tiles;
  std::vector<DistanceReflectStats> per_chunk(out.found.size());
  executor.parallel_for("distance_map_search.search", n, kChunk, [&](std::size_t begin, std::size_t end) {
    DistanceReflectStats& st = per_chunk[begin / kChunk];
    std::vector<glm::vec3>& found = out.found[begin / kChunk];
    const glm::vec3* before = earlier_object ? earlier->found[begin / kChunk].data() : nullptr;
    std::vector<LookupTileMarker> markers;
    for (std::size_t m = 0; m < maps.cubes.size(); ++m) markers.emplace_back(tiles[m], maps.levels[m]);
    SubLobeAxes axes(options.lobe_directions);
    // A lookup's single searches (a mirror's, or any lobe searched along its axis alone) are
    // gathered in sample order (their directions' places in `found` kept) and made eight at a
    // time along runs of one map after the chunk's samples, sharing their secant steps' lanes.
    struct Request {
      glm::vec3 x, r;
      int map;
      float exponent;
      std::size_t slot, sample;
    };
    std::vector<Request> requests;
    requests.reserve(end - begin);
    for (std::size_t i = begin; i < end; ++i) {
      const int m_now = searched_map(g, g.object.pixels[i], maps, i);
      const int m_before = earlier_object ? searched_map(g, earlier_object->pixels[i], maps, i) : -1;
      if (m_now < 0 && m_before < 0) continue;
      const int m = m_now >= 0 ? m_now : m_before;
      const glm::vec3 x = g.position.pixels[i], n = g.normal.pixels[i];
      const auto lookup = [&](const glm::vec3& d, float exponent) {
        return searched_lookup(n, d, exponent, axes,
                               [&](const glm::vec3* dk, int count, float e, glm::vec3* radiance) {
          if (m_before >= 0) {
            for (int j = 0; j < count && m_now >= 0; ++j) {
              found.push_back(before[j]);
              markers[m].mark(before[j], e);
            }
            before += count;
          } else if (count > 1) {  // a glossy lobe's sub-lobe searches share their secant steps' lanes
            glm::vec3 along[kLobeBatch];
            if (search_counted(maps, m, x, dk, count, options, st, along) && fallbacks)
              fallbacks->mark(i, Fallback::search_missed);
            for (int j = 0; j < count; ++j) {
              found.push_back(along[j]);
              markers[m].mark(along[j], e);
            }
          } else {
            requests.push_back({x, dk[0], m, e, found.size(), i});
            found.emplace_back(0.0f);
          }
          std::fill(radiance, radiance + count, glm::vec3(0.0f));
        });
      };
      // Its value is not needed here: it makes the lookups (R, and T for a refractor) in the
      // order distance_map_lookup replays them.
      specular_radiance(g.surface[i], n, g.view_direction(i), lookup);
    }
    for (std::size_t q = 0; q < requests.size();) {
      const int m = requests[q].map;
      std::size_t run = 1;
      while (run < kLobeBatch && q + run < requests.size() && requests[q + run].map == m) ++run;
      glm::vec3 x[kLobeBatch], r[kLobeBatch], along[kLobeBatch];
      for (std::size_t j = 0; j < run; ++j) x[j] = requests[q + j].x, r[j] = requests[q + j].r;
      const unsigned missed = search_counted(maps, m, x, r, static_cast<int>(run), options, st, along);
      for (std::size_t j = 0; j < run; ++j) {
        const Request& req = requests[q + j];
        if (fallbacks && ((missed >> j) & 1u)) fallbacks->mark(req.sample, Fallback::search_missed);
        found[req.slot] = along[j];
        markers[static_cast<std::size_t>(m)].mark(along[j], req.exponent);
      }
      q += run;
    }
  });
  for (CubeTileMask& mask : tiles) settle_wide_reads(executor, mask);
  add_stats(out.stats, per_chunk);
  return out;
}

}  // namespace

DistanceSearches distance_map_search(par::Executor& executor, const GBuffer& g, const ReflectorMaps& maps,
                                     const DistanceSearchOptions& options, FallbackMask* fallbacks,
                                     std::vector<CubeTileMask>* mark_into) {
  return search_samples(executor, g, maps, options, fallbacks, mark_into, nullptr, nullptr);
}

DistanceSearches distance_map_search_reusing(par::Executor& executor, const GBuffer& g, const ReflectorMaps& maps,
                                             const DistanceSearchOptions& options, const IdBuffer& earlier_object,
                                             const DistanceSearches& earlier, std::vector<CubeTileMask>* mark_into) {
  return search_samples(executor, g, maps, options, nullptr, mark_into, &earlier_object, &earlier);
}

ImageRGBA distance_map_lookup(par::Executor& executor, const GBuffer& g, const EnvironmentMap& env,
                              const ReflectorMaps& maps, const DistanceSearches& searches,
                              const DistanceSearchOptions& options) {
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  executor.parallel_for("distance_map_reflect.lookup", out.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    const std::vector<glm::vec3>& found = searches.found[begin / kChunk];
    // The chunk's samples' lookups first (their plans, each found direction's map and lobe,
    // and how each lookup combines its directions), then the colour along every found
    // direction, eight at a time along a run of one map (radiance8: each lane the bits of one
    // lookup, whichever others share the call), then each sample's radiance from its lookups
    // with searched_lookup's arithmetic in its order.
    struct Sample {
      std::size_t i;
      int map;
      SpecularLookups plan;
      int averaged[2] = {0, 0};  // per lookup: searched_lookup's `averaged`
    };
    std::vector<Sample> samples;
    std::vector<int> map_of;
    std::vector<float> exponent_of;
    map_of.reserve(found.size());
    exponent_of.reserve(found.size());
    SubLobeAxes axes(options.lobe_directions);
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      Sample& sample = samples.emplace_back(Sample{i, map_of_sample(g, maps, i), SpecularLookups(s, g.normal.pixels[i], g.view_direction(i))});
      if (sample.map < 0) continue;
      for (int k = 0; k < sample.plan.count; ++k)
        searched_lookup(g.normal.pixels[i], sample.plan.direction[k], sample.plan.exponent[k], axes,
                        [&](const glm::vec3*, int count, float e, glm::vec3* radiance) {
          for (int j = 0; j < count; ++j) map_of.push_back(sample.map), exponent_of.push_back(e);
          std::fill(radiance, radiance + count, glm::vec3(0.0f));
        }, &sample.averaged[k]);
    }
    std::vector<glm::vec3> colour(map_of.size());
    for (std::size_t q = 0; q < map_of.size();) {
      std::size_t run = 1;
      while (run < kLobeBatch && q + run < map_of.size() && map_of[q + run] == map_of[q]) ++run;
      maps.maps[static_cast<std::size_t>(map_of[q])].radiance8(&found[q], &exponent_of[q], static_cast<int>(run), &colour[q]);
      q += run;
    }
    std::size_t next = 0;
    for (const Sample& sample : samples) {
      glm::vec3 arriving[2];
      for (int k = 0; k < sample.plan.count; ++k) {
        if (sample.map < 0) {
          arriving[k] = env.radiance(sample.plan.direction[k], sample.plan.exponent[k]);
        } else if (const int used = sample.averaged[k]; used > 0) {
          glm::vec3 sum(0.0f);
          for (int j = 0; j < used; ++j) sum += colour[next++];
          arriving[k] = sum / float(used);
        } else {
          arriving[k] = colour[next++];
        }
      }
      out.pixels[sample.i] = glm::vec4(sample.plan.radiance(arriving), 1.0f);
    }
  });
  return out;
}

ImageRGBA DistanceMapReflectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                            const EnvironmentMap& environment,
                                            const ReflectorMaps& maps) const {
  DistanceReflectStats st;
  FallbackMask fallbacks = c.capturing() ? FallbackMask(gbuffer.width, gbuffer.height) : FallbackMask();
  ImageRGBA specular = distance_map_reflect(c.executor(), gbuffer, environment, maps, search, &st, &fallbacks);
  publish_searches(c, st, std::move(fallbacks));
  return specular;
}

DistanceSearches DistanceMapSearchPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                                  const ReflectorMaps& maps) const {
  FallbackMask fallbacks = c.capturing() ? FallbackMask(gbuffer.width, gbuffer.height) : FallbackMask();
  DistanceSearches found = distance_map_search(c.executor(), gbuffer, maps, search, &fallbacks);
  publish_searches(c, found.stats, std::move(fallbacks));
  return found;
}

ImageRGBA DistanceMapLookupPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                            const EnvironmentMap& environment, const ReflectorMaps& maps,
                                            const DistanceSearches& searches) const {
  return distance_map_lookup(c.executor(), gbuffer, environment, maps, searches, search);
}

}  // namespace speculum::raster
