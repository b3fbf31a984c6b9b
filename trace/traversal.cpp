// Closest-hit / any-hit traversal of the 8-wide and threaded BVH layouts, the all-pairs
// oracle and the chunked stream kernels (see traversal.h). Box tests are the slab test
// with the far distance widened by a few ulps (Ize, "Robust BVH ray traversal", 2013) so a
// rounding error never culls a box the watertight triangle test would hit.
#include "trace/traversal.h"

#include <algorithm>
#include <cmath>

#include "trace/ray_triangle.h"
#include "trace/scalar_box_test.h"
#include "trace/wide_kernels.h"

namespace speculum::trace {

namespace {

using scalar::box_hit;
using scalar::RayPrep;
using scalar::valid_ray;

// Closest-hit update with the lower-index tie rule.
inline void test_leaf_closest(const Bvh& bvh, const RayPrep& r, std::uint32_t first, std::uint32_t count,
                              Hit& best, TraversalCounters& c) {
  const auto& tris = bvh.leaf_triangles();
  const auto& ids = bvh.triangle_ids();
  for (std::uint32_t k = first; k < first + count; ++k) {
    ++c.triangle_tests;
    TriangleHit h;
    if (!intersect_triangle_watertight(r.shear, tris[k].a, tris[k].b, tris[k].c, r.tmin, best.t, h)) continue;
    const std::uint32_t id = ids[k];
    if (h.t < best.t || id < best.triangle) best = {h.t, h.u, h.v, id};
  }
}

[[gnu::always_inline]] inline void test_packs_closest(const TrianglePack* packs, const wide::PackRay& r, float tmin,
                                                          std::uint32_t ref, Hit& best, TraversalCounters& c) {
  const std::uint32_t first = (ref & ~kLeafBit) >> 2, count = (ref & 3u) + 1;
  for (std::uint32_t p = first; p < first + count; ++p) {
    const TrianglePack& pk = packs[p];
    c.triangle_tests += 4;
    float t[4], u[4], v[4];
    unsigned bits = wide::intersect_pack(pk, r, tmin, best.t, t, u, v);
    while (bits) {
      const int l = __builtin_ctz(bits);
      bits &= bits - 1;
      // Lanes were tested against the best t before this pack: compare t again.
      if (t[l] < best.t || (t[l] == best.t && pk.id[l] < best.triangle)) best = {t[l], u[l], v[l], pk.id[l]};
    }
  }
}

[[gnu::always_inline]] inline bool test_packs_any(const TrianglePack* packs, const wide::PackRay& r, float tmin,
                                                     float tmax, std::uint32_t ref, TraversalCounters& c) {
  const std::uint32_t first = (ref & ~kLeafBit) >> 2, count = (ref & 3u) + 1;
  for (std::uint32_t p = first; p < first + count; ++p) {
    c.triangle_tests += 4;
    float t[4], u[4], v[4];
    if (wide::intersect_pack(packs[p], r, tmin, tmax, t, u, v)) return true;
  }
  return false;
}

// Touches the lines of a child (a wide node's 224 bytes, or its leaf's first pack).
inline void prefetch_ref(const WideNode* nodes, const TrianglePack* packs, std::uint32_t ref) {
  const char* p = (ref & kLeafBit) ? reinterpret_cast<const char*>(&packs[(ref & ~kLeafBit) >> 2])
                                   : reinterpret_cast<const char*>(&nodes[ref]);
  _mm_prefetch(p, _MM_HINT_T0);
  _mm_prefetch(p + 64, _MM_HINT_T0);
  _mm_prefetch(p + 128, _MM_HINT_T0);
  if (!(ref & kLeafBit)) _mm_prefetch(p + 192, _MM_HINT_T0);
}

}  // namespace

Hit closest_hit(const Bvh& bvh, const Ray& ray, TraversalCounters* counters) {
  return closest_hit_limited_stack(bvh, ray, kTraversalStackSize, counters);
}

Hit closest_hit_limited_stack(const Bvh& bvh, const Ray& ray, int stack_limit, TraversalCounters* counters) {
  stack_limit = stack_limit < 1 ? 1 : (stack_limit > kTraversalStackSize ? kTraversalStackSize : stack_limit);
  TraversalCounters c;
  c.rays = 1;
  Hit best;
  best.t = ray.tmax;
  if (valid_ray(ray) && bvh.wide_root() != kEmptyChild) {
    const RayPrep r(ray);
    const wide::BoxRay br(r.o, r.d, r.inv, r.tmin);
    const wide::PackRay pr(r.shear);
    const WideNode* nodes = bvh.wide_nodes().data();
    const TrianglePack* packs = bvh.triangle_packs().data();
    // Pending children as two arrays, with room for a whole node's 8 lanes stored at once.
    alignas(32) std::uint32_t stack_ref[kTraversalStackSize + kWideArity];
    alignas(32) float stack_t[kTraversalStackSize + kWideArity];
    int sp = 0;
    std::uint32_t cur = bvh.wide_root();
    while (true) {
      if (cur & kLeafBit) {
        test_packs_closest(packs, pr, r.tmin, cur, best, c);
      } else {
        ++c.nodes_visited;
        const WideNode& n = nodes[cur];
        __m256 tnv;
        const unsigned bits = wide::box_hits(n, br, best.t, tnv);
        const int hits = __builtin_popcount(bits);
        if (hits == 1) {  // the common case: descend without the stack
          cur = n.child[__builtin_ctz(bits)];
          continue;
        }
        if (hits == 2) {  // push the farther, descend into the nearer (no branch on the order)
          alignas(32) float tn[kWideArity];
          _mm256_store_ps(tn, tnv);
          const int k0 = __builtin_ctz(bits), k1 = __builtin_ctz(bits & (bits - 1));
          const bool k1_nearer = tn[k1] < tn[k0];
          const int near = k1_nearer ? k1 : k0, far = k1_nearer ? k0 : k1;
          if (sp < stack_limit) {
            stack_ref[sp] = n.child[far];
            stack_t[sp++] = tn[far];
            prefetch_ref(nodes, packs, n.child[far]);
          } else {
            ++c.stack_overflows;
          }
          cur = n.child[near];
          continue;
        }
        if (hits > 2) {
          // Push all but the nearest, far to near, in one store of the sorted lanes; the
          // runner-up (the likely next pop) starts its cache lines now.
          const __m256i order = wide::order_far_to_near(bits, tnv);
          const __m256i refs = _mm256_permutevar8x32_epi32(
              _mm256_load_si256(reinterpret_cast<const __m256i*>(n.child)), order);
          const __m256 tns = _mm256_permutevar8x32_ps(tnv, order);
          const int pushed = std::min(hits - 1, stack_limit - sp);
          c.stack_overflows += static_cast<std::uint64_t>(hits - 1 - pushed);
          // An overflow keeps the farthest children (the lanes stored first).
          _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack_ref + sp), refs);
          _mm256_storeu_ps(stack_t + sp, tns);
          cur = stack_ref[sp + hits - 1];
          sp += pushed;
          if (pushed > 0) prefetch_ref(nodes, packs, stack_ref[sp - 1]);
          continue;
        }
      }
      // Pop the next entry still nearer than the best hit.
      bool found = false;
      while (sp > 0) {
        --sp;
        if (stack_t[sp] <= best.t) {
          cur = stack_ref[sp];
          found = true;
          break;
        }
      }
      if (!found) break;
    }
  }
  if (!best.hit()) best = Hit{};
  if (counters) counters->add(c);
  return best;
}

bool any_hit(const Bvh& bvh, const Ray& ray, TraversalCounters* counters) {
  TraversalCounters c;
  c.rays = 1;
  bool found = false;
  if (valid_ray(ray) && bvh.wide_root() != kEmptyChild) {
    const RayPrep r(ray);
    const wide::BoxRay br(r.o, r.d, r.inv, r.tmin);
    const wide::PackRay pr(r.shear);
    const auto& nodes = bvh.wide_nodes();
    const TrianglePack* packs = bvh.triangle_packs().data();
    std::uint32_t stack[kTraversalStackSize];
    int sp = 0;
    stack[sp++] = bvh.wide_root();
    while (sp > 0 && !found) {
      const std::uint32_t ref = stack[--sp];
      if (ref & kLeafBit) {
        found = test_packs_any(packs, pr, r.tmin, r.tmax, ref, c);
        continue;
      }
      ++c.nodes_visited;
      __m256 tn;
      unsigned bits = wide::box_hits(nodes[ref], br, r.tmax, tn);
      while (bits) {
        const int k = __builtin_ctz(bits);
        bits &= bits - 1;
        if (sp == kTraversalStackSize) {
          ++c.stack_overflows;
          continue;
        }
        stack[sp++] = nodes[ref].child[k];
      }
    }
  }
  if (counters) counters->add(c);
  return found;
}

Hit closest_hit_threaded(const Bvh& bvh, const Ray& ray, TraversalCounters* counters) {
  TraversalCounters c;
  c.rays = 1;
  Hit best;
  best.t = ray.tmax;
  const auto& nodes = bvh.threaded_nodes();
  if (valid_ray(ray) && !nodes.empty()) {
    const RayPrep r(ray);
    std::uint32_t i = 0;
    while (i != kThreadEnd) {
      const ThreadedNode& n = nodes[i];
      ++c.nodes_visited;
      float tnear;
      if (!box_hit(r, n.box, best.t, tnear)) {
        i = n.miss;
        continue;
      }
      if (n.count) test_leaf_closest(bvh, r, n.first, n.count, best, c);
      i = n.hit;
    }
  }
  if (!best.hit()) best = Hit{};
  if (counters) counters->add(c);
  return best;
}

Hit closest_hit_oracle(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx, const Ray& ray) {
  Hit best;
  best.t = ray.tmax;
  if (!valid_ray(ray)) return Hit{};
  const RayShear shear(ray.origin, ray.direction);
  for (std::size_t t = 0; t < idx.size() / 3; ++t) {
    TriangleHit h;
    if (!intersect_triangle_watertight(shear, p[idx[3 * t]], p[idx[3 * t + 1]], p[idx[3 * t + 2]], ray.tmin,
                                       best.t, h))
      continue;
    const auto id = static_cast<std::uint32_t>(t);
    if (h.t < best.t || id < best.triangle) best = {h.t, h.u, h.v, id};
  }
  if (!best.hit()) best = Hit{};
  return best;
}

bool any_hit_oracle(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx, const Ray& ray) {
  if (!valid_ray(ray)) return false;
  const RayShear shear(ray.origin, ray.direction);
  for (std::size_t t = 0; t < idx.size() / 3; ++t) {
    TriangleHit h;
    if (intersect_triangle_watertight(shear, p[idx[3 * t]], p[idx[3 * t + 1]], p[idx[3 * t + 2]], ray.tmin,
                                      ray.tmax, h))
      return true;
  }
  return false;
}

void RayStream::set(std::size_t i, const Ray& r) {
  ox[i] = r.origin.x; oy[i] = r.origin.y; oz[i] = r.origin.z;
  dx[i] = r.direction.x; dy[i] = r.direction.y; dz[i] = r.direction.z;
  tmin[i] = r.tmin; tmax[i] = r.tmax;
}
Ray RayStream::get(std::size_t i) const {
  Ray r;
  r.origin = {ox[i], oy[i], oz[i]};
  r.direction = {dx[i], dy[i], dz[i]};
  r.tmin = tmin[i];
  r.tmax = tmax[i];
  return r;
}
void HitStream::resize(std::size_t n) {
  t.resize(n);
  u.resize(n);
  v.resize(n);
  triangle.resize(n);
}

void closest_hit_stream(const Bvh& bvh, const RayStream& rays, HitStream& hits, par::Executor& ex,
                        TraversalCounters* counters) {
  const std::size_t n = rays.size();
  hits.resize(n);
  const std::size_t chunks = (n + kRayChunk - 1) / kRayChunk;
  std::vector<TraversalCounters> per_chunk(counters ? chunks : 0);
  ex.parallel_for("trace_closest", n, kRayChunk, [&](std::size_t b, std::size_t e) {
    TraversalCounters c;
    // One ray at a time: a kernel that interleaved 8 rays per thread (to overlap their cache
    // misses) measured 0.74-0.87x this one on incoherent reflect-cone30 rays (1M triangles).
    for (std::size_t i = b; i < e; ++i) {
      const Hit h = closest_hit(bvh, rays.get(i), &c);
      hits.t[i] = h.t;
      hits.u[i] = h.u;
      hits.v[i] = h.v;
      hits.triangle[i] = h.triangle;
    }
    if (counters) per_chunk[b / kRayChunk] = c;
  });
  if (counters)
    for (const auto& c : per_chunk) counters->add(c);
}

}  // namespace speculum::trace
