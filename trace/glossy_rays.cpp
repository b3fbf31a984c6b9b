// The glossy_rays kernel (see glossy_rays.h), YU §3.3 eq.4–5.
#include "trace/glossy_rays.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/brdf.h"
#include "core/error.h"
#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"
#include "parallel/page_buffer.h"

namespace speculum::trace {

namespace {
const Ray kUnbounded;  // a reflected ray's default t range
}  // namespace

float glossy_mixture_pdf(float cos_r, float cos_n, float exponent) {
  return (1.0f - kDefensiveShare) * phong_lobe_pdf(cos_r, exponent) +
         kDefensiveShare * std::max(cos_n, 0.0f) / kPi;
}

float sample_solid_angle(float cos_theta, float exponent, int n) {
  const float p = phong_lobe_pdf(cos_theta, exponent);
  return p > 0.0f ? 1.0f / (static_cast<float>(n) * p) : 0.0f;
}

GlossyRays generate_glossy_rays(par::Executor& ex, const Buffer2D<glm::vec3>& positions,
                                const Buffer2D<glm::vec3>& normals,
                                const SurfacePlane& surface, const IdBuffer& object,
                                const glm::vec3& eye, const GlossyRayOptions& opt) {
  if (opt.rays_per_pixel < 1 || opt.rays_per_pixel > 4096)
    throw InputError("glossy_rays", "rays per pixel out of range (1..4096)");
  const std::size_t n_pix = object.size();
  if (positions.size() != n_pix || normals.size() != n_pix || surface.size() != n_pix)
    throw InputError("glossy_rays", "G-buffer planes differ in size");
  GlossyRays out;
  out.width = object.width;
  out.height = object.height;
  out.rays_per_pixel = opt.rays_per_pixel;
  // Which samples trace: a serial pass over flags, then the compaction primitive's order.
  for (std::size_t i = 0; i < n_pix; ++i)
    if (object.pixels[i] != kNoId && traces_glossy(surface[i]))
      out.pixel.push_back(static_cast<std::uint32_t>(i));
  const std::size_t N = static_cast<std::size_t>(opt.rays_per_pixel);
  const std::size_t P = out.pixel.size();
  RayStream& rs = out.rays;
  for (auto* v : {&rs.ox, &rs.oy, &rs.oz, &rs.dx, &rs.dy, &rs.dz, &rs.tmin, &rs.tmax, &out.solid_angle})
    par::resize_on_huge_pages(*v, P * N);
  out.weight.resize(P * N);
  out.albedo.resize(P);
  // The N Hamersley points are the same for every pixel (only the rotation differs).
  std::vector<glm::vec2> points(N);
  for (std::size_t j = 0; j < N; ++j)
    points[j] = hamersley(static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(N));
  constexpr std::size_t kChunk = 64;  // pixels per chunk
  std::vector<std::uint64_t> rejected((P + kChunk - 1) / kChunk, 0);
  ex.parallel_for("glossy_rays", P, kChunk, [&](std::size_t b, std::size_t e) {
    std::uint64_t below = 0;
    for (std::size_t k = b; k < e; ++k) {
      const std::uint32_t i = out.pixel[k];
      const glm::vec3 p = positions.pixels[i];
      const glm::vec3 n = normals.pixels[i];
      const SurfaceParams& s = surface[i];
      glm::vec3 v = eye - p;
      const float vl = glm::length(v);
      v = vl > 0.0f ? v / vl : n;
      const glm::vec3 r = glm::normalize(reflect(-v, n));
      const float cos_nv = std::max(glm::dot(n, v), 0.0f);
      const Onb lobe(r), hemisphere(n);
      const glm::vec2 shift = random_float2(i, 0, 0, opt.seed);
      const glm::vec3 origin = offset_ray_origin(p, n);
      const float exponent = s.phong_exponent;
      const bool mirror = s.is_mirror_lobe();
      const float defensive = mirror ? 0.0f : kDefensiveShare;
      BrdfParams brdf = brdf_params_for_punctual_light(s);
      brdf.alpha = s.roughness * s.roughness;  // the lobe itself, not the punctual-light clamp
      out.albedo[k] = specular_reflectance(s, cos_nv);
      const std::size_t first = k * N;
      // Origin and t range are per pixel: written as one run, then the per-ray directions.
      std::fill_n(rs.ox.begin() + first, N, origin.x);
      std::fill_n(rs.oy.begin() + first, N, origin.y);
      std::fill_n(rs.oz.begin() + first, N, origin.z);
      for (std::size_t j = 0; j < N; ++j) {
        glm::vec2 u = rotate_unit_square(points[j], shift);
        // u.x splits the stratified set between the two lobes, each keeping its strata.
        glm::vec3 d;
        if (u.x < defensive) {
          d = hemisphere.to_world(sample_cosine_hemisphere({u.x / defensive, u.y}));
        } else {
          u.x = (u.x - defensive) / (1.0f - defensive);
          d = lobe.to_world(sample_phong_lobe(u, exponent));
        }
        const float cos_nd = glm::dot(d, n);
        const std::size_t slot = first + j;
        const float pdf = mirror ? 0.0f : glossy_mixture_pdf(glm::dot(d, r), cos_nd, exponent);
        if (cos_nd <= 0.0f || (!mirror && !(pdf > 0.0f))) {
          // Rejected, not reflected: the BRDF is zero below the surface, and the estimator
          // still divides by N (as the reference tracer does).
          ++below;
          rs.dx[slot] = rs.dy[slot] = rs.dz[slot] = 0.0f;
          rs.tmin[slot] = 1.0f;
          rs.tmax[slot] = 0.0f;
          out.solid_angle[slot] = 0.0f;
          out.weight[slot] = glm::vec3(0.0f);
        } else {
          rs.dx[slot] = d.x;
          rs.dy[slot] = d.y;
          rs.dz[slot] = d.z;
          rs.tmin[slot] = kUnbounded.tmin;
          rs.tmax[slot] = kUnbounded.tmax;
          if (mirror) {
            // A delta lobe: every ray is (within 1e-3 rad of) R and carries F(N·V).
            out.solid_angle[slot] = sample_solid_angle(glm::dot(d, r), exponent, static_cast<int>(N));
            out.weight[slot] = out.albedo[k];
          } else {
            out.solid_angle[slot] = 1.0f / (static_cast<float>(N) * pdf);
            out.weight[slot] = gltf_brdf(brdf, n, d, v).specular * (cos_nd / pdf);
          }
        }
      }
    }
    rejected[b / kChunk] = below;
  });
  for (const std::uint64_t r : rejected) out.below_horizon += r;
  return out;
}

}  // namespace speculum::trace
