// 8- and 16-ray packet traversal of the 8-wide BVH (see packet_traversal.h). Culling is
// conservative by monotonicity: every float operation of the single-ray slab test is
// monotone in its operands, so the same operations applied to the packet's extreme
// origins and reciprocals bound every ray's computed entry (from below) and exit (from
// above); a box any ray would enter, the packet enters. Leaves then use each ray's own
// box test and the watertight pack test, so hits equal closest_hit's bit for bit.
//
// Measured on 1M primary rays of the 1.02M-triangle yardstick scene (trace CPU time, one
// thread, same hits) and not kept: the per-ray leaf kernels in AVX-512 (16 rays in one
// register, a GCC target region picked at run time) 82-87 ms against 79-80 for the two
// AVX2 halves, and 87 ms with only the leaf box test in AVX-512; tiles in 16x16-pixel
// blocks per chunk instead of 64x4 strips 87-89 ms against 77-79; the packet setup's
// seven divisions and square root per ray in 8-lane registers 80.3 against 80.8; leaf
// children in near-to-far order 10.79 -> 10.54 triangle tests per ray, time unchanged.
#include "trace/packet_traversal.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "trace/ray_triangle.h"
#include "trace/wide_kernels.h"

namespace speculum::trace {

namespace {

// A packet's directions must agree in sign per axis (the near plane is then the same
// for all rays) and be close: the interval bounds of a wide fan cull little.
constexpr float kMaxDirectionSpread = 0.05f;  // per component of the normalized direction

// The most packets a stream chunk traces as single rays after a refused packet.
constexpr int kMaxSkippedPackets = 8;

struct Packet {
  int count = 0;
  int halves = 1;  // 8-lane halves in use: 1 for up to 8 rays, 2 for up to 16
  // Per ray (lanes), for the per-ray leaf box test.
  alignas(32) float ox[kMaxPacketSize], oy[kMaxPacketSize], oz[kMaxPacketSize];
  alignas(32) float ix[kMaxPacketSize], iy[kMaxPacketSize], iz[kMaxPacketSize];
  alignas(32) float tmin[kMaxPacketSize], best_t[kMaxPacketSize];
  RayShear shear[kMaxPacketSize];
  // When every ray has the same watertight axis permutation (kx, ky, kz), the leaf test
  // runs across the rays, one triangle at a time: the shear in lanes.
  bool common_shear = false;
  std::uint32_t offx = 0, offy = 0, offz = 0;  // the common kx/ky/kz rows (wide::pack_axis_offset)
  alignas(32) float okx[kMaxPacketSize], oky[kMaxPacketSize], okz[kMaxPacketSize];
  alignas(32) float sx[kMaxPacketSize], sy[kMaxPacketSize], sz[kMaxPacketSize];
  // Packet bounds for the interval node test.
  __m256 near_o[3], far_o[3], inv_lo[3], inv_hi[3], tmin_lo;
  std::uint32_t near_off[3], far_off[3];  // plane rows of a WideNode picked by the signs
};

// Interval test of the packet against a node's 8 children: bit k when some ray may enter
// child k before max_t; tnear gets a lower bound of the rays' widened entries.
[[gnu::always_inline]] inline unsigned packet_box_hits(const WideNode& n, const Packet& p, float max_t,
                                                       __m256& tnear) {
  const char* base = reinterpret_cast<const char*>(&n);
  auto plane = [base](std::uint32_t off) { return _mm256_load_ps(reinterpret_cast<const float*>(base + off)); };
  __m256 entry = _mm256_set1_ps(-3.0e38f), exit = _mm256_set1_ps(3.0e38f);
  for (int a = 0; a < 3; ++a) {
    const __m256 dn = _mm256_sub_ps(plane(p.near_off[a]), p.near_o[a]);
    const __m256 df = _mm256_sub_ps(plane(p.far_off[a]), p.far_o[a]);
    entry = _mm256_max_ps(entry, _mm256_min_ps(_mm256_mul_ps(dn, p.inv_lo[a]), _mm256_mul_ps(dn, p.inv_hi[a])));
    exit = _mm256_min_ps(exit, _mm256_max_ps(_mm256_mul_ps(df, p.inv_lo[a]), _mm256_mul_ps(df, p.inv_hi[a])));
  }
  const __m256 big = _mm256_set1_ps(3.0e38f), eps = _mm256_set1_ps(2.0f * wide::kWiden);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  entry = _mm256_min_ps(entry, big);
  exit = _mm256_max_ps(exit, _mm256_sub_ps(_mm256_setzero_ps(), big));
  const __m256 near = _mm256_max_ps(_mm256_sub_ps(entry, _mm256_mul_ps(_mm256_and_ps(entry, abs_mask), eps)), p.tmin_lo);
  const __m256 far = _mm256_min_ps(_mm256_add_ps(exit, _mm256_mul_ps(_mm256_and_ps(exit, abs_mask), eps)),
                                   _mm256_set1_ps(max_t));
  tnear = near;
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ)));
}

// Child k's box against each ray (lanes) with its own best t: the single-ray box test of
// wide_kernels.h, transposed. Bit r when ray r enters the box.
[[gnu::always_inline]] inline unsigned rays_box_hits_half(const WideNode& n, int k, const Packet& p, int half) {
  const float* rows = n.lo_x;
  auto bcast = [&](std::uint32_t off) {
    return _mm256_set1_ps(*reinterpret_cast<const float*>(reinterpret_cast<const char*>(rows) + off + 4u * k));
  };
  const int h = 8 * half;
  const __m256 o[3] = {_mm256_load_ps(p.ox + h), _mm256_load_ps(p.oy + h), _mm256_load_ps(p.oz + h)};
  const __m256 inv[3] = {_mm256_load_ps(p.ix + h), _mm256_load_ps(p.iy + h), _mm256_load_ps(p.iz + h)};
  __m256 entry = _mm256_set1_ps(-3.0e38f), exit = _mm256_set1_ps(3.0e38f);
  for (int a = 0; a < 3; ++a) {
    entry = _mm256_max_ps(entry, _mm256_mul_ps(_mm256_sub_ps(bcast(p.near_off[a]), o[a]), inv[a]));
    exit = _mm256_min_ps(exit, _mm256_mul_ps(_mm256_sub_ps(bcast(p.far_off[a]), o[a]), inv[a]));
  }
  const __m256 big = _mm256_set1_ps(3.0e38f), eps = _mm256_set1_ps(wide::kWiden);
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  entry = _mm256_min_ps(entry, big);
  exit = _mm256_max_ps(exit, _mm256_sub_ps(_mm256_setzero_ps(), big));
  const __m256 near = _mm256_max_ps(_mm256_sub_ps(entry, _mm256_mul_ps(_mm256_and_ps(entry, abs_mask), eps)),
                                    _mm256_load_ps(p.tmin + h));
  const __m256 far = _mm256_min_ps(_mm256_add_ps(exit, _mm256_mul_ps(_mm256_and_ps(exit, abs_mask), eps)),
                                   _mm256_load_ps(p.best_t + h));
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ)));
}

[[gnu::always_inline]] inline unsigned rays_box_hits(const WideNode& n, int k, const Packet& p) {
  unsigned bits = rays_box_hits_half(n, k, p, 0);
  if (p.halves == 2) bits |= rays_box_hits_half(n, k, p, 1) << 8;
  return bits;
}

inline float lane_max(const Packet& p) {
  float m = p.best_t[0];
  for (int i = 1; i < 8 * p.halves; ++i) m = p.best_t[i] > m ? p.best_t[i] : m;
  return m;
}

// Fills the packet; false when the rays are not coherent enough (or not all valid).
bool prepare(const Ray* rays, int count, Packet& p) {
  p.count = count;
  // Coherence first (cheap, and most incoherent packets stop here): valid rays, no
  // clamped axis (those need the single-ray origin shift of wide_kernels.h), direction
  // signs equal per axis and normalized directions within kMaxDirectionSpread.
  glm::vec3 dlo(3.0e38f), dhi(-3.0e38f);
  for (int r = 0; r < count; ++r) {
    const Ray& ray = rays[r];
    if (!wide::valid_ray(ray) || wide::has_clamped_axis(ray.direction)) return false;
    const glm::vec3& d = ray.direction;
    // Only the coherence decision reads dn (both paths give the same hits): one division.
    const glm::vec3 dn = d * (1.0f / std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z));
    dlo = glm::min(dlo, dn);
    dhi = glm::max(dhi, dn);
  }
  for (int a = 0; a < 3; ++a)
    if (dhi[a] - dlo[a] > kMaxDirectionSpread || (dlo[a] < 0.0f) != (dhi[a] < 0.0f)) return false;
  glm::vec3 olo(3.0e38f), ohi(-3.0e38f), ilo(3.0e38f), ihi(-3.0e38f);
  float tmin_lo = 3.0e38f;
  p.halves = count > 8 ? 2 : 1;
  for (int r = 0; r < 8 * p.halves; ++r) {
    const Ray& ray = rays[r < count ? r : 0];
    const glm::vec3 inv = wide::safe_inverse(ray.direction);
    olo = glm::min(olo, ray.origin);
    ohi = glm::max(ohi, ray.origin);
    ilo = glm::min(ilo, inv);
    ihi = glm::max(ihi, inv);
    tmin_lo = std::min(tmin_lo, ray.tmin);
    p.ox[r] = ray.origin.x; p.oy[r] = ray.origin.y; p.oz[r] = ray.origin.z;
    p.ix[r] = inv.x; p.iy[r] = inv.y; p.iz[r] = inv.z;
    p.tmin[r] = ray.tmin;
    // Lanes past count copy ray 0 but can never be entered (best t below everything).
    p.best_t[r] = r < count ? ray.tmax : -3.0e38f;
    p.shear[r] = RayShear(ray.origin, ray.direction);
    const RayShear& sh = p.shear[r];
    p.okx[r] = sh.origin[sh.kx]; p.oky[r] = sh.origin[sh.ky]; p.okz[r] = sh.origin[sh.kz];
    p.sx[r] = sh.sx; p.sy[r] = sh.sy; p.sz[r] = sh.sz;
  }
  const RayShear& first = p.shear[0];
  p.offx = wide::pack_axis_offset(first.kx);
  p.offy = wide::pack_axis_offset(first.ky);
  p.offz = wide::pack_axis_offset(first.kz);
  p.common_shear = true;
  for (int r = 1; r < count; ++r)
    if (p.shear[r].kx != first.kx || p.shear[r].ky != first.ky || p.shear[r].kz != first.kz) p.common_shear = false;
  constexpr std::uint32_t row = kWideArity * sizeof(float), hi = 3 * row;
  for (int a = 0; a < 3; ++a) {
    if (std::signbit(ilo[a]) != std::signbit(ihi[a])) return false;  // mixed signs (±0 directions)
    const bool neg = std::signbit(ilo[a]);
    p.near_off[a] = static_cast<std::uint32_t>(a) * row + (neg ? hi : 0);
    p.far_off[a] = static_cast<std::uint32_t>(a) * row + (neg ? 0 : hi);
    // Entry (near plane - o) * inv is smallest for the origin farthest along the ray's
    // travel; exit is largest for the nearest one.
    p.near_o[a] = _mm256_set1_ps(neg ? olo[a] : ohi[a]);
    p.far_o[a] = _mm256_set1_ps(neg ? ohi[a] : olo[a]);
    p.inv_lo[a] = _mm256_set1_ps(ilo[a]);
    p.inv_hi[a] = _mm256_set1_ps(ihi[a]);
  }
  p.tmin_lo = _mm256_set1_ps(tmin_lo);
  return true;
}

struct Entry {
  std::uint32_t ref;
  float tnear;
};

// Triangle l of pack pk against the rays of one 8-lane half (bits `lanes` of it): the
// watertight test of ray_triangle.h with the rays in lanes and the triangle broadcast, the
// same operations in the same order as intersect_pack and the scalar test, so the same
// bits. Lanes whose edge function is exactly zero (or whose product underflows) are redone
// by the scalar test, which owns the double-precision fallback. Updates best[] / best_t[]
// (closest t, ties to the lower triangle id); true when some ray's best improved.
[[gnu::always_inline]] inline bool ray_lanes_triangle(const TrianglePack& pk, int l, Packet& p, int half,
                                                      unsigned lanes, Hit* best) {
  const int h = 8 * half;
  // Vertex v's kx/ky/kz coordinates of triangle l: rows of the pack picked by byte offset.
  const char* base = reinterpret_cast<const char*>(&pk) + 4 * l;
  auto coord = [base](std::uint32_t vertex, std::uint32_t off) {
    return _mm256_broadcast_ss(reinterpret_cast<const float*>(base + wide::pack_vertex_offset(vertex) + off));
  };
  const __m256 okx = _mm256_load_ps(p.okx + h), oky = _mm256_load_ps(p.oky + h), okz = _mm256_load_ps(p.okz + h);
  const __m256 sx = _mm256_load_ps(p.sx + h), sy = _mm256_load_ps(p.sy + h), sz = _mm256_load_ps(p.sz + h);
  const __m256 Akx = _mm256_sub_ps(coord(0, p.offx), okx), Aky = _mm256_sub_ps(coord(0, p.offy), oky),
               Akz = _mm256_sub_ps(coord(0, p.offz), okz);
  const __m256 Bkx = _mm256_sub_ps(coord(1, p.offx), okx), Bky = _mm256_sub_ps(coord(1, p.offy), oky),
               Bkz = _mm256_sub_ps(coord(1, p.offz), okz);
  const __m256 Ckx = _mm256_sub_ps(coord(2, p.offx), okx), Cky = _mm256_sub_ps(coord(2, p.offy), oky),
               Ckz = _mm256_sub_ps(coord(2, p.offz), okz);
  const __m256 ax = _mm256_sub_ps(Akx, _mm256_mul_ps(sx, Akz)), ay = _mm256_sub_ps(Aky, _mm256_mul_ps(sy, Akz));
  const __m256 bx = _mm256_sub_ps(Bkx, _mm256_mul_ps(sx, Bkz)), by = _mm256_sub_ps(Bky, _mm256_mul_ps(sy, Bkz));
  const __m256 cx = _mm256_sub_ps(Ckx, _mm256_mul_ps(sx, Ckz)), cy = _mm256_sub_ps(Cky, _mm256_mul_ps(sy, Ckz));
  const __m256 U = _mm256_sub_ps(_mm256_mul_ps(cx, by), _mm256_mul_ps(cy, bx));
  const __m256 V = _mm256_sub_ps(_mm256_mul_ps(ax, cy), _mm256_mul_ps(ay, cx));
  const __m256 W = _mm256_sub_ps(_mm256_mul_ps(bx, ay), _mm256_mul_ps(by, ax));
  const __m256 zero = _mm256_setzero_ps();
  const __m256 mn = _mm256_min_ps(_mm256_min_ps(U, V), W), mx = _mm256_max_ps(_mm256_max_ps(U, V), W);
  const __m256 inside = _mm256_or_ps(_mm256_cmp_ps(mn, zero, _CMP_GE_OQ), _mm256_cmp_ps(mx, zero, _CMP_LE_OQ));
  unsigned candidates = static_cast<unsigned>(_mm256_movemask_ps(inside)) & lanes;
  if (!candidates) return false;
  const unsigned zero_edge =
      static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_mul_ps(_mm256_mul_ps(U, V), W), zero, _CMP_EQ_OQ))) &
      candidates;
  const __m256 det = _mm256_add_ps(_mm256_add_ps(U, V), W);
  const __m256 T =
      _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(U, _mm256_mul_ps(sz, Akz)), _mm256_mul_ps(V, _mm256_mul_ps(sz, Bkz))),
                    _mm256_mul_ps(W, _mm256_mul_ps(sz, Ckz)));
  const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), det);
  const __m256 tt = _mm256_mul_ps(T, inv);
  const __m256 in_range = _mm256_and_ps(_mm256_cmp_ps(tt, _mm256_load_ps(p.tmin + h), _CMP_GE_OQ),
                                        _mm256_cmp_ps(tt, _mm256_load_ps(p.best_t + h), _CMP_LE_OQ));
  unsigned ok = static_cast<unsigned>(_mm256_movemask_ps(in_range)) & candidates & ~zero_edge;
  if (!ok && !zero_edge) return false;
  alignas(32) float ts[8], us[8], vs[8];
  _mm256_store_ps(ts, tt);
  _mm256_store_ps(us, _mm256_mul_ps(V, inv));
  _mm256_store_ps(vs, _mm256_mul_ps(W, inv));
  const std::uint32_t id = pk.id[l];
  bool improved = false;
  auto offer = [&](int r, float t, float u, float v) {
    if (t < best[r].t || (t == best[r].t && id < best[r].triangle)) {
      best[r] = {t, u, v, id};
      p.best_t[r] = t;
      improved = true;
    }
  };
  for (; ok; ok &= ok - 1) {
    const int j = __builtin_ctz(ok);
    offer(h + j, ts[j], us[j], vs[j]);
  }
  for (unsigned z = zero_edge; z; z &= z - 1) {
    const int r = h + __builtin_ctz(z);
    TriangleHit th;
    const glm::vec3 A(pk.ax[l], pk.ay[l], pk.az[l]), B(pk.bx[l], pk.by[l], pk.bz[l]), C(pk.cx[l], pk.cy[l], pk.cz[l]);
    if (intersect_triangle_watertight(p.shear[r], A, B, C, p.tmin[r], best[r].t, th)) offer(r, th.t, th.u, th.v);
  }
  return improved;
}

// Leaf child k of n: every ray whose own box test passes is tested against the leaf's
// triangles; best[r] (and p.best_t[r]) keep ray r's closest hit, ties to the lower
// triangle id (so the order of the tests does not matter). With a common shear and several
// rays in the leaf, the rays go in lanes against one triangle at a time; otherwise each ray
// goes against 4-triangle packs. True when some ray's best improved.
[[gnu::always_inline]] inline bool intersect_leaf(const WideNode& n, int k, const TrianglePack* packs,
                                                  Packet& p, Hit* best, TraversalCounters& c) {
  bool improved = false;
  const std::uint32_t ref = n.child[k];
  const std::uint32_t first = (ref & ~kLeafBit) >> 2, npacks = (ref & 3u) + 1;
  const unsigned rays_in = rays_box_hits(n, k, p);
  if (!rays_in) return false;
  if (p.common_shear && __builtin_popcount(rays_in) >= 3) {
    c.triangle_tests += 4u * npacks * static_cast<unsigned>(__builtin_popcount(rays_in));
    for (std::uint32_t q = first; q < first + npacks; ++q) {
      const TrianglePack& pk = packs[q];
      for (int l = 0; l < 4; ++l) {
        if (pk.id[l] == kEmptyChild) continue;
        for (int half = 0; half < p.halves; ++half) {
          const unsigned lanes = (rays_in >> (8 * half)) & 0xffu;
          if (lanes && ray_lanes_triangle(pk, l, p, half, lanes, best)) improved = true;
        }
      }
    }
    return improved;
  }
  for (unsigned rb = rays_in; rb; rb &= rb - 1) {
    const int r = __builtin_ctz(rb);
    const wide::PackRay pr(p.shear[r]);
    for (std::uint32_t q = first; q < first + npacks; ++q) {
      const TrianglePack& pk = packs[q];
      c.triangle_tests += 4;
      float t[4], u[4], v[4];
      unsigned hit = wide::intersect_pack(pk, pr, p.tmin[r], best[r].t, t, u, v);
      while (hit) {
        const int l = __builtin_ctz(hit);
        hit &= hit - 1;
        if (t[l] < best[r].t || (t[l] == best[r].t && pk.id[l] < best[r].triangle)) {
          best[r] = {t[l], u[l], v[l], pk.id[l]};
          p.best_t[r] = t[l];
          improved = true;
        }
      }
    }
  }
  return improved;
}

// A refused packet's rays, traced as single rays.
void closest_hits_one_by_one(const Bvh& bvh, const Ray* rays, int count, Hit* out, TraversalCounters* counters) {
  for (int r = 0; r < count; ++r) out[r] = closest_hit(bvh, rays[r], counters);
}

// The inner children in `bits` whose entry bound tn[k] is within max_t, sorted far to
// near into `hits` (the nearest last, where the descent continues); returns their count.
[[gnu::always_inline]] inline int children_far_to_near(const WideNode& n, unsigned bits, const float* tn,
                                                        float max_t, Entry* hits) {
  int m = 0;
  for (; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    if (!(tn[k] <= max_t)) continue;
    const Entry e{n.child[k], tn[k]};
    int j = m++;
    while (j > 0 && hits[j - 1].tnear < e.tnear) {
      hits[j] = hits[j - 1];
      --j;
    }
    hits[j] = e;
  }
  return m;
}

}  // namespace

bool closest_hit_packet(const Bvh& bvh, const Ray* rays, int count, Hit* out, TraversalCounters* counters) {
  count = std::clamp(count, 0, kMaxPacketSize);
  Packet p;
  if (count < 2 || bvh.wide_root() == kEmptyChild || (bvh.wide_root() & kLeafBit) || !prepare(rays, count, p)) {
    closest_hits_one_by_one(bvh, rays, count, out, counters);
    return false;
  }
  TraversalCounters c;
  c.rays = static_cast<std::uint64_t>(count);
  Hit best[kMaxPacketSize];
  for (int r = 0; r < count; ++r) best[r].t = p.best_t[r];
  const WideNode* nodes = bvh.wide_nodes().data();
  const TrianglePack* packs = bvh.triangle_packs().data();
  float max_t = lane_max(p);
  Entry stack[kTraversalStackSize];
  int sp = 0;
  std::uint32_t cur = bvh.wide_root();
  while (true) {
    ++c.nodes_visited;
    const WideNode& n = nodes[cur];
    __m256 tnv;
    unsigned bits = packet_box_hits(n, p, max_t, tnv);
    alignas(32) float tn[kWideArity];
    _mm256_store_ps(tn, tnv);
    // Leaf children now, each ray against its box, then its triangles.
    unsigned leaves = 0;
    for (unsigned b = bits; b; b &= b - 1) {
      const int k = __builtin_ctz(b);
      if (!(n.child[k] & kLeafBit)) continue;
      leaves |= 1u << k;
      // The leaves' triangles are the traversal's cache misses: start them all before the
      // first is tested (a pack is 160 bytes, three lines).
      const char* pk = reinterpret_cast<const char*>(&packs[(n.child[k] & ~kLeafBit) >> 2]);
      _mm_prefetch(pk, _MM_HINT_T0);
      _mm_prefetch(pk + 64, _MM_HINT_T0);
      _mm_prefetch(pk + 128, _MM_HINT_T0);
    }
    bits &= ~leaves;
    bool improved = false;
    while (leaves) {
      const int k = __builtin_ctz(leaves);
      leaves &= leaves - 1;
      if (intersect_leaf(n, k, packs, p, best, c)) improved = true;
    }
    if (improved) max_t = lane_max(p);
    // Inner children: descend into the nearest, push the others far-to-near.
    if (bits) {
      Entry hits[kWideArity];
      const int m = children_far_to_near(n, bits, tn, max_t, hits);
      if (m > 0) {
        for (int i = 0; i + 1 < m; ++i) {
          if (sp == kTraversalStackSize) {
            ++c.stack_overflows;
            continue;
          }
          stack[sp++] = hits[i];
        }
        cur = hits[m - 1].ref;
        continue;
      }
    }
    bool found = false;
    while (sp > 0) {
      const Entry e = stack[--sp];
      if (e.tnear <= max_t) {
        cur = e.ref;
        found = true;
        break;
      }
    }
    if (!found) break;
  }
  for (int r = 0; r < count; ++r) out[r] = best[r].hit() ? best[r] : Hit{};
  if (counters) counters->add(c);
  return true;
}

void closest_hit_stream_packets(const Bvh& bvh, const RayStream& rays, HitStream& hits, par::Executor& ex,
                                TraversalCounters* counters, int image_width) {
  static_assert(kRayChunk % kMaxPacketSize == 0, "packets never straddle chunks");
  const std::size_t n = rays.size();
  hits.resize(n);
  // The packets: slot[kMaxPacketSize * q + l] is the ray of lane l of packet q (or n for an
  // unused lane). An image's rays go in 4x4 pixel tiles (16 rays that share most of their
  // node path), row-major tiles; other streams in runs of kPacketSize consecutive rays.
  const bool tiles = image_width > 0 && n % static_cast<std::size_t>(image_width) == 0;
  const std::size_t w = tiles ? static_cast<std::size_t>(image_width) : 0, h = tiles ? n / w : 0;
  const std::size_t tiles_x = (w + 3) / 4, tiles_y = (h + 3) / 4;
  const std::size_t packets = tiles ? tiles_x * tiles_y : (n + kPacketSize - 1) / kPacketSize;
  const std::size_t per_chunk_packets = kRayChunk / (tiles ? kMaxPacketSize : kPacketSize);
  const std::size_t chunks = (packets + per_chunk_packets - 1) / per_chunk_packets;
  std::vector<TraversalCounters> per_chunk(counters ? chunks : 0);
  ex.parallel_for("trace_closest_packets", packets, per_chunk_packets, [&](std::size_t b, std::size_t e) {
    TraversalCounters c;
    // A packet refused as incoherent sends the next 1, 2, 4, then up to kMaxSkippedPackets
    // packets of the chunk straight to single rays before the next try: an incoherent stream
    // (reflected glossy rays) pays the coherence test on a few packets per chunk instead of
    // every one. Both paths give the same hits, so this changes the speed only.
    int skip = 0, backoff = 1;
    for (std::size_t q = b; q < e; ++q) {
      std::size_t slot[kMaxPacketSize];
      int count = 0;
      if (tiles) {
        const std::size_t x0 = (q % tiles_x) * 4, y0 = (q / tiles_x) * 4;
        for (std::size_t y = y0; y < std::min(y0 + 4, h); ++y)
          for (std::size_t x = x0; x < std::min(x0 + 4, w); ++x) slot[count++] = y * w + x;
      } else {
        for (std::size_t i = q * kPacketSize; i < std::min(n, (q + 1) * kPacketSize); ++i) slot[count++] = i;
      }
      Ray r[kMaxPacketSize];
      Hit hh[kMaxPacketSize];
      for (int k = 0; k < count; ++k) r[k] = rays.get(slot[k]);
      if (skip > 0) {
        --skip;
        closest_hits_one_by_one(bvh, r, count, hh, &c);
      } else if (closest_hit_packet(bvh, r, count, hh, &c)) {
        backoff = 1;
      } else {
        skip = backoff;
        backoff = std::min(2 * backoff, kMaxSkippedPackets);
      }
      for (int k = 0; k < count; ++k) {
        const std::size_t j = slot[k];
        hits.t[j] = hh[k].t;
        hits.u[j] = hh[k].u;
        hits.v[j] = hh[k].v;
        hits.triangle[j] = hh[k].triangle;
      }
    }
    if (counters) per_chunk[b / per_chunk_packets] = c;
  });
  if (counters)
    for (const auto& c : per_chunk) counters->add(c);
}

}  // namespace speculum::trace
