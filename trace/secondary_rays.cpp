// Secondary ray generations and hit shading for the ray-hierarchy technique (see
// secondary_rays.h; ROGER §3.1, §3.4; shading model core/shading.h).
#include "trace/secondary_rays.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"

namespace speculum::trace {

namespace {

constexpr std::size_t kPixelChunk = 1024;

// The reflected or refracted continuation at a surface seen along unit `dir`: n and ng
// face the incident side. Returns false for non-specular surfaces.
bool continuation(const SurfaceParams& s, const glm::vec3& p, const glm::vec3& ng, const glm::vec3& n,
                  bool entering, const glm::vec3& dir, Ray& ray, glm::vec3& weight) {
  if (!has_secondary_ray(s)) return false;
  const float cos_nv = std::max(-glm::dot(n, dir), 0.0f);
  ray = Ray{};
  if (s.is_refractor()) {
    const float nu = entering ? s.ior : 1.0f / s.ior;
    glm::vec3 t;
    if (refract(dir, n, nu, t)) {
      const float F = fresnel_dielectric(cos_nv, nu);
      ray.origin = offset_ray_origin(p, -ng);
      ray.direction = glm::normalize(t);
      weight = s.transmission * (1.0f - F) * s.base_color;
    } else {
      ray.origin = offset_ray_origin(p, ng);
      ray.direction = reflect(dir, n);
      weight = glm::vec3(s.transmission);
    }
    return true;
  }
  ray.origin = offset_ray_origin(p, ng);
  ray.direction = reflect(dir, n);
  weight = specular_reflectance(s, cos_nv);
  return true;
}

void store(SecondaryRays& g, std::size_t i, const Ray& r, const glm::vec3& w) {
  g.rays.set(i, r);
  g.active[i] = 1;
  g.weight[i] = w;
}

}  // namespace

SecondaryRays empty_generation(int width, int height) {
  SecondaryRays g;
  g.width = width;
  g.height = height;
  const std::size_t n = std::size_t(width) * std::size_t(height);
  g.rays.resize(n);
  g.active.assign(n, 0);
  g.weight.assign(n, glm::vec3(0.0f));
  return g;
}

void count_active(SecondaryRays& g) {
  g.count = 0;
  for (std::uint8_t a : g.active) g.count += a;
}

SecondaryRays secondary_rays(par::Executor& ex, const Buffer2D<glm::vec3>& position,
                             const Buffer2D<glm::vec3>& normal, const SurfacePlane& surface,
                             const IdBuffer& object, const glm::vec3& eye) {
  SecondaryRays g = empty_generation(object.width, object.height);
  ex.parallel_for("secondary_rays", object.size(), kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (object.pixels[i] == kNoId) continue;
      const glm::vec3 p = position.pixels[i];
      const glm::vec3 to_eye = eye - p;
      const float l = glm::length(to_eye);
      if (!(l > 0.0f)) continue;
      const glm::vec3 dir = -to_eye / l;
      glm::vec3 n = normal.pixels[i];
      // Opaque G-buffer normals already face the camera; refractors keep the geometric
      // orientation, which tells entering from leaving.
      const bool entering = glm::dot(n, dir) < 0.0f;
      if (!entering) n = -n;
      Ray r;
      glm::vec3 w;
      if (continuation(surface[i], p, n, n, entering, dir, r, w)) store(g, i, r, w);
    }
  });
  count_active(g);
  return g;
}

SecondaryRays bounce_rays(par::Executor& ex, const Scene& scene, const SecondaryRays& in, const HitStream& hits) {
  SecondaryRays g = empty_generation(in.width, in.height);
  ex.parallel_for("bounce_rays", in.active.size(), kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!in.active[i] || hits.triangle[i] == kNoHit) continue;
      const Ray incoming = in.rays.get(i);
      const HitSurface hs = hit_surface(scene, Hit{hits.t[i], hits.u[i], hits.v[i], hits.triangle[i]},
                                        incoming.direction);
      Ray r;
      glm::vec3 w;
      if (continuation(hs.s, hs.p, hs.ng, hs.n, hs.entering, glm::normalize(incoming.direction), r, w))
        store(g, i, r, w * in.weight[i]);
    }
  });
  count_active(g);
  return g;
}

namespace {

// The light reaches the hit's front side with non-zero irradiance (shadow_rays and
// shade_hits use the same rule, so a pixel has a shadow ray exactly when it is shaded).
bool light_reaches(const HitSurface& hs, const LightSample& ls) {
  return ls.irradiance != glm::vec3(0.0f) && glm::dot(hs.ng, ls.direction) > 0.0f;
}

}  // namespace

SecondaryRays shadow_rays(par::Executor& ex, const Scene& scene, const Light& light, const SecondaryRays& gen,
                          const HitStream& hits) {
  SecondaryRays g = empty_generation(gen.width, gen.height);
  ex.parallel_for("shadow_rays", gen.active.size(), kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!gen.active[i] || hits.triangle[i] == kNoHit) continue;
      const HitSurface hs = hit_surface(scene, Hit{hits.t[i], hits.u[i], hits.v[i], hits.triangle[i]},
                                        gen.rays.get(i).direction);
      const LightSample ls = sample_light(light, hs.p);
      if (!light_reaches(hs, ls)) continue;
      const glm::vec3 above = offset_ray_origin(hs.p, hs.ng);
      Ray r;
      if (light.type == LightType::Directional) {
        r.origin = above;
        r.direction = ls.direction;
      } else {
        r.origin = light.position;
        r.direction = above - light.position;
        r.tmax = 1.0f - 1e-4f;
      }
      store(g, i, r, glm::vec3(1.0f));
    }
  });
  count_active(g);
  return g;
}

void shade_hits(par::Executor& ex, const Scene& scene, const SecondaryRays& gen, const HitStream& hits,
                const std::vector<HitStream>& shadow_hits, ImageRGBA& out) {
  // Ambient light on the diffuse lobe, unshadowed, as the rasterized direct light adds it
  // (core/shading.h): without it a hit in a light's shadow would be black where the
  // reference shows the sky's light.
  const glm::vec3 ambient = kPi * environment_mean_radiance(scene.environment);
  ex.parallel_for("shade_hits", gen.active.size(), kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!gen.active[i]) continue;
      const glm::vec3 dir = glm::normalize(gen.rays.get(i).direction);
      glm::vec3 L(0.0f);
      if (hits.triangle[i] == kNoHit) {
        L = environment_radiance(scene.environment, dir);
      } else {
        const HitSurface hs = hit_surface(scene, Hit{hits.t[i], hits.u[i], hits.v[i], hits.triangle[i]}, dir);
        L = hs.s.emissive;
        for (std::size_t l = 0; l < scene.lights.size(); ++l) {
          const LightSample ls = sample_light(scene.lights[l], hs.p);
          if (!light_reaches(hs, ls)) continue;
          if (l < shadow_hits.size() && shadow_hits[l].triangle[i] != kNoHit) continue;
          L += shade_light(hs.s, hs.n, -dir, ls);
        }
        L += diffuse_albedo_over_pi(hs.s, std::max(-glm::dot(hs.n, dir), 0.0f)) * ambient;
      }
      const glm::vec3 c = gen.weight[i] * L;
      out.pixels[i] += glm::vec4(c, 0.0f);
    }
  });
}

void add_environment_fallback(par::Executor& ex, const Scene& scene, const SecondaryRays& gen, ImageRGBA& out) {
  ex.parallel_for("environment_fallback", gen.active.size(), kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i)
      if (gen.active[i])
        out.pixels[i] += glm::vec4(gen.weight[i] * environment_radiance(scene.environment, glm::normalize(gen.rays.get(i).direction)), 0.0f);
  });
}

}  // namespace speculum::trace
