// ROGER ch.5 cone tracing (see cone_tracing.h; §5.2.1–5.2.6).
#include "trace/cone_tracing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

#include <glm/geometric.hpp>

#include "core/shading.h"
#include "parallel/compact.h"
#include "parallel/partition.h"
#include "trace/cone_coverage.h"
#include "trace/ray_triangle.h"

namespace speculum::trace {

namespace {

constexpr std::size_t kPixelChunk = 1024;
constexpr std::size_t kPairChunk = 4096;
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kPiF = 3.14159265358979f;

bool is_ray(const PixelCones& c, std::size_t i) { return c.radius[i] == 0.0f && c.angle[i] == 0.0f; }

std::uint64_t count_flags(const std::vector<std::uint8_t>& f) {
  std::uint64_t n = 0;
  for (std::uint8_t x : f) n += x;
  return n;
}

}  // namespace

PixelCones pixel_cones(par::Executor& ex, const Buffer2D<glm::vec3>& position, const Buffer2D<glm::vec3>& normal,
                       const SurfacePlane& surface, const IdBuffer& object, const IdBuffer& triangle,
                       const ImageF& curvature, const Camera& camera, const PixelConeOptions& o) {
  PixelCones pc;
  pc.axes = secondary_rays(ex, position, normal, surface, object, camera.eye);
  const std::size_t n = object.pixels.size();
  pc.radius.assign(n, 0.0f);
  pc.angle.assign(n, 0.0f);
  pc.near.assign(n, 0.0f);
  pc.far.assign(n, kInf);
  pc.self.assign(n, kNoId);
  std::vector<std::uint8_t> cone(n, 0), fallback(n, 0), refracted(n, 0), clamped(n, 0);
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  // Pixel pitch at unit distance along the view axis (vfov spans the height).
  const float pitch = 2.0f * std::tan(camera.vfov_degrees * (kPiF / 180.0f) * 0.5f) / float(object.height);
  ex.parallel_for("pixel_cones", n, kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (!pc.axes.active[i]) continue;
      pc.far[i] = pc.axes.rays.tmax[i];
      const SurfaceParams& s = surface[i];
      if (s.is_refractor()) {  // the curvature's mirror sphere says nothing about refraction
        refracted[i] = 1;
        continue;
      }
      const glm::vec3 v = position.pixels[i] - camera.eye;
      const float dist = glm::length(v);
      if (!(dist > 0.0f)) continue;
      const glm::vec3 view = v / dist;
      const float cos_view = std::max(glm::dot(forward, view), 1e-3f);
      const float solid_angle = pitch * pitch * cos_view * cos_view * cos_view;
      const float beta = o.footprint * std::sqrt(solid_angle / kPiF);
      const float w = dist * std::tan(beta);
      const glm::vec3 nrm = normal.pixels[i];
      const float cos_i = std::max(-glm::dot(nrm, view), 1e-4f);
      const float kappa = curvature.pixels[i];
      if (w > 0.0f && beta + 2.0f * kappa * w / cos_i < 0.0f) {  // double cone: a ray
        fallback[i] = 1;
        continue;
      }
      const float alpha_r = std::max(beta + 2.0f * kappa * w, 0.0f);
      float gloss = 0.0f;
      if (o.gloss_angle >= 0.0f) {
        gloss = o.gloss_angle;
      } else if (s.is_glossy_lobe()) {
        const float n_exp = std::max(s.phong_exponent, 0.0f);
        gloss = std::acos(std::clamp(std::pow(1.0f - o.lobe_energy, 1.0f / (n_exp + 1.0f)), 0.0f, 1.0f));
      }
      float alpha = alpha_r + gloss;
      const glm::vec3 d = glm::normalize(pc.axes.rays.get(i).direction);
      const float elevation = std::asin(std::clamp(glm::dot(d, nrm), 0.0f, 1.0f));
      if (alpha > 0.5f * elevation) {
        alpha = 0.5f * elevation;
        clamped[i] = 1;
      }
      if (!(alpha > 0.0f) && !(w > 0.0f)) continue;  // zero width: the axis ray itself
      pc.radius[i] = w;
      pc.angle[i] = alpha;
      pc.near[i] = w / std::max(std::tan(0.75f * elevation) - std::tan(alpha), 1e-6f);
      if (gloss > 0.0f && o.far_blur > 0.0f)
        pc.far[i] = std::min(pc.far[i], o.far_blur * o.scene_radius / std::tan(gloss));
      pc.self[i] = triangle.pixels[i];
      cone[i] = 1;
    }
  });
  pc.cones = count_flags(cone);
  pc.ray_fallbacks = count_flags(fallback);
  pc.refraction_rays = count_flags(refracted);
  pc.horizon_clamped = count_flags(clamped);
  return pc;
}

RayHierarchy build_cone_hierarchy(par::Executor& ex, const PixelCones& c) {
  return build_ray_hierarchy(ex, c.axes.rays, c.axes.active, c.axes.width, c.axes.height, &c.radius, &c.angle);
}

ConeHits cone_triangle_hits(par::Executor& ex, const Scene& scene, const PixelCones& cones,
                            const RayHierarchy& hierarchy, int kept, const HierarchyTraverseOptions& options,
                            HierarchyTraverseStats* stats) {
  ConeHits out;
  out.width = cones.axes.width;
  out.height = cones.axes.height;
  out.kept = std::max(kept, 1);
  const std::size_t npix = std::size_t(out.width) * std::size_t(out.height);
  const std::size_t K = std::size_t(out.kept);
  out.distance.assign(npix * K, kInf);
  out.coverage.assign(npix * K, 0.0f);
  out.u.assign(npix * K, 0.0f);
  out.v.assign(npix * K, 0.0f);
  out.triangle.assign(npix * K, kNoHit);
  out.count.assign(npix, 0);
  out.total.assign(npix, 0);
  out.dropped.assign(npix, 0.0f);
  const auto& pos = scene.mesh.positions;
  const auto& idx = scene.mesh.indices;
  const RayStream& rays = cones.axes.rays;
  const std::size_t side = std::size_t(hierarchy.side), width = std::size_t(out.width);

  std::vector<float> cov, dist, hu, hv;
  std::vector<std::uint8_t> flag;
  std::vector<std::uint32_t> compacted, pixel_of, grouped, scratch;
  std::vector<std::uint32_t> begin(npix + 1);
  const std::size_t block = std::max<std::size_t>(1, options.block_size);

  const CandidateConsumer consume = [&](std::span<const std::uint32_t> leaf, std::span<const std::uint32_t> tri) {
    const std::size_t m = leaf.size();
    cov.resize(m);
    dist.resize(m);
    hu.resize(m);
    hv.resize(m);
    flag.resize(m);
    ex.parallel_for("cone_triangle_coverage", m, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::size_t i = (leaf[k] / side) * width + leaf[k] % side;
        const std::uint32_t* t = &idx[3 * std::size_t(tri[k])];
        flag[k] = 0;
        const glm::vec3 o(rays.ox[i], rays.oy[i], rays.oz[i]), d(rays.dx[i], rays.dy[i], rays.dz[i]);
        if (is_ray(cones, i)) {  // the ray hierarchy's exact test, coverage 1 at the hit
          TriangleHit h;
          if (intersect_triangle_watertight(RayShear(o, d), pos[t[0]], pos[t[1]], pos[t[2]], rays.tmin[i],
                                            rays.tmax[i], h)) {
            cov[k] = 1.0f;
            dist[k] = h.t;
            hu[k] = h.u;
            hv[k] = h.v;
            flag[k] = 1;
          }
          continue;
        }
        if (tri[k] == cones.self[i]) continue;
        // Back faces (seen from the cone's origin) are hidden behind the front faces of the
        // same closed surface; the saturate blend would count that surface twice (ROGER
        // §5.2.4: the blend is wrong where one triangle masks another), so cones skip them.
        const glm::vec3 pa = pos[t[0]];
        if (glm::dot(glm::cross(pos[t[1]] - pa, pos[t[2]] - pa), pa - o) >= 0.0f) continue;
        Cone cone;
        cone.origin = o;
        cone.axis = glm::normalize(d);
        cone.radius = cones.radius[i];
        cone.tan_angle = std::tan(cones.angle[i]);
        cone.near = cones.near[i];
        cone.far = cones.far[i];
        ConeTriangleHit h;
        if (cone_triangle_coverage(cone, pos[t[0]], pos[t[1]], pos[t[2]], h)) {
          cov[k] = h.coverage;
          dist[k] = h.distance;
          hu[k] = h.u;
          hv[k] = h.v;
          flag[k] = 1;
        }
      }
    });
    compacted.resize(m);
    const std::size_t nh = par::compact_hierarchical(ex, "cone_hits_compact", flag, compacted, block, &scratch);
    out.pairs += m;
    out.hits += nh;
    if (nh == 0) return;
    pixel_of.resize(nh);
    ex.parallel_for("cone_hits_pixel", nh, kPairChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const std::uint32_t l = leaf[compacted[k]];
        pixel_of[k] = std::uint32_t((l / side) * width + l % side);
      }
    });
    grouped.resize(nh);
    par::partition_stable(ex, "cone_hits_partition", pixel_of, std::uint32_t(npix), grouped, begin);
    // Each pixel merges its hits of this batch into its n nearest by (distance, triangle): a
    // total order, so the kept set does not depend on how the triangles were batched.
    ex.parallel_for("cone_keep_nearest", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p) {
        for (std::uint32_t g = begin[p]; g < begin[p + 1]; ++g) {
          const std::size_t k = compacted[grouped[g]];
          const float dk = dist[k];
          const std::uint32_t tk = tri[k];
          ++out.total[p];
          float* D = &out.distance[p * K];
          std::uint32_t* T = &out.triangle[p * K];
          std::uint32_t c = out.count[p];
          auto before = [&](std::uint32_t j) { return dk < D[j] || (dk == D[j] && tk < T[j]); };
          if (c == K && !before(c - 1)) {
            out.dropped[p] += cov[k];
            continue;
          }
          if (c == K) out.dropped[p] += out.coverage[p * K + c - 1];
          std::uint32_t j = c == K ? c - 1 : c;  // the slot to fill (the farthest drops out)
          while (j > 0 && before(j - 1)) {
            D[j] = D[j - 1];
            T[j] = T[j - 1];
            out.coverage[p * K + j] = out.coverage[p * K + j - 1];
            out.u[p * K + j] = out.u[p * K + j - 1];
            out.v[p * K + j] = out.v[p * K + j - 1];
            --j;
          }
          D[j] = dk;
          T[j] = tk;
          out.coverage[p * K + j] = cov[k];
          out.u[p * K + j] = hu[k];
          out.v[p * K + j] = hv[k];
          if (c < K) out.count[p] = c + 1;
        }
      }
    });
  };
  hierarchy_candidates(ex, pos, idx, hierarchy, rays, consume, options, stats);
  for (std::size_t p = 0; p < npix; ++p) {
    out.overflow += out.total[p] - out.count[p];
    out.max_count = std::max(out.max_count, out.count[p]);
  }
  return out;
}

LayerGrid layer_grid(const ConeHits& hits) {
  LayerGrid g;
  g.width = hits.width;
  g.height = hits.height;
  const int layers = std::max<int>(1, int(hits.max_count));
  while (g.tx * g.tx < layers) ++g.tx;
  g.ty = (layers + g.tx - 1) / g.tx;
  return g;
}

SecondaryRays blend_layers(par::Executor& ex, const Scene& scene, const PixelCones& cones, const ConeHits& hits,
                           HitStream& layer_hits) {
  const LayerGrid grid = layer_grid(hits);
  SecondaryRays gen = empty_generation(grid.width * grid.tx, grid.height * grid.ty);
  const std::size_t n = gen.active.size();
  layer_hits.resize(n);
  std::fill(layer_hits.t.begin(), layer_hits.t.end(), kInf);
  std::fill(layer_hits.u.begin(), layer_hits.u.end(), 0.0f);
  std::fill(layer_hits.v.begin(), layer_hits.v.end(), 0.0f);
  std::fill(layer_hits.triangle.begin(), layer_hits.triangle.end(), kNoHit);
  const auto& pos = scene.mesh.positions;
  const auto& idx = scene.mesh.indices;
  const std::size_t npix = std::size_t(hits.width) * std::size_t(hits.height), K = std::size_t(hits.kept);
  ex.parallel_for("cone_blend", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      if (!cones.axes.active[p]) continue;
      const Ray axis = cones.axes.rays.get(p);
      float acc = 0.0f;
      for (std::uint32_t j = 0; j < hits.count[p]; ++j) {
        const std::size_t s = p * K + j;
        const float share = std::min(hits.coverage[s], 1.0f - acc);
        if (!(share > 0.0f)) break;
        acc += share;
        const std::size_t q = grid.index(p, j);
        Ray r = axis;
        float t = hits.distance[s];
        if (!is_ray(cones, p)) {  // towards the point seen along the region's centroid
          const std::uint32_t* tr = &idx[3 * std::size_t(hits.triangle[s])];
          const glm::vec3 x = (1.0f - hits.u[s] - hits.v[s]) * pos[tr[0]] + hits.u[s] * pos[tr[1]] +
                              hits.v[s] * pos[tr[2]];
          const glm::vec3 d = x - axis.origin;
          const float l = glm::length(d);
          if (l > 0.0f) r.direction = d / l;
          r.tmin = 0.0f;
          r.tmax = kInf;
          t = l;
        }
        gen.rays.set(q, r);
        gen.active[q] = 1;
        gen.weight[q] = cones.axes.weight[p] * share;
        layer_hits.t[q] = t;
        layer_hits.u[q] = hits.u[s];
        layer_hits.v[q] = hits.v[s];
        layer_hits.triangle[q] = hits.triangle[s];
      }
    }
  });
  count_active(gen);
  return gen;
}

ImageRGBA gather_layers(par::Executor& ex, const Scene& scene, const PixelCones& cones, const ConeHits& hits,
                        const ImageRGBA& layers, bool fill_dropped) {
  const LayerGrid grid = layer_grid(hits);
  ImageRGBA out(hits.width, hits.height, glm::vec4(0.0f));
  const std::size_t npix = std::size_t(hits.width) * std::size_t(hits.height), K = std::size_t(hits.kept);
  ex.parallel_for("cone_gather", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      if (!cones.axes.active[p]) continue;
      glm::vec4 c(0.0f);
      float acc = 0.0f;
      for (std::uint32_t j = 0; j < hits.count[p]; ++j) {
        const float share = std::min(hits.coverage[p * K + j], 1.0f - acc);
        if (!(share > 0.0f)) break;
        acc += share;
        c += layers.pixels[grid.index(p, j)];
      }
      float rest = 1.0f - acc;
      if (rest > 0.0f && fill_dropped && hits.dropped[p] > 0.0f && acc > 0.0f) {
        // The dropped hits' saturate share, in the kept hits' mean colour.
        const float share = std::min(hits.dropped[p], rest);
        c = glm::vec4(glm::vec3(c) * ((acc + share) / acc), c.w);
        rest -= share;
      }
      if (rest > 0.0f) {
        const glm::vec3 dir = glm::normalize(cones.axes.rays.get(p).direction);
        c += glm::vec4(cones.axes.weight[p] * rest * environment_radiance(scene.environment, dir), 0.0f);
      }
      out.pixels[p] = c;
    }
  });
  return out;
}

SecondaryRays first_layer_bounce(par::Executor& ex, const Scene& scene, const SecondaryRays& layers,
                                 const HitStream& layer_hits, const ConeHits& hits, std::uint64_t* dropped) {
  const LayerGrid grid = layer_grid(hits);
  const SecondaryRays all = bounce_rays(ex, scene, layers, layer_hits);
  SecondaryRays out = empty_generation(hits.width, hits.height);
  const std::size_t npix = out.active.size();
  const std::uint32_t layer_count = std::uint32_t(grid.tx * grid.ty);
  ex.parallel_for("cone_first_layer", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      std::size_t first = 0;
      bool found = false;
      glm::vec3 w(0.0f);
      for (std::uint32_t j = 0; j < layer_count; ++j) {
        const std::size_t q = grid.index(p, j);
        if (!all.active[q]) continue;
        if (!found) {
          first = q;
          found = true;
          w = all.weight[q];
        } else {
          w += all.weight[q];
        }
      }
      if (!found) continue;
      out.rays.set(p, all.rays.get(first));
      out.active[p] = 1;
      out.weight[p] = w;
    }
  });
  count_active(out);
  if (dropped) *dropped = all.count - out.count;
  return out;
}

SecondaryRays first_layer(par::Executor& ex, const SecondaryRays& layers, const HitStream& layer_hits,
                          const ConeHits& hits, HitStream& first_hits) {
  const LayerGrid grid = layer_grid(hits);
  SecondaryRays out = empty_generation(hits.width, hits.height);
  const std::size_t npix = out.active.size();
  first_hits.resize(npix);
  ex.parallel_for("cone_first_layer", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      const std::size_t q = grid.index(p, 0);
      first_hits.t[p] = layer_hits.t[q];
      first_hits.u[p] = layer_hits.u[q];
      first_hits.v[p] = layer_hits.v[q];
      first_hits.triangle[p] = layer_hits.triangle[q];
      if (!layers.active[q]) continue;
      out.rays.set(p, layers.rays.get(q));
      out.active[p] = 1;
      out.weight[p] = layers.weight[q];
    }
  });
  count_active(out);
  return out;
}

std::vector<HitStream> spread_first_layer_shadows(par::Executor& ex, const std::vector<HitStream>& first,
                                                  const ConeHits& hits) {
  const LayerGrid grid = layer_grid(hits);
  const std::size_t n = std::size_t(grid.width) * std::size_t(grid.tx) * std::size_t(grid.height) *
                        std::size_t(grid.ty);
  const std::size_t npix = std::size_t(hits.width) * std::size_t(hits.height);
  const std::uint32_t layers = std::uint32_t(grid.tx * grid.ty);
  std::vector<HitStream> out(first.size());
  for (std::size_t l = 0; l < first.size(); ++l) {
    HitStream& o = out[l];
    o.resize(n);
    ex.parallel_for("cone_shadow_spread", npix, kPixelChunk, [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p)
        for (std::uint32_t j = 0; j < layers; ++j) {
          const std::size_t q = grid.index(p, j);
          o.t[q] = first[l].t[p];
          o.u[q] = first[l].u[p];
          o.v[q] = first[l].v[p];
          o.triangle[q] = first[l].triangle[p];
        }
    });
  }
  return out;
}

}  // namespace speculum::trace
