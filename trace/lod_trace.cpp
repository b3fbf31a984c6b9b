// The LOD traversal kernel (see lod_trace.h), YU §3.4 eq.6–7. The box and leaf tests are
// those of trace/traversal.cpp (same slab widening, same watertight test, same tie rule:
// equal t goes to the lower triangle index), so with LOD off the hits equal
// closest_hit_threaded's bit for bit.
#include "trace/lod_trace.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "parallel/page_buffer.h"
#include "trace/glossy_rays.h"
#include "trace/ray_triangle.h"
#include "trace/scalar_box_test.h"

namespace speculum::trace {

namespace {

using scalar::box_hit;
using scalar::RayPrep;
using scalar::valid_ray;

inline bool inside(const Aabb& b, const glm::vec3& p) {
  return p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y &&
         p.z <= b.hi.z;
}

// The quad proxy of node n, both faces; accepts t in (tmin, tmax).
inline bool intersect_proxy(const RayPrep& r, const LodNode& n, float tmax, float& t_out,
                            float& s_out, float& w_out) {
  const float denom = glm::dot(r.d, n.normal);
  if (std::fabs(denom) < 1e-12f) return false;
  const float t = glm::dot(n.origin - r.o, n.normal) / denom;
  if (!(t > r.tmin && t < tmax)) return false;
  const glm::vec3 p = r.o + t * r.d - n.origin;
  const float uu = glm::dot(n.edge_u, n.edge_u), vv = glm::dot(n.edge_v, n.edge_v);
  const float s = uu > 0.0f ? glm::dot(p, n.edge_u) / uu : 0.0f;
  const float w = vv > 0.0f ? glm::dot(p, n.edge_v) / vv : 0.0f;
  if (s < 0.0f || s > 1.0f || w < 0.0f || w > 1.0f) return false;
  if (!LodBvh::proxy_covers(n, s, w)) return false;  // the surface does not reach this texel
  t_out = t;
  s_out = s;
  w_out = w;
  return true;
}


// The traversal, compiled once with the eq.7 test and once without it (LOD off: exactly the
// threaded traversal's loop, with no per-node LOD branch).
template <bool kLod>
LodHit traverse(const Bvh& bvh, const LodBvh& lod, const Ray& ray, float budget, LodCounters& c) {
  LodHit best;
  best.t = ray.tmax;
  const ThreadedNode* nodes = bvh.threaded_nodes().data();
  const LeafTriangle* tris = bvh.leaf_triangles().data();
  const std::uint32_t* ids = bvh.triangle_ids().data();
  const float* stop_k = lod.stop_k.data();
  if (!valid_ray(ray) || bvh.threaded_nodes().empty()) return best;
  const RayPrep r(ray);
  std::uint64_t visited = 0, tested = 0;
  std::uint32_t i = 0;
  while (i != kThreadEnd) {
    const ThreadedNode& n = nodes[i];
    ++visited;
    float tnear;
    if (!box_hit(r, n.box, best.t, tnear)) {
      i = n.miss;
      continue;
    }
    if constexpr (kLod) {
      if (n.count == 0) {
        // eq.7 as Ω_box ≤ α² Ω_s, with eq.6's division moved to the right-hand side.
        const glm::vec3 to_center = n.box.center() - r.o;
        if (stop_k[i] <= budget * glm::dot(to_center, to_center) && !inside(n.box, r.o)) {
          ++c.lod_stops;
          float t, s, w;
          if (intersect_proxy(r, lod.nodes[i], best.t, t, s, w)) {
            best.t = t;
            best.u = s;
            best.v = w;
            best.triangle = kNoHit;
            best.proxy = i;
          }
          i = n.miss;
          continue;
        }
      }
    }
    for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
      ++tested;
      TriangleHit h;
      if (!intersect_triangle_watertight(r.shear, tris[k].a, tris[k].b, tris[k].c, r.tmin, best.t, h))
        continue;
      const std::uint32_t id = ids[k];
      if (h.t < best.t || id < best.triangle) {
        best.t = h.t;
        best.u = h.u;
        best.v = h.v;
        best.triangle = id;
        best.proxy = kNoHit;
      }
    }
    i = n.hit;
  }
  c.traversal.nodes_visited += visited;
  c.traversal.triangle_tests += tested;
  return best;
}

// Accumulates into `c` (one ray).
LodHit closest_hit_lod_into(const Bvh& bvh, const LodBvh& lod, const Ray& ray, float solid_angle,
                            const LodOptions& opt, LodCounters& c) {
  ++c.traversal.rays;
  const float budget = opt.alpha * opt.alpha * solid_angle;
  const bool lod_on = opt.enabled && budget > 0.0f && lod.nodes.size() == bvh.threaded_nodes().size() &&
                      lod.stop_k.size() == lod.nodes.size();
  LodHit best = lod_on ? traverse<true>(bvh, lod, ray, budget, c) : traverse<false>(bvh, lod, ray, budget, c);
  if (!best.hit()) best = LodHit{};
  if (best.proxy != kNoHit) ++c.proxy_hits;
  return best;
}

}  // namespace

LodHit closest_hit_lod(const Bvh& bvh, const LodBvh& lod, const Ray& ray, float solid_angle,
                       const LodOptions& opt, LodCounters* counters) {
  LodCounters c;
  const LodHit best = closest_hit_lod_into(bvh, lod, ray, solid_angle, opt, c);
  if (counters) counters->add(c);
  return best;
}

void closest_hit_lod_stream(const Bvh& bvh, const LodBvh& lod, const RayStream& rays,
                            const std::vector<float>& solid_angle, const LodOptions& opt,
                            std::vector<LodHit>& hits, par::Executor& ex, LodCounters* counters) {
  const std::size_t n = rays.size();
  par::resize_on_huge_pages(hits, n);
  const std::size_t chunks = (n + kRayChunk - 1) / kRayChunk;
  std::vector<LodCounters> per_chunk(chunks);
  ex.parallel_for("lod_trace", n, kRayChunk, [&](std::size_t b, std::size_t e) {
    LodCounters c;
    for (std::size_t i = b; i < e; ++i) {
      const float omega = i < solid_angle.size() ? solid_angle[i] : 0.0f;
      Ray ray;
      ray.origin = {rays.ox[i], rays.oy[i], rays.oz[i]};
      ray.direction = {rays.dx[i], rays.dy[i], rays.dz[i]};
      ray.tmin = rays.tmin[i];
      ray.tmax = rays.tmax[i];
      hits[i] = closest_hit_lod_into(bvh, lod, ray, omega, opt, c);
    }
    per_chunk[b / kRayChunk] = c;
  });
  if (counters)
    for (const auto& c : per_chunk) counters->add(c);
}

}  // namespace speculum::trace
