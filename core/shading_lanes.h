// core/shading.h's per-light terms for W points at once, each lane with the bits of the
// scalar form: LightSampler::sample (operator()'s operations in its order), shade_light and
// the diffuse albedo.
#pragma once

#include "core/brdf_lanes.h"
#include "core/shading.h"
#include "core/vec3_lanes.h"

namespace speculum {

template <int W>
[[gnu::always_inline]] inline void LightSampler::sample(const Vec3Lanes<W>& position, Vec3Lanes<W>& direction, Vec3Lanes<W>& irradiance) const {
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  const Light& light = *light_;
  if (light.type == LightType::Directional) {
    direction = Vec3Lanes<W>(-direction_);
    irradiance = Vec3Lanes<W>(light.color * light.intensity);
    return;
  }
  const f32 zero(0.0f), one(1.0f);
  const Vec3Lanes<W> to_light = Vec3Lanes<W>(light.position) - position;
  const f32 d2 = dot(to_light, to_light);
  const auto reached = d2 > zero;  // at the light itself: no defined direction
  const f32 d = L::sqrt(d2);
  const Vec3Lanes<W> dir = to_light / d;
  f32 window = one;
  if (light.range > 0.0f) {
    const f32 r = d / light.range;
    const f32 r2 = r * r;
    window = L::clamp(1.0f - r2 * r2, zero, one);
  }
  f32 cone = one;
  if (light.type == LightType::Spot) {
    const f32 cd = dot(Vec3Lanes<W>(direction_), -dir);
    const f32 a = L::clamp((cd - cos_outer_) * cone_scale_, zero, one);
    cone = a * a;
  }
  const f32 e = light.intensity * window * cone / d2;
  const Vec3Lanes<W> none(zero, zero, zero);
  direction = select(reached, dir, Vec3Lanes<W>(glm::vec3(0.0f, 1.0f, 0.0f)));
  irradiance = select(reached, Vec3Lanes<W>(light.color) * e, none);
}

// brdf_params_for_punctual_light of surfaces s[0, count) as lanes (lanes past count repeat
// s[0]); `mirror` marks the lanes whose surface is_mirror_lobe() (shade_light_lanes' mask).
template <int W>
inline BrdfParamsLanes<W> punctual_brdf_params_lanes(const SurfaceParams* const* s, int count,
                                                     typename par::Lanes<W>::mask& mirror) {
  using L = par::Lanes<W>;
  alignas(64) float params[8][W];
  for (int j = 0; j < W; ++j) {
    const SurfaceParams& sj = *s[j < count ? j : 0];
    const BrdfParams b = brdf_params_for_punctual_light(sj);
    const float fields[8] = {b.base_color.x, b.base_color.y, b.base_color.z, b.metallic, b.alpha, b.dielectric_f0,
                             b.transmission, sj.is_mirror_lobe() ? 1.0f : 0.0f};
    for (int k = 0; k < 8; ++k) params[k][j] = fields[k];
  }
  BrdfParamsLanes<W> p;
  p.base_color = {L::load(params[0]), L::load(params[1]), L::load(params[2])};
  p.metallic = L::load(params[3]), p.alpha = L::load(params[4]);
  p.dielectric_f0 = L::load(params[5]), p.transmission = L::load(params[6]);
  mirror = L::load(params[7]) > typename L::f32(0.0f);
  return p;
}

// shade_light(s, view, n, v, {l, irradiance}) per lane for lanes whose N·L > 0 (the others:
// 0); `mirror` marks the lanes whose surface is_mirror_lobe() (no highlight).
template <int W>
[[gnu::always_inline]] inline Vec3Lanes<W> shade_light_lanes(const BrdfAtViewLanes<W>& view, const typename par::Lanes<W>::mask& mirror,
                               const Vec3Lanes<W>& n, const Vec3Lanes<W>& v, const Vec3Lanes<W>& l,
                               const Vec3Lanes<W>& irradiance) {
  using f32 = typename par::Lanes<W>::f32;
  const f32 cos_nl = dot(n, l);
  const BrdfValueLanes<W> f = gltf_brdf_lanes(view, n, l, v);
  const Vec3Lanes<W> brdf = select(mirror, f.diffuse, f.diffuse + f.specular);
  const f32 zero(0.0f);
  return select(cos_nl > zero, brdf * (cos_nl * irradiance), Vec3Lanes<W>(zero, zero, zero));
}

// diffuse_albedo_over_pi(s, view) per lane, from the BrdfParams of s (their metallic and
// transmission are the surface's own, unclamped, as that function reads them).
template <int W>
[[gnu::always_inline]] inline Vec3Lanes<W> diffuse_albedo_over_pi_lanes(const BrdfParamsLanes<W>& p,
                                                                        const BrdfAtViewLanes<W>& view) {
  const typename par::Lanes<W>::f32 e = view.dielectric_f0 * view.scale_at_view + view.bias_at_view;
  return p.base_color * ((1.0f - p.metallic) * (1.0f - p.transmission) * (1.0f - e) / kPi);
}

}  // namespace speculum
