// Radiance bake and hit shading for the YU technique (see hit_radiance.h), eq.8–9.
#include "trace/hit_radiance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"
#include "core/shading.h"

namespace speculum::trace {

namespace {

// The surface at barycentrics (u, v) of triangle t: position, geometric and shading
// normals (not yet oriented), material.
struct SurfacePoint {
  glm::vec3 p, ng, n;
  SurfaceParams s;
};

SurfacePoint surface_point(const Scene& scene, std::uint32_t t, float u, float v) {
  const TriangleMesh& m = scene.mesh;
  const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
  const float w0 = 1.0f - u - v;
  SurfacePoint sp;
  sp.p = m.positions[i0] * w0 + m.positions[i1] * u + m.positions[i2] * v;
  glm::vec3 ng = glm::cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]);
  const float len = glm::length(ng);
  sp.ng = len > 0.0f ? ng / len : glm::vec3(0.0f, 1.0f, 0.0f);
  sp.n = sp.ng;
  if (m.normals.size() == m.positions.size()) {
    const glm::vec3 s = m.normals[i0] * w0 + m.normals[i1] * u + m.normals[i2] * v;
    if (glm::length(s) > 0.0f) sp.n = glm::normalize(s);
  }
  glm::vec2 uv(0.0f), uv1(0.0f);
  if (m.uvs.size() == m.positions.size()) uv = m.uvs[i0] * w0 + m.uvs[i1] * u + m.uvs[i2] * v;
  if (m.uvs1.size() == m.positions.size()) uv1 = m.uvs1[i0] * w0 + m.uvs1[i1] * u + m.uvs1[i2] * v;
  const std::uint32_t mat = t < m.triangle_material.size() ? m.triangle_material[t] : 0u;
  sp.s = surface_params(scene, mat, uv, uv1);
  return sp;
}

}  // namespace

namespace {

// The points of a triangle where its lighting is baked: the centroid and one point towards
// each corner (barycentrics (2/3, 1/6, 1/6) and its rotations), so an object that covers only
// part of a large triangle (a mirror hung on a wall) shades it partly, not all or nothing.
constexpr int kBakePoints = 4;
constexpr float kBakeU[kBakePoints] = {1.0f / 3.0f, 1.0f / 6.0f, 2.0f / 3.0f, 1.0f / 6.0f};
constexpr float kBakeV[kBakePoints] = {1.0f / 3.0f, 1.0f / 6.0f, 1.0f / 6.0f, 2.0f / 3.0f};

// A ray origin just above bake point j of triangle t, on the side its shading normal shows.
struct BakePoint {
  SurfacePoint sp;
  glm::vec3 ng, above;
  Onb frame;  // about the shading normal, for the sky's cosine samples
};
BakePoint bake_point(const Scene& scene, std::uint32_t t, int j) {
  const SurfacePoint sp = surface_point(scene, t, kBakeU[j], kBakeV[j]);
  const glm::vec3 ng = glm::dot(sp.ng, sp.n) < 0.0f ? -sp.ng : sp.ng;
  return BakePoint{sp, ng, offset_ray_origin(sp.p, ng), Onb(sp.n)};
}

}  // namespace

TriangleLighting bake_triangle_lighting(par::Executor& ex, const Scene& scene, const Bvh& bvh,
                                        const RadianceBakeOptions& opt) {
  const std::size_t nt = scene.mesh.triangle_count();
  TriangleLighting out;
  out.light_count = scene.lights.size();
  out.visibility.assign(nt * out.light_count, 0.0f);
  out.environment_irradiance.assign(nt, glm::vec3(0.0f));
  out.radiance.assign(nt, glm::vec3(0.0f));
  // Per triangle: the lit fraction of its bake points for every light, and the occluded
  // environment irradiance from cosine rays spread over the same points (no interreflection,
  // as in the reference tracer).
  const int ks = std::max(0, opt.environment_samples);
  ex.parallel_for("radiance_bake", nt, 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t t = b; t < e; ++t) {
      const auto tri = static_cast<std::uint32_t>(t);
      static_assert(kBakePoints == 4);
      const std::array<BakePoint, kBakePoints> points{bake_point(scene, tri, 0), bake_point(scene, tri, 1),
                                                      bake_point(scene, tri, 2), bake_point(scene, tri, 3)};
      glm::vec3 lights_e(0.0f);
      for (const BakePoint& bp : points) {
        for (std::size_t l = 0; l < out.light_count; ++l) {
          const LightSample ls = sample_light(scene.lights[l], bp.sp.p);
          if (ls.irradiance == glm::vec3(0.0f) || glm::dot(bp.ng, ls.direction) <= 0.0f) continue;
          Ray r;
          r.origin = bp.above;
          r.direction = ls.direction;
          r.tmax = std::isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : 3.0e38f;
          if (any_hit(bvh, r)) continue;
          out.visibility[t * out.light_count + l] += 1.0f / kBakePoints;
          lights_e += ls.irradiance * std::max(glm::dot(bp.sp.n, ls.direction), 0.0f) / float(kBakePoints);
        }
      }
      glm::vec3 env_e(0.0f);
      if (ks > 0) {
        const glm::vec2 shift = random_float2(tri, 0, 0, opt.seed);
        for (int k = 0; k < ks; ++k) {
          const BakePoint& bp = points[static_cast<std::size_t>(k % kBakePoints)];
          const glm::vec2 u = rotate_unit_square(hamersley(static_cast<std::uint32_t>(k),
                                                           static_cast<std::uint32_t>(ks)), shift);
          const glm::vec3 wi = bp.frame.to_world(sample_cosine_hemisphere(u));
          if (glm::dot(wi, bp.ng) <= 0.0f) continue;
          Ray r;
          r.origin = bp.above;
          r.direction = wi;
          if (!any_hit(bvh, r)) env_e += environment_radiance(scene.environment, wi);
        }
        env_e *= kPi / static_cast<float>(ks);  // E = π × mean radiance under cosine sampling
      }
      out.environment_irradiance[t] = env_e;
      const SurfaceParams& s = points[0].sp.s;  // the centroid's material
      out.radiance[t] = s.emissive + diffuse_albedo_over_pi(s, 1.0f) * (lights_e + env_e) +
                        specular_f0(s) * (env_e / kPi);
    }
  });
  return out;
}

float footprint_area(float distance, float solid_angle, float cos_incidence) {
  return distance * distance * solid_angle / std::max(cos_incidence, 1e-3f);
}

float mip_level(float footprint, float texel_area) {
  if (!(footprint > 0.0f) || !(texel_area > 0.0f)) return 0.0f;
  return 0.5f * std::log2(footprint / texel_area);
}

glm::vec3 hit_radiance(const Scene& scene, const LodBvh& lod, const TriangleLighting& lighting,
                       const glm::vec3& dir_in, float solid_angle, const LodHit& hit) {
  const glm::vec3 dir = glm::normalize(dir_in);
  if (!hit.hit()) return environment_radiance(scene.environment, dir);
  if (hit.proxy != kNoHit) return lod.proxy_radiance(hit.proxy, hit.u, hit.v);
  const std::uint32_t t = hit.triangle;
  const SurfacePoint sp = surface_point(scene, t, hit.u, hit.v);
  glm::vec3 ng = sp.ng, n = sp.n;
  if (glm::dot(ng, dir) > 0.0f) ng = -ng;
  if (glm::dot(n, ng) < 0.0f) n = -n;
  const glm::vec3 v = -dir;
  const float cos_nv = std::max(glm::dot(n, v), 0.0f);
  // Level 0: the exact shading model at the hit, with the triangle's baked visibility.
  glm::vec3 L = sp.s.emissive;
  for (std::size_t l = 0; l < lighting.light_count; ++l) {
    const float lit = lighting.visibility[t * lighting.light_count + l];
    if (lit == 0.0f) continue;
    const LightSample ls = sample_light(scene.lights[l], sp.p);
    if (ls.irradiance == glm::vec3(0.0f) || glm::dot(ng, ls.direction) <= 0.0f) continue;
    L += lit * shade_light(sp.s, n, v, ls);
  }
  L += diffuse_albedo_over_pi(sp.s, cos_nv) * lighting.environment_irradiance[t];
  if (!sp.s.is_refractor() && (sp.s.is_mirror_lobe() || sp.s.is_glossy_lobe()))
    L += specular_reflectance(sp.s, cos_nv) * environment_radiance(scene.environment, reflect(dir, n));
  // eq.8–9: a footprint larger than the triangle blends towards its ancestors' radiance.
  const float texel = lod.triangle_area[t];
  const float level = mip_level(footprint_area(hit.t * glm::length(dir_in), solid_angle,
                                               std::fabs(glm::dot(sp.ng, dir))), texel);
  if (level <= 0.0f) return L;
  float prev_level = 0.0f;
  glm::vec3 prev = L;
  for (std::uint32_t node = lod.triangle_leaf[t]; node != kThreadEnd; node = lod.nodes[node].parent) {
    const LodNode& ln = lod.nodes[node];
    const float node_level = mip_level(ln.area, texel);
    if (node_level >= level) {
      if (node_level <= prev_level) return ln.radiance;
      const float w = (level - prev_level) / (node_level - prev_level);
      return prev * (1.0f - w) + ln.radiance * w;
    }
    if (node_level > prev_level) {
      prev_level = node_level;
      prev = ln.radiance;
    }
  }
  return prev;
}

ImageRGBA glossy_reflection(par::Executor& ex, const Scene& scene, const LodBvh& lod,
                            const TriangleLighting& lighting, const GlossyRays& rays,
                            const std::vector<LodHit>& hits, HitRadianceStats* stats) {
  ImageRGBA out(rays.width, rays.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  const std::size_t P = rays.pixel.size();
  const std::size_t N = static_cast<std::size_t>(std::max(rays.rays_per_pixel, 1));
  constexpr std::size_t kChunk = 64;
  std::vector<HitRadianceStats> per_chunk((P + kChunk - 1) / kChunk);
  ex.parallel_for("hit_radiance", P, kChunk, [&](std::size_t b, std::size_t e) {
    HitRadianceStats st;
    for (std::size_t k = b; k < e; ++k) {
      glm::vec3 sum(0.0f), weight_sum(0.0f);
      for (std::size_t j = 0; j < N; ++j) {
        const std::size_t slot = k * N + j;
        const float omega = rays.solid_angle[slot];
        if (!(omega > 0.0f)) continue;  // below the horizon: contributes 0
        const LodHit& h = hits[slot];
        if (!h.hit()) ++st.misses;
        else if (h.proxy != kNoHit) ++st.proxy_hits;
        else ++st.triangle_hits;
        const glm::vec3 d(rays.rays.dx[slot], rays.rays.dy[slot], rays.rays.dz[slot]);
        sum += rays.weight[slot] * hit_radiance(scene, lod, lighting, d, omega, h);
        weight_sum += rays.weight[slot];
      }
      // The self-normalized estimate E Σ w L / Σ w (trace/glossy_rays.h); no active ray: 0.
      const glm::vec3 ratio = glm::vec3(weight_sum.x > 0.0f ? sum.x / weight_sum.x : 0.0f,
                                        weight_sum.y > 0.0f ? sum.y / weight_sum.y : 0.0f,
                                        weight_sum.z > 0.0f ? sum.z / weight_sum.z : 0.0f);
      out.pixels[rays.pixel[k]] = glm::vec4(rays.albedo[k] * ratio, 1.0f);
    }
    per_chunk[b / kChunk] = st;
  });
  if (stats)
    for (const auto& s : per_chunk) {
      stats->triangle_hits += s.triangle_hits;
      stats->proxy_hits += s.proxy_hits;
      stats->misses += s.misses;
    }
  return out;
}

}  // namespace speculum::trace
