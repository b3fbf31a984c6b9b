// Forward light tracing of caustics (see light_tracer.h).
#include "trace/light_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/camera_rays.h"
#include "core/error.h"
#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "trace/hit_surface.h"
#include "trace/traversal.h"

namespace speculum::trace {

namespace {

constexpr std::size_t kPhotonChunk = 1024;

bool delta_surface(const SurfaceParams& s) { return s.is_refractor() || s.is_mirror_lobe(); }

// The photons of one (light, generator) pair.
struct Emitter {
  const Light* light = nullptr;
  CausticGenerator generator;
  float cos_max = -1.0f;   // point/spot: the cone holding the generator's sphere
  float solid_angle = 0.0f;
  float far = 0.0f;        // directional: how far behind the sphere the disc starts
};

struct PhotonTracer {
  const Scene& scene;
  const Bvh& bvh;
  const PhotonOptions& opt;
  PhotonStats stats;
  TraversalCounters counters;

  // Follows photon i of emitter `e` (pair index `pair`), calling arrive(PhotonHit, SurfaceParams,
  // shading normal) at every non-delta part of a surface after at least one specular bounce.
  template <class Arrive>
  void trace(const Emitter& e, std::uint32_t pair, std::uint64_t i, Arrive&& arrive) {
    ++stats.photons;
    const auto rnd = [&](std::uint32_t dim) {
      return random_float(static_cast<std::uint32_t>(i), pair, dim, opt.seed ^ static_cast<std::uint32_t>(i >> 32));
    };
    const glm::vec2 u{rnd(0), rnd(1)};
    const float n_photons = static_cast<float>(opt.photons);
    Ray ray;
    float area_or_angle = 0.0f;  // photon's share of the emitter: Ω/N (point) or A/N (directional)
    if (e.light->type == LightType::Directional) {
      const glm::vec3 d = glm::normalize(e.light->direction);
      const Onb basis(d);
      // Uniform on the disc that the generator's sphere shadows (concentric by sqrt).
      const float r = e.generator.radius * std::sqrt(u.x), phi = 2.0f * kPi * u.y;
      ray.origin = e.generator.center - d * e.far + basis.t * (r * std::cos(phi)) + basis.b * (r * std::sin(phi));
      ray.direction = d;
      area_or_angle = kPi * e.generator.radius * e.generator.radius / n_photons;
    } else {
      const glm::vec3 axis = glm::normalize(e.generator.center - e.light->position);
      ray.origin = e.light->position;
      ray.direction = Onb(axis).to_world(sample_uniform_cone(u, e.cos_max));
      area_or_angle = e.solid_angle / n_photons;
    }
    Hit h = closest_hit(bvh, ray, &counters);
    if (!h.hit() || scene.mesh.triangle_object[h.triangle] != e.generator.object) return;
    const HitSurface first = hit_surface(scene, h, ray.direction);
    if (!delta_surface(first.s)) return;  // a non-delta part of the generator: direct light
    ++stats.generator_hits;
    // Power: Φ = I(ω) Ω/N for a point light, E A/N for a directional one. sample_light gives
    // E at the first hit, I(ω) window cone / d², so E d² is the intensity (with the range
    // window of the glTF light, a rendering cut-off, taken at the first hit).
    const LightSample ls = sample_light(*e.light, first.p);
    glm::vec3 flux = e.light->type == LightType::Directional
                         ? ls.irradiance * area_or_angle
                         : ls.irradiance * (ls.distance * ls.distance) * area_or_angle;
    if (flux == glm::vec3(0.0f)) return;
    HitSurface hit = first;
    glm::vec3 dir = glm::normalize(ray.direction);
    for (int bounce = 0;; ++bounce) {
      const SurfaceParams& s = hit.s;
      if (bounce > 0) {
        PhotonHit ph;
        ph.p = hit.p;
        ph.ng = hit.ng;
        ph.wi = -dir;
        ph.flux = flux;
        ph.triangle = h.triangle;
        ph.bounces = static_cast<std::uint32_t>(bounce);
        ++stats.arrivals;
        arrive(ph, s, hit.n);
        if (!delta_surface(s)) return;
      }
      if (bounce >= opt.max_depth) {
        ++stats.depth_limited;
        return;
      }
      // The delta lobes, as the camera paths weight them (reference_tracer.cpp): a mirror's
      // Schlick F(N·V); a refractor's transmission × (F reflected, (1 − F) base colour
      // refracted), the branch chosen with probability F so the weight stays bounded.
      const float cos_i = std::max(glm::dot(hit.n, -dir), 0.0f);
      glm::vec3 next(0.0f), origin(0.0f);
      if (s.is_refractor()) {
        const float nu = hit.entering ? s.ior : 1.0f / s.ior;
        glm::vec3 t(0.0f);
        const bool ok = refract(dir, hit.n, nu, t);
        const float F = ok ? fresnel_dielectric(cos_i, nu) : 1.0f;
        if (rnd(2 + static_cast<std::uint32_t>(bounce)) < F) {
          next = reflect(dir, hit.n);
          origin = offset_ray_origin(hit.p, hit.ng);
          flux *= s.transmission;
        } else {
          next = glm::normalize(t);
          origin = offset_ray_origin(hit.p, -hit.ng);
          flux *= s.transmission * s.base_color;
        }
      } else {
        next = reflect(dir, hit.n);
        origin = offset_ray_origin(hit.p, hit.ng);
        flux *= specular_reflectance(s, cos_i);
      }
      if (flux == glm::vec3(0.0f)) return;
      Ray r;
      r.origin = origin;
      r.direction = next;
      h = closest_hit(bvh, r, &counters);
      if (!h.hit()) return;
      dir = glm::normalize(next);
      hit = hit_surface(scene, h, dir);
    }
  }
};

std::vector<Emitter> emitters(const Scene& scene) {
  const std::vector<CausticGenerator> gens = caustic_generators(scene);
  const Bounds b = scene.bounds();
  const float scene_radius = b.valid() ? 0.5f * glm::length(b.extent()) : 1.0f;
  std::vector<Emitter> out;
  for (const Light& light : scene.lights)
    for (const CausticGenerator& g : gens) {
      Emitter e;
      e.light = &light;
      e.generator = g;
      if (light.type == LightType::Directional) {
        e.far = 2.0f * scene_radius + glm::length(g.center - b.center()) + g.radius;
      } else {
        const float d = glm::length(g.center - light.position);
        if (d > g.radius * 1.0001f) {
          const float sin_max = g.radius / d;
          e.cos_max = std::sqrt(std::max(0.0f, 1.0f - sin_max * sin_max));
        }
        e.solid_angle = 2.0f * kPi * (1.0f - e.cos_max);
      }
      out.push_back(e);
    }
  return out;
}

void add_stats(PhotonStats& a, const PhotonStats& b) {
  a.photons += b.photons;
  a.generator_hits += b.generator_hits;
  a.arrivals += b.arrivals;
  a.splats += b.splats;
  a.depth_limited += b.depth_limited;
}

void check_options(const PhotonOptions& o) {
  if (o.photons == 0 || o.photons > (std::uint64_t{1} << 32))
    throw InputError("caustic photons", "photon count out of range (1..2^32)");
  if (o.max_depth < 1 || o.max_depth > 64) throw InputError("caustic photons", "depth out of range (1..64)");
}

// Runs every photon of every emitter in fixed chunks; body(tracer, emitter, pair, photon,
// chunk) for each.
template <class Body>
void for_each_photon(const Scene& scene, const Bvh& bvh, const PhotonOptions& opt, par::Executor& ex,
                     const char* kernel, std::size_t& chunks, std::vector<PhotonStats>& per_chunk, Body&& body) {
  const std::vector<Emitter> es = emitters(scene);
  const std::size_t total = es.size() * static_cast<std::size_t>(opt.photons);
  chunks = (total + kPhotonChunk - 1) / kPhotonChunk;
  per_chunk.assign(chunks, PhotonStats{});
  if (total == 0) return;
  ex.parallel_for(kernel, total, kPhotonChunk, [&](std::size_t b, std::size_t end) {
    PhotonTracer tr{scene, bvh, opt, {}, {}};
    for (std::size_t k = b; k < end; ++k) {
      const std::size_t pair = k / opt.photons, i = k % opt.photons;
      body(tr, es[pair], static_cast<std::uint32_t>(pair), static_cast<std::uint64_t>(i), b / kPhotonChunk);
    }
    per_chunk[b / kPhotonChunk] = tr.stats;
  });
}

}  // namespace

std::vector<CausticGenerator> caustic_generators(const Scene& scene) {
  std::vector<CausticGenerator> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    if (obj.triangle_count == 0 || obj.material >= scene.materials.size()) continue;
    const SurfaceParams s = surface_params(scene.materials[obj.material]);
    if (!delta_surface(s)) continue;
    Bounds b;
    for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
      for (int k = 0; k < 3; ++k) b.grow(scene.mesh.positions[scene.mesh.indices[3 * t + k]]);
    CausticGenerator g;
    g.object = o;
    g.center = b.center();
    // The farthest vertex from the box's centre, a little enlarged so round-off never loses
    // a rim (the box's half diagonal would waste 2/3 of a sphere's photons).
    float r2 = 0.0f;
    for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 d = scene.mesh.positions[scene.mesh.indices[3 * t + k]] - g.center;
        r2 = std::max(r2, glm::dot(d, d));
      }
    g.radius = std::sqrt(r2) * 1.001f + 1e-6f;
    out.push_back(g);
  }
  return out;
}

std::vector<PhotonHit> trace_caustic_photons(const Scene& scene, const Bvh& bvh, const PhotonOptions& opt,
                                             par::Executor& ex, PhotonStats* stats) {
  check_options(opt);
  std::size_t chunks = 0;
  std::vector<PhotonStats> per_chunk;
  std::vector<std::vector<PhotonHit>> hits;
  const std::vector<Emitter> es = emitters(scene);
  hits.resize((es.size() * opt.photons + kPhotonChunk - 1) / kPhotonChunk);
  for_each_photon(scene, bvh, opt, ex, "caustic_photons", chunks, per_chunk,
                  [&](PhotonTracer& tr, const Emitter& e, std::uint32_t pair, std::uint64_t i, std::size_t chunk) {
                    tr.trace(e, pair, i, [&](const PhotonHit& ph, const SurfaceParams&, const glm::vec3&) {
                      hits[chunk].push_back(ph);
                    });
                  });
  std::vector<PhotonHit> out;
  for (auto& h : hits) out.insert(out.end(), h.begin(), h.end());
  if (stats)
    for (const PhotonStats& s : per_chunk) add_stats(*stats, s);
  return out;
}

ImageRGBA render_caustics(const Scene& scene, const Bvh& bvh, const Camera& camera, int width, int height,
                          const PhotonOptions& opt, par::Executor& ex, PhotonStats* stats) {
  validate_camera(camera, "caustic camera");
  check_options(opt);
  if (width <= 0 || height <= 0 || width > 32768 || height > 32768)
    throw InputError("caustic photons", "image size out of range (1..32768)");
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tan_half = std::tan(glm::radians(camera.vfov_degrees) * 0.5f);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  // A pixel's area on the image plane at unit distance (primary_ray's plane).
  const float pixel_side = 2.0f * tan_half / static_cast<float>(height);
  const float pixel_area = pixel_side * pixel_side;

  struct Splat {
    std::uint32_t pixel;
    glm::vec3 value;
  };
  const std::vector<Emitter> es = emitters(scene);
  std::vector<std::vector<Splat>> splats((es.size() * opt.photons + kPhotonChunk - 1) / kPhotonChunk);
  std::size_t chunks = 0;
  std::vector<PhotonStats> per_chunk;
  for_each_photon(
      scene, bvh, opt, ex, "caustic_light_trace", chunks, per_chunk,
      [&](PhotonTracer& tr, const Emitter& e, std::uint32_t pair, std::uint64_t i, std::size_t chunk) {
        tr.trace(e, pair, i, [&](const PhotonHit& ph, const SurfaceParams& s, const glm::vec3& n) {
          glm::vec3 to_eye = camera.eye - ph.p;
          const float r = glm::length(to_eye);
          if (!(r > 0.0f)) return;
          to_eye /= r;
          const float cos_x = glm::dot(ph.ng, to_eye);  // the eye must be on the photon's side
          const float cos_in = glm::dot(n, ph.wi);
          if (cos_x <= 0.0f || cos_in <= 1e-6f) return;
          const glm::vec3 d = -to_eye;
          const float cos_c = glm::dot(d, forward);
          if (cos_c <= 1e-6f) return;
          const glm::vec3 q = d / cos_c;
          const float sx = (glm::dot(q, right) / (tan_half * aspect) + 1.0f) * 0.5f * static_cast<float>(width);
          const float sy = (1.0f - glm::dot(q, up) / tan_half) * 0.5f * static_cast<float>(height);
          if (!(sx >= 0.0f && sx < static_cast<float>(width) && sy >= 0.0f && sy < static_cast<float>(height)))
            return;
          // f Φ: shade_light returns f (N·L) E; with E := Φ, divide the cosine out.
          LightSample as_light;
          as_light.direction = ph.wi;
          as_light.distance = 1.0f;
          as_light.irradiance = ph.flux;
          const glm::vec3 f_flux = shade_light(s, n, to_eye, as_light) / cos_in;
          if (f_flux == glm::vec3(0.0f)) return;
          Ray shadow;
          shadow.origin = offset_ray_origin(ph.p, ph.ng);
          shadow.direction = to_eye;
          shadow.tmax = r * (1.0f - 1e-4f);
          if (any_hit(bvh, shadow, &tr.counters)) return;
          // Pixel mean radiance: (1/A_pix) ∫ L dω / cos³θ_c with dω = cosθ_x dA / r².
          const float w = cos_x / (r * r * pixel_area * cos_c * cos_c * cos_c);
          const int x = std::min(static_cast<int>(sx), width - 1), y = std::min(static_cast<int>(sy), height - 1);
          ++tr.stats.splats;
          splats[chunk].push_back({static_cast<std::uint32_t>(y * width + x), f_flux * w});
        });
      });
  ImageRGBA image(width, height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  for (const auto& chunk : splats)
    for (const Splat& sp : chunk) image.pixels[sp.pixel] += glm::vec4(sp.value, 0.0f);
  if (stats)
    for (const PhotonStats& s : per_chunk) add_stats(*stats, s);
  return image;
}

}  // namespace speculum::trace
