// Benchmark ray sets (see ray_generation.h). Random numbers are keyed by (pixel, 0,
// dimension, seed), so the file is the same for any thread count.
#include "trace/ray_generation.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/error.h"
#include "core/optics.h"
#include "core/ray_offset.h"
#include "core/sampling.h"

namespace speculum::trace {

RaySetKind parse_ray_set_kind(const std::string& name) {
  if (name == "primary") return RaySetKind::Primary;
  if (name == "reflect-cone30") return RaySetKind::ReflectCone30;
  if (name == "hemisphere") return RaySetKind::Hemisphere;
  throw InputError("--emit-rays", "unknown ray set '" + name + "' (primary, reflect-cone30, hemisphere)");
}

RayStream generate_rays(RaySetKind kind, const Bvh& bvh, const Camera& camera, int width, int height,
                        std::uint32_t seed, par::Executor& ex) {
  validate_camera(camera, "--emit-rays camera");
  if (width <= 0 || height <= 0 || width > 65536 || height > 65536)
    throw InputError("--emit-rays", "image size out of range");
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  RayStream primary;
  primary.resize(pixels);
  ex.parallel_for("emit_primary", pixels, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      Ray r = primary_ray(camera, width, height, static_cast<float>(i % width) + 0.5f,
                          static_cast<float>(i / width) + 0.5f);
      r.tmax = 3.0e38f;
      primary.set(i, r);
    }
  });
  if (kind == RaySetKind::Primary) return primary;

  HitStream hits;
  closest_hit_stream(bvh, primary, hits, ex);
  // One secondary ray per primary hit, in pixel order: mark, then compact serially.
  std::vector<Ray> secondary(pixels);
  std::vector<std::uint8_t> valid(pixels, 0);
  const auto& tris = bvh.leaf_triangles();
  const auto& ids = bvh.triangle_ids();
  // Leaf slot of each original triangle id, to fetch its vertices.
  std::vector<std::uint32_t> slot(ids.size());
  for (std::size_t k = 0; k < ids.size(); ++k) slot[ids[k]] = static_cast<std::uint32_t>(k);
  const float cos30 = std::cos(30.0f * kPi / 180.0f);
  ex.parallel_for("emit_secondary", pixels, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (hits.triangle[i] == kNoHit) continue;
      const LeafTriangle& t = tris[slot[hits.triangle[i]]];
      glm::vec3 ng = glm::cross(t.b - t.a, t.c - t.a);
      if (!(glm::length(ng) > 0.0f)) continue;
      ng = glm::normalize(ng);
      const Ray pr = primary.get(i);
      const glm::vec3 d = glm::normalize(pr.direction);
      if (glm::dot(ng, d) > 0.0f) ng = -ng;
      const glm::vec3 p = t.a * (1.0f - hits.u[i] - hits.v[i]) + t.b * hits.u[i] + t.c * hits.v[i];
      const glm::vec2 u = random_float2(static_cast<std::uint32_t>(i), 0, 0, seed);
      glm::vec3 dir;
      if (kind == RaySetKind::ReflectCone30) {
        dir = Onb(reflect(d, ng)).to_world(sample_uniform_cone(u, cos30));
      } else {
        dir = Onb(ng).to_world(sample_cosine_hemisphere(u));
      }
      Ray r;
      r.origin = offset_ray_origin(p, ng);
      r.direction = glm::normalize(dir);
      r.tmin = 0.0f;
      r.tmax = 3.0e38f;
      secondary[i] = r;
      valid[i] = 1;
    }
  });
  RayStream out;
  std::size_t n = 0;
  for (std::uint8_t v : valid) n += v;
  out.resize(n);
  std::size_t k = 0;
  for (std::size_t i = 0; i < pixels; ++i)
    if (valid[i]) out.set(k++, secondary[i]);
  return out;
}

}  // namespace speculum::trace
