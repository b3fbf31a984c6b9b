// core/brdf.h's per-light BRDF for W points at once: the same operations in the same order
// as the scalar gltf_brdf(BrdfAtView, ...) and specular_albedo, so every lane has the bits
// of the scalar call (tests/core/brdf_lanes_test.cpp compares them). A shading pass computes
// each point's viewer terms once and evaluates the lights eight points at a time.
#pragma once

#include <cstdint>

#include "core/brdf.h"
#include "core/sampling.h"
#include "core/vec3_lanes.h"

namespace speculum {

// BrdfAtView's fields as lanes (brdf_at_view_lanes computes them).
template <int W>
struct BrdfAtViewLanes {
  using f32 = typename par::Lanes<W>::f32;
  Vec3Lanes<W> base_color, f0;
  f32 alpha, cos_nv, diffuse_weight, dielectric_f0, one_minus_e_v, one_minus_e_avg, smith_view_root;
  f32 scale_at_view, bias_at_view;
};

template <int W>
struct BrdfValueLanes {
  Vec3Lanes<W> diffuse, specular;
};

namespace brdf_lanes_detail {

template <int W>
[[gnu::always_inline]] inline typename par::Lanes<W>::f32 clamp01(const typename par::Lanes<W>::f32& x) {
  using f32 = typename par::Lanes<W>::f32;
  return par::Lanes<W>::clamp(x, f32(0.0f), f32(1.0f));
}

// brdf.cpp's grid(): the albedo table's cell of x ∈ [0, 1] (clamped below too, so a NaN
// cannot index outside) and the fraction within it.
template <int W>
[[gnu::always_inline]] inline void grid(const typename par::Lanes<W>::f32& x, typename par::Lanes<W>::i32& cell,
          typename par::Lanes<W>::f32& fraction) {
  using L = par::Lanes<W>;
  using i32 = typename L::i32;
  const typename L::f32 f = clamp01<W>(x) * float(kAlbedoTableSize - 1);
  cell = L::max(L::min(L::to_int(f), i32(kAlbedoTableSize - 2)), i32(0));
  fraction = f - L::to_float(cell);
}

template <int W>
[[gnu::always_inline]] inline typename par::Lanes<W>::f32 lerp(const typename par::Lanes<W>::f32& a, const typename par::Lanes<W>::f32& b,
                                 const typename par::Lanes<W>::f32& t) {
  return a + (b - a) * t;
}

// The table's entries as floats: {scale, bias} pairs.
[[gnu::always_inline]] inline const float* table_fields(const SpecularAlbedo* entries) {
  static_assert(sizeof(SpecularAlbedo) == 2 * sizeof(float));
  return reinterpret_cast<const float*>(entries);
}

}  // namespace brdf_lanes_detail

// specular_albedo(cos_nv, alpha) per lane (brdf.cpp: the table's bilinear lookup).
template <int W>
[[gnu::always_inline]] inline void specular_albedo_lanes(const typename par::Lanes<W>::f32& cos_nv, const typename par::Lanes<W>::f32& alpha,
                           typename par::Lanes<W>::f32& scale, typename par::Lanes<W>::f32& bias) {
  using namespace brdf_lanes_detail;
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  using i32 = typename L::i32;
  i32 j, i;
  f32 tr, tm;
  grid<W>(L::sqrt(clamp01<W>(alpha)), j, tr);
  grid<W>(cos_nv, i, tm);
  const float* fields = table_fields(albedo_table().e.data());
  const i32 at = (j * kAlbedoTableSize + i) * 2;
  const auto field = [&](int offset) { return L::gather(fields, at + offset); };
  constexpr int kRow = 2 * kAlbedoTableSize;
  scale = lerp<W>(lerp<W>(field(0), field(2), tm), lerp<W>(field(kRow), field(kRow + 2), tm), tr);
  bias = lerp<W>(lerp<W>(field(1), field(3), tm), lerp<W>(field(kRow + 1), field(kRow + 3), tm), tr);
}

// specular_albedo(cos_nv, alpha)(f0) per lane.
template <int W>
[[gnu::always_inline]] inline typename par::Lanes<W>::f32 specular_albedo_lanes(const typename par::Lanes<W>::f32& cos_nv,
                                                  const typename par::Lanes<W>::f32& alpha,
                                                  const typename par::Lanes<W>::f32& f0) {
  typename par::Lanes<W>::f32 scale, bias;
  specular_albedo_lanes<W>(cos_nv, alpha, scale, bias);
  return f0 * scale + bias;
}

// average_specular_albedo(alpha)(f0) per lane.
template <int W>
[[gnu::always_inline]] inline typename par::Lanes<W>::f32 average_specular_albedo_lanes(const typename par::Lanes<W>::f32& alpha,
                                                          const typename par::Lanes<W>::f32& f0) {
  using namespace brdf_lanes_detail;
  using L = par::Lanes<W>;
  typename L::i32 j;
  typename L::f32 tr;
  grid<W>(L::sqrt(clamp01<W>(alpha)), j, tr);
  const float* fields = table_fields(albedo_table().average.data());
  const auto field = [&](int offset) { return L::gather(fields, j * 2 + offset); };
  return f0 * lerp<W>(field(0), field(2), tr) + lerp<W>(field(1), field(3), tr);
}

// BrdfParams as lanes.
template <int W>
struct BrdfParamsLanes {
  using f32 = typename par::Lanes<W>::f32;
  Vec3Lanes<W> base_color;
  f32 metallic, alpha, dielectric_f0, transmission;
};

// brdf_at_view(p, n, v) per lane.
template <int W>
[[gnu::always_inline]] inline BrdfAtViewLanes<W> brdf_at_view_lanes(const BrdfParamsLanes<W>& p, const Vec3Lanes<W>& n, const Vec3Lanes<W>& v) {
  using namespace brdf_lanes_detail;
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  BrdfAtViewLanes<W> a;
  a.base_color = p.base_color;
  a.cos_nv = L::max(dot(n, v), f32(0.0f));
  const f32 metallic = clamp01<W>(p.metallic);
  a.alpha = L::max(p.alpha, f32(kMinAlpha));
  a.diffuse_weight = (1.0f - metallic) * (1.0f - clamp01<W>(p.transmission));
  a.dielectric_f0 = p.dielectric_f0;
  specular_albedo_lanes<W>(a.cos_nv, a.alpha, a.scale_at_view, a.bias_at_view);
  a.one_minus_e_v = 1.0f - (p.dielectric_f0 * a.scale_at_view + a.bias_at_view);
  a.one_minus_e_avg = L::max(1.0f - average_specular_albedo_lanes<W>(a.alpha, p.dielectric_f0), f32(1e-6f));
  const f32 nv = L::abs(a.cos_nv), a2 = a.alpha * a.alpha;
  a.smith_view_root = L::sqrt(nv * nv * (1.0f - a2) + a2);
  a.f0 = Vec3Lanes<W>(p.dielectric_f0 * (1.0f - metallic), p.dielectric_f0 * (1.0f - metallic),
                      p.dielectric_f0 * (1.0f - metallic)) +
         p.base_color * metallic;
  return a;
}

// gltf_brdf(view, n, l, v) per lane: both lobes 0 where N·L ≤ 0, the specular 0 where
// N·H ≤ 0.
template <int W>
[[gnu::always_inline]] inline BrdfValueLanes<W> gltf_brdf_lanes(const BrdfAtViewLanes<W>& a, const Vec3Lanes<W>& n, const Vec3Lanes<W>& l,
                                  const Vec3Lanes<W>& v) {
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  const f32 zero(0.0f), one(1.0f);
  const f32 cos_nl = dot(n, l);
  const Vec3Lanes<W> sum = l + v;
  const f32 sum2 = dot(sum, sum);
  const Vec3Lanes<W> h = select(sum2 > 1e-12f, sum / L::sqrt(sum2), n);
  const f32 vh = dot(v, h);
  const f32 cos_vh = L::clamp(vh, zero, one);

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
