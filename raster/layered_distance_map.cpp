// Layered distance maps and their recursive tracer: see layered_distance_map.h.
#include "raster/layered_distance_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "raster/direct_light.h"

namespace speculum::raster {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kMaxLayers = 8;
constexpr int kBandRows = 8;  // rows per peeling chunk (fixed: independent of threads)

struct Fragment {
  float t = kInf;
  std::uint32_t triangle = kNoId;
  float b1 = 0, b2 = 0;
};

// Inserts f into the sorted list (nearest first, ties by triangle id), keeping `layers`.
void insert(Fragment* list, int layers, const Fragment& f) {
  int k = layers - 1;
  if (f.t > list[k].t || (f.t == list[k].t && f.triangle >= list[k].triangle)) return;
  while (k > 0 && (f.t < list[k - 1].t || (f.t == list[k - 1].t && f.triangle < list[k - 1].triangle))) {
    list[k] = list[k - 1];
    --k;
  }
  list[k] = f;
}

struct PixelBox {
  int x0 = 1, x1 = 0, y0 = 1, y1 = 0;  // inclusive; empty when x0 > x1
};

// Face frame recovered from cube_direction, so texel directions match every cube lookup.
struct Frame {
  glm::vec3 f, r, u;
};
Frame face_frame(int face, int s) {
  const float h = 0.5f * s;
  const glm::vec3 f = cube_direction(face, {h, h}, s);
  const glm::vec3 r = cube_direction(face, {float(s), h}, s) * std::sqrt(2.0f) - f;
  const glm::vec3 u = cube_direction(face, {h, 0.0f}, s) * std::sqrt(2.0f) - f;
  return {f, r, u};
}

// Conservative pixel box of a triangle on one face (whole face when it reaches the plane
// through o, where projection breaks down).
PixelBox triangle_box(const Frame& fr, int s, const glm::vec3 v[3]) {
  // The part of the triangle in front of the face (depth >= eps, clipped edge by edge),
  // projected; points just in front of o project far out and clamp to the face border.
  const float eps = 1e-6f * (glm::length(v[0]) + glm::length(v[1]) + glm::length(v[2]));
  glm::vec3 pts[6];
  int n = 0;
  for (int k = 0; k < 3; ++k) {
    const glm::vec3 &a = v[k], &b = v[(k + 1) % 3];
    const float za = glm::dot(a, fr.f), zb = glm::dot(b, fr.f);
    if (za >= eps) pts[n++] = a;
    if ((za >= eps) != (zb >= eps)) pts[n++] = a + (b - a) * ((eps - za) / (zb - za));
  }
  PixelBox b;
  if (n == 0) return b;
  float minx = kInf, maxx = -kInf, miny = kInf, maxy = -kInf;
  for (int k = 0; k < n; ++k) {
    const float z = std::max(glm::dot(pts[k], fr.f), eps);
    const float px = std::clamp((glm::dot(pts[k], fr.r) / z + 1.0f) * 0.5f * s, -1.0f, s + 1.0f);
    const float py = std::clamp((1.0f - glm::dot(pts[k], fr.u) / z) * 0.5f * s, -1.0f, s + 1.0f);
    minx = std::min(minx, px), maxx = std::max(maxx, px);
    miny = std::min(miny, py), maxy = std::max(maxy, py);
  }
  b.x0 = std::max(0, int(std::floor(minx)) - 1), b.x1 = std::min(s - 1, int(std::ceil(maxx)) + 1);
  b.y0 = std::max(0, int(std::floor(miny)) - 1), b.y1 = std::min(s - 1, int(std::ceil(maxy)) + 1);
  return b;
}

// Möller–Trumbore from the origin (vertices relative to o); t along unit d.
bool intersect(const glm::vec3& d, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
               Fragment& out) {
  const glm::vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const float det = glm::dot(e1, p);
  if (det == 0.0f) return false;
  const float inv = 1.0f / det;
  const glm::vec3 tv = -a;
  const float u = glm::dot(tv, p) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const glm::vec3 q = glm::cross(tv, e1);
  const float v = glm::dot(d, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  out.t = glm::dot(e2, q) * inv;
  out.b1 = u, out.b2 = v;
  return true;
}

// Nearest texel of a face image towards direction d.
template <class Image>
const auto& texel(const std::array<Image, kCubeFaces>& faces, const glm::vec3& d, int size) {
  const CubeCoord c = cube_coord(d, size);
  const int x = std::min(static_cast<int>(c.pixel.x), size - 1);
  const int y = std::min(static_cast<int>(c.pixel.y), size - 1);
  return faces[c.face].pixels[static_cast<std::size_t>(y) * size + x];
}

}  // namespace

LayeredDistanceMap render_layered_distance_map(par::Executor& executor, const Scene& scene,
                                               const glm::vec3& centre,
                                               const std::vector<ShadowMap>& shadows,
                                               const EnvironmentMap& env,
                                               const LayeredMapOptions& options) {
  const int s = options.size, layers = std::clamp(options.layers, 1, kMaxLayers);
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  const float znear = depth_range.znear;
  const TriangleMesh& m = scene.mesh;
  const std::size_t tris = m.triangle_count();
  LayeredDistanceMap out;
  out.size = s;
  out.centre = centre;
  out.layers.resize(layers);
  const std::size_t bands = (s + kBandRows - 1) / kBandRows;
  for (int face = 0; face < kCubeFaces; ++face) {
    const Frame fr = face_frame(face, s);
    std::vector<PixelBox> boxes(tris);
    executor.parallel_for("layered_distance_map.boxes", tris, 4096,
                          [&](std::size_t begin, std::size_t end) {
      for (std::size_t t = begin; t < end; ++t) {
        const glm::vec3 v[3] = {m.positions[m.indices[3 * t]] - centre,
                                m.positions[m.indices[3 * t + 1]] - centre,
                                m.positions[m.indices[3 * t + 2]] - centre};
        boxes[t] = triangle_box(fr, s, v);
      }
    });
    // The k-buffer: per texel the `layers` nearest hits of its ray from o.
    std::vector<Fragment> frags(static_cast<std::size_t>(s) * s * layers);
    executor.parallel_for("layered_distance_map.peel", bands, 1,
                          [&](std::size_t begin, std::size_t end) {
      for (std::size_t band = begin; band < end; ++band) {
        const int y0 = int(band) * kBandRows, y1 = std::min(s, y0 + kBandRows) - 1;
        for (std::size_t t = 0; t < tris; ++t) {
          const PixelBox& b = boxes[t];
          if (b.x0 > b.x1 || b.y1 < y0 || b.y0 > y1) continue;
          const glm::vec3 a = m.positions[m.indices[3 * t]] - centre,
                          bb = m.positions[m.indices[3 * t + 1]] - centre,
                          c = m.positions[m.indices[3 * t + 2]] - centre;
          for (int y = std::max(b.y0, y0); y <= std::min(b.y1, y1); ++y)
            for (int x = b.x0; x <= b.x1; ++x) {
              const glm::vec3 d = cube_direction(face, {x + 0.5f, y + 0.5f}, s);
              Fragment f;
              if (!intersect(d, a, bb, c, f) || f.t < znear) continue;
              f.triangle = static_cast<std::uint32_t>(t);
              insert(&frags[(static_cast<std::size_t>(y) * s + x) * layers], layers, f);
            }
        }
      }
    });
    const Camera cam = cube_face_camera(face, centre, znear, depth_range.zfar);
    for (int k = 0; k < layers; ++k) {
      VisibilityBuffer vis;
      vis.width = vis.height = s;
      vis.triangle = IdBuffer(s, s, kNoId);
      vis.object = IdBuffer(s, s, kNoId);
      vis.depth = ImageF(s, s, kInf);
      vis.bary = Buffer2D<glm::vec2>(s, s, glm::vec2(0.0f));
      ImageF& dist = out.layers[k].distance[face];
      dist = ImageF(s, s, kInf);
      for (std::size_t i = 0; i < vis.triangle.size(); ++i) {
        const Fragment& f = frags[i * layers + k];
        if (f.triangle == kNoId) continue;
        const glm::vec3 d = cube_direction(face, {float(i % s) + 0.5f, float(i / s) + 0.5f}, s);
        vis.triangle.pixels[i] = f.triangle;
        vis.object.pixels[i] = m.triangle_object[f.triangle];
        vis.depth.pixels[i] = f.t * glm::dot(d, fr.f);
        vis.bary.pixels[i] = {f.b1, f.b2};
        dist.pixels[i] = f.t;
      }
      out.layers[k].surface[face] = resolve_gbuffer(executor, scene, vis, centre);
      out.layers[k].colour[face] =
          direct_light(executor, scene, out.layers[k].surface[face], cam, shadows, env);
    }
  }
  return out;
}

namespace {

// The nearest valid hit of ray x + r d (x relative to o) in one layer: linear search on the
// §4.1.2 spacing, regula-falsi refinement of each undershoot → overshoot bracket, accepted
// when the refined point lies on the stored surface (within the tolerance) and beyond
// `min_d` (the ray's own surface); otherwise the march goes on. After the march, a
// parallax guess (eq.4) covers hits beyond its last sample.
float search_layer(const CubeLayer& layer, int size, const glm::vec3& x, const glm::vec3& r,
                   const LayeredTraceOptions& o, float min_d, std::uint64_t& lookups) {
  const auto stored = [&](const glm::vec3& d) {
    ++lookups;
    return texel(layer.distance, d, size);
  };
  const auto ratio = [&](float d) {
    const glm::vec3 l = x + r * d;
    const float len = glm::length(l);
    if (len <= 0.0f) return 0.0f;
    const float st = stored(l);
    return std::isinf(st) ? 0.0f : len / st;
  };
  const float xlen = glm::length(x);
  if (xlen == 0.0f) {
    const float d = stored(r);
    return d > min_d ? d : kInf;
  }
  const int n = std::max(2, o.linear_steps);
  float d_prev = 0.0f, g_prev = ratio(0.0f);
  float last_d = 0.0f;
  for (int k = 1; k < n; ++k) {
    const float t = float(k) / float(n);
    const float d = xlen * t / (1.0f - t);
    const float g = ratio(d);
    if (g_prev < 1.0f && g >= 1.0f) {
      float dl = d_prev, gl = g_prev, dp = d, gp = g, best = dp, gbest = gp;
      for (int s = 0; s < o.secant_steps; ++s) {
        const float dn = secant_from_ratios(dl, gl, dp, gp);
        const float gn = ratio(dn);
        best = dn, gbest = gn;
        if (gn < 1.0f) dl = dn, gl = gn;
        else dp = dn, gp = gn;
      }
      if (best > min_d && gbest > 0.0f && std::abs(gbest - 1.0f) < o.hit_tolerance) return best;
    }
    d_prev = d, g_prev = g, last_d = d;
  }
  const float dp = parallax_step(stored, x, r, r);
  if (std::isfinite(dp) && dp > last_d && dp > min_d) {
    const float g = ratio(dp);
    if (g > 0.0f && std::abs(g - 1.0f) < o.hit_tolerance) return dp;
  }
  return kInf;
}

}  // namespace

namespace {

// The light a specular surface at x (stored normal n_stored, seen along unit r) sends back
// towards -r: F times its mirror reflection and, for a refractor, (1 − F) × transmission ×
// base colour times the refracted ray (all reflected on total internal reflection) —
// SURVEY §4.3's refraction traced through the same layers as reflections. `depth` is the
// continuations' depth: traced while it is within the bounce limit, else the environment
// (counted per continuation, so the count equals the searches one more bounce would add).
glm::vec3 specular_continuation(const LayeredDistanceMap& map, const EnvironmentMap& env, const glm::vec3& x,
                                const glm::vec3& r, const glm::vec3& n_stored, const SurfaceParams& s,
                                const LayeredTraceOptions& o, int depth, LayeredTraceStats& stats) {
  auto follow = [&](const glm::vec3& dir) -> glm::vec3 {
    if (depth > o.bounces) {
      ++stats.depth_exhausted;
      return env.radiance(dir, 1e6f);
    }
    return trace_layered(map, env, x, dir, o, depth, stats);
  };
  const bool entering = glm::dot(n_stored, r) < 0.0f;
  const glm::vec3 n = entering ? n_stored : -n_stored;  // faces the incident side
  const float cos_i = std::max(-glm::dot(n, r), 0.0f);
  if (!s.is_refractor()) return specular_reflectance(s, cos_i) * follow(reflect(r, n));
  const float nu = entering ? s.ior : 1.0f / s.ior;
  glm::vec3 t;
  if (!refract(r, n, nu, t)) return s.transmission * follow(reflect(r, n));
  const float F = fresnel_dielectric(cos_i, nu);
  return F * follow(reflect(r, n)) + s.transmission * (1.0f - F) * s.base_color * follow(glm::normalize(t));
}

}  // namespace

glm::vec3 trace_layered(const LayeredDistanceMap& map, const EnvironmentMap& env,
                        const glm::vec3& x_world, const glm::vec3& r,
                        const LayeredTraceOptions& o, int depth, LayeredTraceStats& stats) {
  ++stats.rays;
  const glm::vec3 x = x_world - map.centre;
  const float min_d = 1e-3f * (glm::length(x) + 1e-2f);
  float best = kInf;
  int best_layer = -1;
  for (std::size_t k = 0; k < map.layers.size(); ++k) {
    const float d = search_layer(map.layers[k], map.size, x, r, o, min_d, stats.lookups);
    if (d < best) best = d, best_layer = static_cast<int>(k);
  }
  if (best_layer < 0) {
    ++stats.misses;
    return env.radiance(r, 1e6f);
  }
  const CubeLayer& layer = map.layers[best_layer];
  const glm::vec3 l = x + r * best;
  const CubeCoord c = cube_coord(l, map.size);
  const std::size_t i = static_cast<std::size_t>(std::min(int(c.pixel.y), map.size - 1)) * map.size +
                        std::min(int(c.pixel.x), map.size - 1);
  const GBuffer& g = layer.surface[c.face];
  glm::vec3 radiance = glm::vec3(layer.colour[c.face].pixels[i]);
  const SurfaceParams& s = g.surface[i];
  if (!g.covered(i) || !is_specular(s)) return radiance;
  // A specular hit: its direct light (already in `colour`) plus what its continuations bring.
  return radiance + specular_continuation(map, env, map.centre + l, r, g.normal.pixels[i], s, o, depth + 1, stats);
}

ImageRGBA layered_reflect(par::Executor& executor, const GBuffer& g, const LayeredDistanceMap& map,
                          const EnvironmentMap& env, const LayeredTraceOptions& options,
                          LayeredTraceStats* stats, FallbackMask* fallbacks) {
  constexpr std::size_t kChunk = 1024;
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  std::vector<LayeredTraceStats> per_chunk((out.size() + kChunk - 1) / kChunk);
  executor.parallel_for("layered_reflect.trace", out.size(), kChunk,
                        [&](std::size_t begin, std::size_t end) {
    LayeredTraceStats& st = per_chunk[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      const LayeredTraceStats before = st;
      const glm::vec3 radiance = specular_continuation(map, env, g.position.pixels[i], -g.view_direction(i),
                                                       g.normal.pixels[i], s, options, 1, st);
      out.pixels[i] = glm::vec4(radiance, 1.0f);
      if (fallbacks && st.misses > before.misses) fallbacks->mark(i, Fallback::search_missed);
      if (fallbacks && st.depth_exhausted > before.depth_exhausted) fallbacks->mark(i, Fallback::depth_exhausted);
    }
  });
  if (stats)
    for (const LayeredTraceStats& c : per_chunk) {
      stats->rays += c.rays;
      stats->lookups += c.lookups;
      stats->misses += c.misses;
      stats->depth_exhausted += c.depth_exhausted;
    }
  return out;
}

LayeredDistanceMap LayeredDistanceMapPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                     const EnvironmentMap& environment) const {
  return render_layered_distance_map(c.executor(), *scene, centre, shadows, environment, options);
}

ImageRGBA LayeredReflectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                        const LayeredDistanceMap& map,
                                        const EnvironmentMap& environment) const {
  LayeredTraceStats st;
  FallbackMask fallbacks = c.capturing() ? FallbackMask(gbuffer.width, gbuffer.height) : FallbackMask();
  ImageRGBA specular = layered_reflect(c.executor(), gbuffer, map, environment, options, &st, &fallbacks);
  c.publish("fallback", std::move(fallbacks));
  c.count("searches", st.rays);
  c.count("distance_lookups", st.lookups);
  c.count("fallback_search_missed", st.misses);
  c.count("fallback_depth_exhausted", st.depth_exhausted);
  return specular;
}

}  // namespace speculum::raster
