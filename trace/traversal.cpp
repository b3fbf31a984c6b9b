// Closest-hit / any-hit traversal of the 4-wide and threaded BVH layouts, the all-pairs
// oracle and the chunked stream kernels (see traversal.h). Box tests are the slab test
// with the far distance widened by a few ulps (Ize, "Robust BVH ray traversal", 2013) so a
// rounding error never culls a box the watertight triangle test would hit.
#include "trace/traversal.h"

#include <algorithm>
#include <cmath>

#include "parallel/lanes.h"
#include "trace/ray_triangle.h"

namespace speculum::trace {

namespace {

// Lanes<W>::min/max are select-based (NaN and ±0 identical for every W), which costs a
// bitset-mask round trip per call in fixed_size simd. The box and leaf kernels here run
// at one fixed width and only ever take min/max of non-NaN values (or of padding lanes
// whose result is discarded), where the hardware min/max give the same values.
template <class V>
inline V vmin(const V& a, const V& b) { return std::experimental::min(a, b); }
template <class V>
inline V vmax(const V& a, const V& b) { return std::experimental::max(a, b); }

constexpr float kFarWiden = 1.0f + 8.0f * 5.96e-8f;   // > 1 + 2 gamma(3)
constexpr float kNearShrink = 1.0f - 8.0f * 5.96e-8f;  // the same margin on the entry side

struct RayPrep {
  glm::vec3 o, d, inv;
  float tmin, tmax;
  RayShear shear;
  explicit RayPrep(const Ray& r) : o(r.origin), d(r.direction), tmin(r.tmin), tmax(r.tmax), shear(r.origin, r.direction) {
    // A zero direction component becomes a huge reciprocal instead of inf, so (lo-o)*inv
    // is never 0*inf = NaN; the slab then spans everything or nothing, as it should.
    for (int a = 0; a < 3; ++a) {
      const float c = std::fabs(d[a]) < 1e-30f ? std::copysign(1e-30f, d[a]) : d[a];
      inv[a] = 1.0f / c;
    }
  }
};

inline bool valid_ray(const Ray& r) {
  const glm::vec3& d = r.direction;
  return (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f) && std::isfinite(d.x) && std::isfinite(d.y) &&
         std::isfinite(d.z) && std::isfinite(r.origin.x) && std::isfinite(r.origin.y) &&
         std::isfinite(r.origin.z) && !(r.tmin > r.tmax);
}

inline bool box_hit(const RayPrep& r, const Aabb& b, float tmax, float& tnear) {
  float t0 = r.tmin, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    float lo = (b.lo[a] - r.o[a]) * r.inv[a];
    float hi = (b.hi[a] - r.o[a]) * r.inv[a];
    if (lo > hi) std::swap(lo, hi);
    lo = lo > 0.0f ? lo * kNearShrink : lo * kFarWiden;
    t0 = lo > t0 ? lo : t0;
    t1 = hi * kFarWiden < t1 ? hi * kFarWiden : t1;
  }
  tnear = t0;
  return t0 <= t1 && !b.empty();
}

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

inline bool test_leaf_any(const Bvh& bvh, const RayPrep& r, std::uint32_t first, std::uint32_t count,
                          TraversalCounters& c) {
  const auto& tris = bvh.leaf_triangles();
  for (std::uint32_t k = first; k < first + count; ++k) {
    ++c.triangle_tests;
    TriangleHit h;
    if (intersect_triangle_watertight(r.shear, tris[k].a, tris[k].b, tris[k].c, r.tmin, r.tmax, h)) return true;
  }
  return false;
}

// The 8 child boxes of a wide node in lanes. Near and far planes are picked by the sign of
// the direction (not by min/max), so an inverted (empty) box always misses. Returns the
// bit mask of hit children and their entry distances.
struct WideRay {
  glm::vec3 o, inv;
  float tmin;
  bool neg[3];
  explicit WideRay(const RayPrep& r) : o(r.o), inv(r.inv), tmin(r.tmin) {
    for (int a = 0; a < 3; ++a) neg[a] = std::signbit(r.inv[a]);
  }
};

[[gnu::always_inline]] inline unsigned wide_box_hits(const WideNode& n, const WideRay& r, float tmax, float (&tnear)[kWideArity]) {
  using L = par::Lanes<kWideArity>;
  const L::f32 nx = L::load(r.neg[0] ? n.hi_x : n.lo_x), fx = L::load(r.neg[0] ? n.lo_x : n.hi_x);
  const L::f32 ny = L::load(r.neg[1] ? n.hi_y : n.lo_y), fy = L::load(r.neg[1] ? n.lo_y : n.hi_y);
  const L::f32 nz = L::load(r.neg[2] ? n.hi_z : n.lo_z), fz = L::load(r.neg[2] ? n.lo_z : n.hi_z);
  const L::f32 ox(r.o.x), oy(r.o.y), oz(r.o.z), ix(r.inv.x), iy(r.inv.y), iz(r.inv.z);
  // Clamped to finite values: an empty child's inverted box gives entry +inf / exit -inf,
  // and the widening below must not turn them into inf - inf = NaN.
  const L::f32 big(3.0e38f);
  const L::f32 entry = vmin(vmax(vmax((nx - ox) * ix, (ny - oy) * iy), (nz - oz) * iz), big);
  const L::f32 exit = vmax(vmin(vmin((fx - ox) * ix, (fy - oy) * iy), (fz - oz) * iz), -big);
  // Widen by a few ulps (entry down, exit up) so rounding never culls a hit. Written with
  // abs rather than a select: fixed_size masks are bitsets, and a select costs a round trip.
  const L::f32 eps(kFarWiden - 1.0f);
  const L::f32 near = vmax(entry - L::abs(entry) * eps, L::f32(r.tmin));
  const L::f32 far = vmin(exit + L::abs(exit) * eps, L::f32(tmax));
  float fa[kWideArity];
  L::store(near, tnear);
  L::store(far, fa);
  unsigned bits = 0;
  for (int k = 0; k < kWideArity; ++k) bits |= static_cast<unsigned>(tnear[k] <= fa[k]) << k;
  return bits;
}

// The watertight test (ray_triangle.h) on 4 triangles in lanes, with exactly the scalar
// operation sequence so every lane's t bits equal the scalar test's; a lane whose edge
// function is exactly zero is redone by the scalar test (its double fallback).
struct PackRay {
  int kx, ky, kz;
  float sx, sy, sz;
  glm::vec3 o;
};

// Returns the mask of lanes hit in [tmin, tmax] and their t, u, v.
[[gnu::always_inline]] inline unsigned intersect_pack(const TrianglePack& p, const RayPrep& r, float tmin, float tmax, float (&t)[4],
                               float (&u)[4], float (&v)[4]) {
  using L = par::Lanes<4>;
  const RayShear& sh = r.shear;
  const float* a[3] = {p.ax, p.ay, p.az};
  const float* b[3] = {p.bx, p.by, p.bz};
  const float* c[3] = {p.cx, p.cy, p.cz};
  const L::f32 okx(sh.origin[sh.kx]), oky(sh.origin[sh.ky]), okz(sh.origin[sh.kz]);
  const L::f32 Akx = L::load(a[sh.kx]) - okx, Aky = L::load(a[sh.ky]) - oky, Akz = L::load(a[sh.kz]) - okz;
  const L::f32 Bkx = L::load(b[sh.kx]) - okx, Bky = L::load(b[sh.ky]) - oky, Bkz = L::load(b[sh.kz]) - okz;
  const L::f32 Ckx = L::load(c[sh.kx]) - okx, Cky = L::load(c[sh.ky]) - oky, Ckz = L::load(c[sh.kz]) - okz;
  const L::f32 sx(sh.sx), sy(sh.sy), sz(sh.sz);
  const L::f32 ax = Akx - sx * Akz, ay = Aky - sy * Akz;
  const L::f32 bx = Bkx - sx * Bkz, by = Bky - sy * Bkz;
  const L::f32 cx = Ckx - sx * Ckz, cy = Cky - sy * Ckz;
  const L::f32 U = cx * by - cy * bx;
  const L::f32 V = ax * cy - ay * cx;
  const L::f32 W = bx * ay - by * ax;
  const L::f32 zero(0.0f);
  const L::f32 det = U + V + W;
  const L::f32 T = U * (sz * Akz) + V * (sz * Bkz) + W * (sz * Ckz);
  const L::f32 inv = L::f32(1.0f) / det;
  const L::f32 tt = T * inv;
  // An exactly-zero edge function anywhere (or a product that underflows: a harmless false
  // alarm) sends the pack to the scalar path with its double-precision fallback.
  const auto zero_edge = (U * V * W) == zero;
  unsigned bits = 0;
  if (!L::any(zero_edge)) {
    // The common case, branch-free, as few lane masks as possible (each is a bitset round
    // trip in fixed_size simd): same-sign edge functions, t in range. det == 0 needs no
    // test: with mixed signs excluded it means t = T/0 = ±inf or NaN, which fails the range
    // test, as do the NaN lanes of unused slots.
    const L::f32 mn = vmin(vmin(U, V), W), mx = vmax(vmax(U, V), W);
    const auto ok = ((mn >= zero) || (mx <= zero)) && (tt >= L::f32(tmin)) && (tt <= L::f32(tmax));
    if (L::none(ok)) return 0;
    const L::f32 weights([](int l) { return static_cast<float>(1 << l); });
    bits = static_cast<unsigned>(L::hadd(L::select(ok, weights, zero)));  // exact: small integers
    L::store(tt, t);
    L::store(V * inv, u);
    L::store(W * inv, v);
    return bits;
  }
  float Us[4], Vs[4], Ws[4], dets[4], ts[4], invs[4];
  L::store(U, Us); L::store(V, Vs); L::store(W, Ws); L::store(det, dets); L::store(tt, ts); L::store(inv, invs);
  for (int l = 0; l < 4; ++l) {
    if (p.id[l] == kEmptyChild) continue;
    if (Us[l] == 0.0f || Vs[l] == 0.0f || Ws[l] == 0.0f) {
      TriangleHit h;
      const glm::vec3 A(p.ax[l], p.ay[l], p.az[l]), B(p.bx[l], p.by[l], p.bz[l]), C(p.cx[l], p.cy[l], p.cz[l]);
      if (intersect_triangle_watertight(sh, A, B, C, tmin, tmax, h)) {
        t[l] = h.t; u[l] = h.u; v[l] = h.v;
        bits |= 1u << l;
      }
      continue;
    }
    const bool neg = Us[l] < 0.0f || Vs[l] < 0.0f || Ws[l] < 0.0f;
    const bool pos = Us[l] > 0.0f || Vs[l] > 0.0f || Ws[l] > 0.0f;
    if ((neg && pos) || dets[l] == 0.0f) continue;
    if (!(ts[l] >= tmin && ts[l] <= tmax)) continue;
    t[l] = ts[l];
    u[l] = Vs[l] * invs[l];
    v[l] = Ws[l] * invs[l];
    bits |= 1u << l;
  }
  return bits;
}

[[gnu::always_inline]] inline void test_packs_closest(const Bvh& bvh, const RayPrep& r, std::uint32_t ref, Hit& best,
                               TraversalCounters& c) {
  const std::uint32_t first = (ref & ~kLeafBit) >> 2, count = (ref & 3u) + 1;
  const auto& packs = bvh.triangle_packs();
  for (std::uint32_t p = first; p < first + count; ++p) {
    const TrianglePack& pk = packs[p];
    c.triangle_tests += 4;
    float t[4], u[4], v[4];
    unsigned bits = intersect_pack(pk, r, r.tmin, best.t, t, u, v);
    while (bits) {
      const int l = __builtin_ctz(bits);
      bits &= bits - 1;
      // Lanes were tested against the best t before this pack: compare t again.
      if (t[l] < best.t || (t[l] == best.t && pk.id[l] < best.triangle)) best = {t[l], u[l], v[l], pk.id[l]};
    }
  }
}

[[gnu::always_inline]] inline bool test_packs_any(const Bvh& bvh, const RayPrep& r, std::uint32_t ref, TraversalCounters& c) {
  const std::uint32_t first = (ref & ~kLeafBit) >> 2, count = (ref & 3u) + 1;
  const auto& packs = bvh.triangle_packs();
  for (std::uint32_t p = first; p < first + count; ++p) {
    c.triangle_tests += 4;
    float t[4], u[4], v[4];
    if (intersect_pack(packs[p], r, r.tmin, r.tmax, t, u, v)) return true;
  }
  return false;
}

struct StackEntry {
  std::uint32_t ref;
  float tnear;
};

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
    const WideRay wr(r);
    const auto& nodes = bvh.wide_nodes();
    StackEntry stack[kTraversalStackSize];
    int sp = 0;
    StackEntry cur{bvh.wide_root(), ray.tmin};
    while (true) {
      if (cur.ref & kLeafBit) {
        test_packs_closest(bvh, r, cur.ref, best, c);
      } else {
        ++c.nodes_visited;
        const WideNode& n = nodes[cur.ref];
        float tn[kWideArity];
        unsigned bits = wide_box_hits(n, wr, best.t, tn);
        if (bits) {
          int k = __builtin_ctz(bits);
          bits &= bits - 1;
          if (!bits) {  // one child hit (the common case): descend without the stack
            cur = {n.child[k], tn[k]};
            continue;
          }
          // Several: push all but the nearest, far-to-near, and descend into the nearest.
          StackEntry hits[kWideArity];
          hits[0] = {n.child[k], tn[k]};
          int count = 1;
          while (bits) {
            k = __builtin_ctz(bits);
            bits &= bits - 1;
            const StackEntry s{n.child[k], tn[k]};
            int j = count++;
            while (j > 0 && hits[j - 1].tnear < s.tnear) {
              hits[j] = hits[j - 1];
              --j;
            }
            hits[j] = s;
          }
          for (int i = 0; i + 1 < count; ++i) {
            if (sp == stack_limit) {
              ++c.stack_overflows;
              continue;
            }
            stack[sp++] = hits[i];
          }
          cur = hits[count - 1];
          continue;
        }
      }
      // Pop the next entry still nearer than the best hit.
      bool found = false;
      while (sp > 0) {
        cur = stack[--sp];
        if (cur.tnear <= best.t) {
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
    const WideRay wr(r);
    const auto& nodes = bvh.wide_nodes();
    std::uint32_t stack[kTraversalStackSize];
    int sp = 0;
    stack[sp++] = bvh.wide_root();
    while (sp > 0 && !found) {
      const std::uint32_t ref = stack[--sp];
      if (ref & kLeafBit) {
        found = test_packs_any(bvh, r, ref, c);
        continue;
      }
      ++c.nodes_visited;
      float tn[kWideArity];
      unsigned bits = wide_box_hits(nodes[ref], wr, r.tmax, tn);
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

bool any_hit_threaded(const Bvh& bvh, const Ray& ray, TraversalCounters* counters) {
  TraversalCounters c;
  c.rays = 1;
  bool found = false;
  const auto& nodes = bvh.threaded_nodes();
  if (valid_ray(ray) && !nodes.empty()) {
    const RayPrep r(ray);
    std::uint32_t i = 0;
    while (i != kThreadEnd && !found) {
      const ThreadedNode& n = nodes[i];
      ++c.nodes_visited;
      float tnear;
      if (!box_hit(r, n.box, r.tmax, tnear)) {
        i = n.miss;
        continue;
      }
      if (n.count) found = test_leaf_any(bvh, r, n.first, n.count, c);
      i = n.hit;
    }
  }
  if (counters) counters->add(c);
  return found;
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

void RayStream::resize(std::size_t n) {
  for (auto* v : {&ox, &oy, &oz, &dx, &dy, &dz, &tmin, &tmax}) v->resize(n);
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

void any_hit_stream(const Bvh& bvh, const RayStream& rays, std::vector<std::uint8_t>& occluded,
                    par::Executor& ex, TraversalCounters* counters) {
  const std::size_t n = rays.size();
  occluded.resize(n);
  const std::size_t chunks = (n + kRayChunk - 1) / kRayChunk;
  std::vector<TraversalCounters> per_chunk(counters ? chunks : 0);
  ex.parallel_for("trace_any", n, kRayChunk, [&](std::size_t b, std::size_t e) {
    TraversalCounters c;
    for (std::size_t i = b; i < e; ++i) occluded[i] = any_hit(bvh, rays.get(i), &c) ? 1 : 0;
    if (counters) per_chunk[b / kRayChunk] = c;
  });
  if (counters)
    for (const auto& c : per_chunk) counters->add(c);
}

}  // namespace speculum::trace
