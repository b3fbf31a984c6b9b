// core/brdf.h's per-light BRDF for W points at once: the same operations in the same order
// as the scalar gltf_brdf(BrdfAtView, ...) and specular_albedo, so every lane has the bits
// of the scalar call (tests/core/brdf_lanes_test.cpp compares them). A shading pass computes
// each point's BrdfAtView once (scalar) and evaluates the lights eight points at a time.
#pragma once

#include <cstdint>

#include "core/brdf.h"
#include "core/sampling.h"
#include "core/vec3_lanes.h"

namespace speculum {

// BrdfAtView's fields as lanes (the ones gltf_brdf reads).
template <int W>
struct BrdfAtViewLanes {
  using f32 = typename par::Lanes<W>::f32;
  Vec3Lanes<W> base_color, f0;
  f32 alpha, cos_nv, diffuse_weight, dielectric_f0, one_minus_e_v, one_minus_e_avg, smith_view_root;

  // views[0, count); lanes past count repeat views[0].
  static BrdfAtViewLanes load(const BrdfAtView* views, int count) {
    using L = par::Lanes<W>;
    alignas(64) float c[13][W];
    for (int j = 0; j < W; ++j) {
      const BrdfAtView& a = views[j < count ? j : 0];
      const float fields[13] = {a.base_color.x, a.base_color.y, a.base_color.z, a.f0.x, a.f0.y, a.f0.z, a.alpha,
                                a.cos_nv, a.diffuse_weight, a.dielectric_f0, a.one_minus_e_v, a.one_minus_e_avg,
                                a.smith_view_root};
      for (int k = 0; k < 13; ++k) c[k][j] = fields[k];
    }
    BrdfAtViewLanes out;
    out.base_color = {L::load(c[0]), L::load(c[1]), L::load(c[2])};
    out.f0 = {L::load(c[3]), L::load(c[4]), L::load(c[5])};
    out.alpha = L::load(c[6]), out.cos_nv = L::load(c[7]), out.diffuse_weight = L::load(c[8]);
    out.dielectric_f0 = L::load(c[9]), out.one_minus_e_v = L::load(c[10]), out.one_minus_e_avg = L::load(c[11]);
    out.smith_view_root = L::load(c[12]);
    return out;
  }
};

template <int W>
struct BrdfValueLanes {
  Vec3Lanes<W> diffuse, specular;
};

// specular_albedo(cos_nv, alpha)(f0) per lane (brdf.cpp: the table's bilinear lookup).
template <int W>
typename par::Lanes<W>::f32 specular_albedo_lanes(const typename par::Lanes<W>::f32& cos_nv,
                                                  const typename par::Lanes<W>::f32& alpha,
                                                  const typename par::Lanes<W>::f32& f0) {
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  using i32 = typename L::i32;
  const auto clamp01 = [](const f32& x) { return L::select(x < 0.0f, f32(0.0f), L::select(f32(1.0f) < x, f32(1.0f), x)); };
  // grid(): cell index (clamped below too, so a NaN input cannot index outside) and fraction.
  const auto grid = [&](const f32& x, i32& cell, f32& fraction) {
    const f32 f = clamp01(x) * float(kAlbedoTableSize - 1);
    cell = L::max(L::min(L::to_int(f), i32(kAlbedoTableSize - 2)), i32(0));
    fraction = f - L::to_float(cell);
  };
  i32 j, i;
  f32 tr, tm;
  grid(L::sqrt(clamp01(alpha)), j, tr);
  grid(cos_nv, i, tm);
  const SpecularAlbedo* e = albedo_table().e.data();
  const float* fields = reinterpret_cast<const float*>(e);  // {scale, bias} pairs
  static_assert(sizeof(SpecularAlbedo) == 2 * sizeof(float));
  const i32 at = (j * kAlbedoTableSize + i) * 2;
  const auto field = [&](int offset) { return L::gather(fields, at + offset); };
  constexpr int kRow = 2 * kAlbedoTableSize;
  const auto lerp = [](const f32& a, const f32& b, const f32& t) { return a + (b - a) * t; };
  const f32 scale = lerp(lerp(field(0), field(2), tm), lerp(field(kRow), field(kRow + 2), tm), tr);
  const f32 bias = lerp(lerp(field(1), field(3), tm), lerp(field(kRow + 1), field(kRow + 3), tm), tr);
  return f0 * scale + bias;
}

// gltf_brdf(view, n, l, v) per lane: both lobes 0 where N·L ≤ 0, the specular 0 where
// N·H ≤ 0.
template <int W>
BrdfValueLanes<W> gltf_brdf_lanes(const BrdfAtViewLanes<W>& a, const Vec3Lanes<W>& n, const Vec3Lanes<W>& l,
                                  const Vec3Lanes<W>& v) {
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  const f32 zero(0.0f), one(1.0f);
  const f32 cos_nl = dot(n, l);
  const Vec3Lanes<W> sum = l + v;
  const f32 sum2 = dot(sum, sum);
  const Vec3Lanes<W> h = select(sum2 > 1e-12f, sum / L::sqrt(sum2), n);
  const f32 vh = dot(v, h);
  const f32 cos_vh = L::select(vh < zero, zero, L::select(one < vh, one, vh));

  const f32 e_l = specular_albedo_lanes<W>(cos_nl, a.alpha, a.dielectric_f0);
  const f32 coupled = a.one_minus_e_v * (1.0f - e_l) / a.one_minus_e_avg;
  BrdfValueLanes<W> out;
  out.diffuse = a.base_color * (a.diffuse_weight * coupled / kPi);

  const f32 cos_nh = dot(n, h);
  const Vec3Lanes<W> nxh = cross(n, h);
  const f32 a2 = a.alpha * a.alpha;
  const f32 denom_d = (cos_nh * cos_nh) * a2 + dot(nxh, nxh);
  const f32 d = a2 / (kPi * denom_d * denom_d);
  const f32 nl = L::abs(cos_nl), nv = L::abs(a.cos_nv);
  const f32 gv = nl * a.smith_view_root;
  const f32 gl = nv * L::sqrt(nl * nl * (1.0f - a2) + a2);
  const f32 denom = gv + gl;
  const f32 vis = L::select(denom > zero, 0.5f / denom, zero);
  const f32 m = 1.0f - cos_vh;
  const f32 m2 = m * m;
  const f32 schlick = m2 * m2 * m;
  const Vec3Lanes<W> fresnel = a.f0 + (Vec3Lanes<W>(glm::vec3(1.0f)) - a.f0) * schlick;
  const Vec3Lanes<W> none(zero, zero, zero);
  out.specular = select(cos_nh > zero, fresnel * (d * vis), none);
  const auto lit = cos_nl > zero;
  out.diffuse = select(lit, out.diffuse, none);
  out.specular = select(lit, out.specular, none);
  return out;
}

}  // namespace speculum
