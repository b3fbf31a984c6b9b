// The reference tracer (see reference_tracer.h): a recursive Whitted/Monte-Carlo radiance
// estimate per path sample over the shared shading model of core/shading.h.
#include "trace/reference_tracer.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/error.h"
#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "trace/hit_surface.h"
#include "trace/light_tracer.h"
#include "trace/photon_map.h"
#include "trace/traversal.h"

namespace speculum::trace {

namespace {

constexpr std::uint32_t kDimsPerBounce = 8;  // random dimensions reserved per depth level

struct Tracer {
  const Scene& scene;
  const Bvh& bvh;
  const ReferenceOptions& opt;
  ReferenceStats stats;
  TraversalCounters counters;
  std::uint32_t pixel = 0, sample = 0;
  const PhotonMap* photons = nullptr;  // caustics seen after a specular bounce

  float rnd(int depth, std::uint32_t k) const {
    return random_float(pixel, sample, static_cast<std::uint32_t>(depth) * kDimsPerBounce + k, opt.seed);
  }

  bool occluded(const glm::vec3& origin, const glm::vec3& dir, float distance) {
    ++stats.shadow_rays;
    Ray r;
    r.origin = origin;
    r.direction = dir;
    r.tmax = std::isfinite(distance) ? distance * (1.0f - 1e-4f) : 3.0e38f;
    return any_hit(bvh, r, &counters);
  }

  // `weight`: the largest channel of the product of the specular weights on the way here
  // (1 at the camera); the photon map is queried only where it can still matter.
  glm::vec3 radiance(const Ray& ray, int depth, float weight = 1.0f) {
    const Hit h = closest_hit(bvh, ray, &counters);
    const glm::vec3 dir = glm::normalize(ray.direction);
    if (!h.hit()) return environment_radiance(scene.environment, dir);

    // The hit point comes from the barycentrics: its error scales with the triangle's
    // coordinates, not with the ray's origin (a far camera would otherwise put p on the wrong
    // side). Both normals face the viewer.
    const HitSurface hit = hit_surface(scene, h, ray.direction);
    const glm::vec3 p = hit.p;
    glm::vec3 ng = hit.ng, n = hit.n;
    const SurfaceParams& s = hit.s;
    const bool entering = hit.entering;
    const glm::vec3 v = -dir;
    const float cos_nv = std::max(glm::dot(n, v), 0.0f);
    const glm::vec3 above = offset_ray_origin(p, ng);

    glm::vec3 L = s.emissive;
    // Direct light with traced shadows.
    for (const Light& light : scene.lights) {
      const LightSample ls = sample_light(light, p);
      if (ls.irradiance == glm::vec3(0.0f) || glm::dot(ng, ls.direction) <= 0.0f) continue;
      const glm::vec3 c = shade_light(s, n, v, ls);
      if (c == glm::vec3(0.0f)) continue;
      if (!occluded(above, ls.direction, ls.distance)) L += c;
    }
    // Caustics: seen directly they are the light tracer's (render_caustics); seen through a
    // mirror, a refractor or a glossy lobe, the photon map's.
    // (Refractors and pure metals reflect no photon light the query could find, and a path
    // whose specular weight has fallen under 1/1024 (deep internal reflections) adds less
    // than the estimate's own noise: both skipped, which saves most of the queries.)
    if (photons && depth > 0 && weight >= 1.0f / 1024.0f && !s.is_refractor() &&
        !(s.is_mirror_lobe() && s.metallic >= 1.0f))
      L += photons->radiance(p, n, v, s);
    // Environment light, occluded, on the lobes no specular ray follows: the diffuse lobe
    // (cosine-sampled, weight f_d cos / (cos/π) = π f_d of the coupled BRDF) and, on rough
    // surfaces, the specular lobe (visible normals, as the glossy branch below).
    if (opt.environment_lighting) {
      const BrdfParams brdf = brdf_params_for_punctual_light(s);
      const glm::vec3 wi = Onb(n).to_world(sample_cosine_hemisphere({rnd(depth, 0), rnd(depth, 1)}));
      const glm::vec3 fd = gltf_brdf(brdf, n, wi, v).diffuse;
      if (fd != glm::vec3(0.0f) && glm::dot(wi, ng) > 0.0f &&
          !occluded(above, wi, std::numeric_limits<float>::infinity()))
        L += kPi * fd * environment_radiance(scene.environment, wi);
      if (s.has_rough_specular_lobe()) {
        const LobeSample ls = sample_specular_lobe(s, n, v, {rnd(depth, 4), rnd(depth, 5)});
        if (ls.weight != glm::vec3(0.0f) && glm::dot(ls.direction, ng) > 0.0f &&
            !occluded(above, ls.direction, std::numeric_limits<float>::infinity()))
          L += ls.weight * environment_radiance(scene.environment, ls.direction);
      }
    }
    if (depth >= opt.max_depth) {
      if (s.is_refractor() || s.is_mirror_lobe() || s.is_glossy_lobe()) ++stats.depth_limited;
      return L;
    }
    const auto largest = [](const glm::vec3& c) { return std::max({c.x, c.y, c.z}); };
    auto trace_dir = [&](const glm::vec3& origin, const glm::vec3& d, float factor) {
      ++stats.specular_rays;
      Ray r;
      r.origin = origin;
      r.direction = d;
      return radiance(r, depth + 1, weight * factor);
    };
    if (s.is_refractor()) {
      const float nu = entering ? s.ior : 1.0f / s.ior;
      glm::vec3 tdir(0.0f);  // written by refract() when it returns true
      const bool ok = refract(dir, n, nu, tdir);
      const float F = ok ? fresnel_dielectric(cos_nv, nu) : 1.0f;
      glm::vec3 Ls = F * trace_dir(above, reflect(dir, n), s.transmission * F);
      if (ok && F < 1.0f)
        Ls += (1.0f - F) * s.base_color *
              trace_dir(offset_ray_origin(p, -ng), glm::normalize(tdir), s.transmission * (1.0f - F) * largest(s.base_color));
      L += s.transmission * Ls;
    } else if (s.is_mirror_lobe()) {
      const glm::vec3 f = specular_reflectance(s, cos_nv);
      L += f * trace_dir(above, reflect(dir, n), largest(f));
    } else if (s.is_glossy_lobe()) {
      // The ground truth samples the GGX lobe itself (visible normals), weighted f cos / p
      // = F(V·H) G2/G1 (core/brdf.h): the same BRDF the techniques' lobes are weighted by.
      const LobeSample ls = sample_specular_lobe(s, n, v, {rnd(depth, 2), rnd(depth, 3)});
      if (ls.weight == glm::vec3(0.0f) || glm::dot(ls.direction, ng) <= 0.0f) ++stats.below_horizon;
      else L += ls.weight * trace_dir(above, ls.direction, largest(ls.weight));
    }
    return L;
  }
};

}  // namespace

ImageRGBA render_reference(const Scene& scene, const Camera& camera, const ReferenceOptions& options,
                           par::Executor& executor, ReferenceStats* stats) {
  const Bvh bvh = Bvh::build(scene.mesh, executor);
  return render_reference(scene, bvh, camera, options, executor, stats);
}

ImageRGBA render_reference(const Scene& scene, const Bvh& bvh, const Camera& camera,
                           const ReferenceOptions& opt, par::Executor& ex, ReferenceStats* stats) {
  validate_camera(camera, "reference camera");
  if (opt.width <= 0 || opt.height <= 0 || opt.width > 32768 || opt.height > 32768)
    throw InputError("reference", "image size out of range (1..32768)");
  if (opt.spp <= 0 || opt.spp > (1 << 20)) throw InputError("reference", "spp out of range (1..2^20)");
  ImageRGBA image(opt.width, opt.height, glm::vec4(0.0f));
  const std::size_t pixels = static_cast<std::size_t>(opt.width) * opt.height;
  constexpr std::size_t kChunk = 64;
  std::unique_ptr<PhotonMap> photon_map;
  if (opt.caustic_photons > 0) {
    // The map stores its photons (~56 bytes each): at most 2^20 per light and generator.
    PhotonOptions po;
    po.photons = std::min<std::uint64_t>(opt.caustic_photons, std::uint64_t{1} << 20);
    po.max_depth = opt.max_depth;
    po.seed = opt.seed ^ 0x5bd1e995u;  // independent of the light tracer's photons
    const Bounds b = scene.bounds();
    const float diagonal = b.valid() ? glm::length(b.extent()) : 1.0f;
    photon_map = std::make_unique<PhotonMap>(trace_caustic_photons(scene, bvh, po, ex), 32, 0.02f * diagonal);
  }
  std::vector<ReferenceStats> per_chunk((pixels + kChunk - 1) / kChunk);
  ex.parallel_for("reference_render", pixels, kChunk, [&](std::size_t b, std::size_t e) {
    Tracer tr{scene, bvh, opt, {}, {}, 0, 0, photon_map.get()};
    for (std::size_t i = b; i < e; ++i) {
      const int x = static_cast<int>(i % opt.width), y = static_cast<int>(i / opt.width);
      tr.pixel = static_cast<std::uint32_t>(i);
      glm::vec3 sum(0.0f);
      for (int k = 0; k < opt.spp; ++k) {
        tr.sample = static_cast<std::uint32_t>(k);
        float jx = 0.5f, jy = 0.5f;
        if (opt.pixel_jitter) {
          jx = random_float(tr.pixel, tr.sample, 0xfffffff0u, opt.seed);
          jy = random_float(tr.pixel, tr.sample, 0xfffffff1u, opt.seed);
        }
        const Ray r = primary_ray(camera, opt.width, opt.height, static_cast<float>(x) + jx, static_cast<float>(y) + jy);
        ++tr.stats.camera_rays;
        sum += tr.radiance(r, 0);
      }
      image.pixels[i] = glm::vec4(sum / static_cast<float>(opt.spp), 1.0f);
    }
    tr.stats.stack_overflows = tr.counters.stack_overflows;
    per_chunk[b / kChunk] = tr.stats;
  });
  if (opt.caustic_photons > 0) {
    PhotonOptions po;
    po.photons = opt.caustic_photons;
    po.max_depth = opt.max_depth;
    po.seed = opt.seed;
    PhotonStats ps;
    const ImageRGBA caustics = render_caustics(scene, bvh, camera, opt.width, opt.height, po, ex, &ps);
    for (std::size_t i = 0; i < pixels; ++i)
      image.pixels[i] += glm::vec4(glm::vec3(caustics.pixels[i]), 0.0f);
    if (stats) {
      stats->caustic_photons += ps.photons;
      stats->caustic_splats += ps.splats;
    }
  }
  if (stats) {
    for (const ReferenceStats& s : per_chunk) {
      stats->camera_rays += s.camera_rays;
      stats->shadow_rays += s.shadow_rays;
      stats->specular_rays += s.specular_rays;
      stats->below_horizon += s.below_horizon;
      stats->depth_limited += s.depth_limited;
      stats->stack_overflows += s.stack_overflows;
    }
  }
  return image;
}

ImageRGBA ReferencePass::operator()(par::NodeContext& c) const {
  ReferenceStats stats;
  ImageRGBA radiance = render_reference(*scene, camera, options, c.executor(), &stats);
  c.count("camera_rays", stats.camera_rays);
  c.count("shadow_rays", stats.shadow_rays);
  c.count("specular_rays", stats.specular_rays);
  if (options.caustic_photons > 0) {
    c.count("caustic_photons", static_cast<double>(stats.caustic_photons));
    c.count("caustic_splats", static_cast<double>(stats.caustic_splats));
  }
  return radiance;
}

}  // namespace speculum::trace
