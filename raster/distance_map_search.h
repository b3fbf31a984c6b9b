// The localized ray search in a distance cube map around a reference point o (SURVEY §4.1):
// parallax correction (§4.1.1 eq.4), linear search with the §4.1.2 spacing, secant
// refinement (§4.1.3 eq.5, kept as regula falsi once bracketed). Each part is switchable.
//
// API (also used by the refraction impostors): coordinates are relative to o; `x` is the ray
// origin, `r` a unit direction; `distance_towards(dir)` returns the stored |y − o| in the
// direction `dir` (any length, non-zero), +inf where the map holds nothing. The answer is a
// ray parameter d and the direction (from o) in which the hit x + r·d is looked up.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "raster/cube_map.h"

namespace speculum::raster {

struct DistanceSearchOptions {
  bool parallax = true;    // eq.4 steps when no linear bracket is found (or linear is off)
  int parallax_steps = 1;  // iterations of d ← R·l' − R·x (the first is eq.4 exactly)
  bool linear = true;      // march t = k/N on r'(t) = s(1−t) + e t (§4.1.2)
  int linear_steps = 16;   // N
  bool secant = true;      // eq.5 refinement of the bracket (or of the parallax guesses)
  int secant_steps = 4;
  // Searches per glossy lobe (distance_map_reflect): 1 searches along the lobe's axis only.
  int lobe_directions = 8;
};

// "parallax=1 linear=16 secant=4" (a step count, or "off" for a disabled search): the
// search as passes and experiments print it.
std::string describe_search(const DistanceSearchOptions& options);

struct DistanceSearchResult {
  float d = std::numeric_limits<float>::infinity();  // ray parameter; +inf: environment guess
  glm::vec3 direction{0.0f, 0.0f, 1.0f};             // from o, where the hit is looked up
  bool bracketed = false;  // the linear search found an undershoot → overshoot pair
  int lookups = 0;         // distance-map reads
};

namespace distance_search_detail {

// |l| / |l'| for l = x + r d: < 1 undershoot, > 1 overshoot; 0 where the map is empty.
template <class DistanceFn>
float ratio(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r, float d,
            int& lookups) {
  const glm::vec3 l = x + r * d;
  const float len = glm::length(l);
  if (len <= 0.0f) return 0.0f;
  ++lookups;
  const float stored = distance_towards(l);
  return std::isinf(stored) ? 0.0f : len / stored;
}

inline glm::vec3 hit_direction(const glm::vec3& x, const glm::vec3& r, float d) {
  if (!std::isfinite(d)) return r;
  const glm::vec3 l = x + r * d;
  return glm::dot(l, l) > 0.0f ? l : r;
}

}  // namespace distance_search_detail

// One parallax step looking up `towards`: assumes the stored surface point l' is on a plane
// perpendicular to r and returns where the ray meets it, d = r·l' − r·x. With towards = r
// this is SURVEY eq.4, d_p = |r'| − R·x. +inf when the map is empty there.
template <class DistanceFn>
float parallax_step(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r,
                    const glm::vec3& towards) {
  const float stored = distance_towards(towards);
  if (std::isinf(stored)) return stored;
  const glm::vec3 l_stored = glm::normalize(towards) * stored;
  return glm::dot(r, l_stored) - glm::dot(r, x);
}

// SURVEY eq.5 from two guesses d_l, d_p with ratios g = |l|/|l'|:
// d_new = d_l + (d_p − d_l)(1 − g_l)/(g_p − g_l). Returns d_l when the ratios are equal.
inline float secant_from_ratios(float d_l, float g_l, float d_p, float g_p) {
  const float denom = g_p - g_l;
  if (denom == 0.0f || !std::isfinite(denom)) return d_l;
  return d_l + (d_p - d_l) * (1.0f - g_l) / denom;
}

// The linear march's samples k ∈ [first, min(first + kMarchBatch, n)) of a march of n:
// d[j] its ray parameter (0 at k = 0, else x_len t / (1 − t) with t = k/n), g[j] the ratio
// there and counted[j] whether reading it took a map lookup (what ratio() counts).
constexpr int kMarchBatch = 8;
struct MarchBatch {
  float d[kMarchBatch], g[kMarchBatch];
  int counted[kMarchBatch];
};

// The march computed with ratio() one sample at a time.
template <class DistanceFn>
struct ScalarMarch {
  const DistanceFn& distance_towards;
  void operator()(const glm::vec3& x, const glm::vec3& r, float x_len, int n, int first, MarchBatch& b) const {
    for (int k = first; k < std::min(first + kMarchBatch, n); ++k) {
      const int j = k - first;
      const float t = float(k) / float(n);
      b.d[j] = k == 0 ? 0.0f : x_len * t / (1.0f - t);  // |R| = 1
      int lookups = 0;
      b.g[j] = distance_search_detail::ratio(distance_towards, x, r, b.d[j], lookups);
      b.counted[j] = lookups;
    }
  }
};

namespace distance_search_detail {

// Where the linear march stopped: the first undershoot → overshoot pair, or none.
struct Bracket {
  bool found = false;
  float d_l = 0.0f, g_l = 0.0f;  // undershoot
  float d_p = 0.0f, g_p = 0.0f;  // overshoot
};

// Where a linear march stands between batches: the last sample scanned (d, ratio), and
// whether the march has ended (a bracket found, or every sample scanned).
struct MarchState {
  float d_prev = 0.0f, g_prev = 0.0f;
  bool ended = false;
};

// Scans batch `b` (samples first .. min(first + kMarchBatch, n) of a march of n) after `st`
// for the first undershoot → overshoot pair; adds to `lookups` those of the samples up to
// it. Ends the march at a bracket (returned in `out`) or at the last sample.
inline void scan_batch(const MarchBatch& b, int first, int n, MarchState& st, int& lookups, Bracket& out) {
  for (int k = first; k < std::min(first + kMarchBatch, n); ++k) {
    const int j = k - first;
    lookups += b.counted[j];
    const float d = b.d[j], g = b.g[j];
    if (k > 0 && st.g_prev < 1.0f && g >= 1.0f) {
      out = {true, st.d_prev, st.g_prev, d, g};
      st.ended = true;
      return;
    }
    st.d_prev = d;
    st.g_prev = g;
  }
  st.ended = first + kMarchBatch >= n;
}

// The linear march of n steps (§4.1.2) from x (|x| = x_len > 0) along r, `march` giving its
// ratios a batch at a time (any batch is computed before it is scanned); adds to `lookups`
// those of the samples up to the bracket.
template <class March>
Bracket march_to_bracket(const March& march, const glm::vec3& x, const glm::vec3& r, float x_len, int n,
                         int& lookups) {
  MarchState st;
  Bracket out;
  MarchBatch b;
  for (int first = 0; first < n && !st.ended; first += kMarchBatch) {
    march(x, r, x_len, n, first, b);
    scan_batch(b, first, n, st, lookups, out);
  }
  return out;
}

// `secant_steps` regula-falsi steps inside the bracket (none: the overshooting sample).
template <class DistanceFn>
void refine_bracket(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r, Bracket b,
                    const DistanceSearchOptions& o, DistanceSearchResult& out) {
  out.bracketed = true;
  float best = b.d_p;
  for (int s = 0; o.secant && s < o.secant_steps; ++s) {
    const float d_new = secant_from_ratios(b.d_l, b.g_l, b.d_p, b.g_p);
    best = d_new;
    const float g_new = ratio(distance_towards, x, r, d_new, out.lookups);
    if (g_new < 1.0f) b.d_l = d_new, b.g_l = g_new;
    else b.d_p = d_new, b.g_p = g_new;
    if (g_new == 1.0f) break;
  }
  out.d = best;
  out.direction = hit_direction(x, r, best);
}

// Without a bracket: `parallax_steps` eq.4 iterations (when on), refined by plain secant
// steps between the last two guesses (the ray start d = 0 counts as the first); with
// nothing on, the environment-map guess r.
template <class DistanceFn>
void search_unbracketed(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r,
                        const DistanceSearchOptions& o, DistanceSearchResult& out) {
  if (!o.parallax || o.parallax_steps < 1) {
    out.direction = r;  // environment mapping
    return;
  }
  float d_before = 0.0f, d = std::numeric_limits<float>::infinity();
  for (int s = 0; s < o.parallax_steps; ++s) {
    ++out.lookups;
    const float next = parallax_step(distance_towards, x, r, hit_direction(x, r, d));
    if (!std::isfinite(next)) break;
    d_before = std::isfinite(d) ? d : 0.0f;
    d = next;
  }
  for (int s = 0; o.secant && std::isfinite(d) && s < o.secant_steps; ++s) {
    const float g_a = ratio(distance_towards, x, r, d_before, out.lookups);
    const float g_b = ratio(distance_towards, x, r, d, out.lookups);
    if (g_a == 0.0f || g_b == 0.0f || g_b == 1.0f) break;
    const float next = secant_from_ratios(d_before, g_a, d, g_b);
    if (!std::isfinite(next) || next < 0.0f) break;
    d_before = d;
    d = next;
  }
  out.d = d;
  out.direction = hit_direction(x, r, d);
}

}  // namespace distance_search_detail

// The combined search. Order: x = o → the direct lookup along r. Linear search (when on)
// for the first undershoot → overshoot pair, then `secant_steps` regula-falsi steps inside
// it (without secant: the overshooting sample). Without a bracket: `parallax_steps` eq.4
// iterations (when on), refined by plain secant steps between the last two guesses (the
// ray start d = 0 counts as the first); with nothing on: the environment-map guess r.
// `march` gives the linear march's ratios a batch at a time (any batch is computed before it
// is scanned; the result and the counted lookups are those of the samples up to the bracket).
template <class DistanceFn, class March>
DistanceSearchResult search_distance(const DistanceFn& distance_towards, const March& march, const glm::vec3& x,
                                     const glm::vec3& r, const DistanceSearchOptions& o) {
  using namespace distance_search_detail;
  DistanceSearchResult out;
  const float x_len = glm::length(x);
  if (x_len == 0.0f) {  // from the reference point every ray is a direct lookup
    out.lookups = 1;
    out.d = distance_towards(r);
    out.direction = r;
    return out;
  }
  if (o.linear && o.linear_steps >= 2) {
    const Bracket b = march_to_bracket(march, x, r, x_len, o.linear_steps, out.lookups);
    if (b.found) {
      refine_bracket(distance_towards, x, r, b, o, out);
      return out;
    }
  }
  search_unbracketed(distance_towards, x, r, o, out);
  return out;
}

// The same with the march one sample at a time.
template <class DistanceFn>
DistanceSearchResult search_distance(const DistanceFn& distance_towards, const glm::vec3& x, const glm::vec3& r,
                                     const DistanceSearchOptions& o) {
  return search_distance(distance_towards, ScalarMarch<DistanceFn>{distance_towards}, x, r, o);
}

// The same in a distance cube map (nearest-texel distances); x_world in world space. The
// linear march reads eight samples at a time in lanes (each with ratio()'s bits).
DistanceSearchResult search_distance_map(const CubeMap& map, const glm::vec3& x_world,
                                         const glm::vec3& r, const DistanceSearchOptions& options);
// search_distance_map from count (1..8) points x_world[j] along directions r[j], into out[j]:
// each search's march as there, then the bracketed ones' secant steps side by side in lanes
// (a step waits on the one before it; eight independent searches keep the core busy), each
// lane with the scalar steps' operations in their order. The same results, bit for bit.
void search_distance_map8(const CubeMap& map, const glm::vec3* x_world, const glm::vec3* r, int count,
                          const DistanceSearchOptions& options, DistanceSearchResult* out);

}  // namespace speculum::raster
