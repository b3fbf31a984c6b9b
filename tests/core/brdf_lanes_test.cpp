// The eight-lane forms of the per-light shading terms (core/brdf_lanes.h,
// core/shading_lanes.h) against their scalar forms, bit for bit, lane by lane: the GGX BRDF
// with its albedo-table lookups, the light samplers of every light type, shade_light.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstdint>

#include <glm/geometric.hpp>

#include "core/brdf.h"
#include "core/brdf_lanes.h"
#include "core/optics.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "core/shading_lanes.h"

namespace speculum {
namespace {

using L = par::Lanes<8>;
using V = Vec3Lanes<8>;

glm::vec3 random_direction(std::uint32_t key, std::uint32_t dimension) {
  return spherical_local(1.0f - 2.0f * random_float(key, 0, dimension, 31), random_float(key, 0, dimension + 1, 31));
}

// Scalar and lanes inputs alike: surfaces of every class, normals, viewers and lights at
// any angle — below the horizon too, and l = −v, where the half vector falls back to n.
struct Batch {
  SurfaceParams s[8];
  BrdfAtView view[8];
  glm::vec3 n[8], v[8], l[8], p[8];
};

Batch batch(std::uint32_t i) {
  Batch b;
  for (int j = 0; j < 8; ++j) {
    const std::uint32_t key = i * 8 + std::uint32_t(j);
    SurfaceParams& s = b.s[j];
    s.roughness = std::array<float, 6>{1.0f, 0.3f, 0.0f, 0.8f, 0.05f, 0.6f}[key % 6];
    s.metallic = key % 4 == 1 ? 1.0f : random_float(key, 0, 0, 31);
    s.transmission = key % 7 == 3 ? 1.0f : 0.0f;
    s.base_color = glm::vec3(random_float(key, 0, 1, 31), 0.5f, 0.25f);
    s.ior = key % 3 == 0 ? 1.33f : 1.5f;
    b.n[j] = random_direction(key, 2);
    b.v[j] = random_direction(key, 4);
    b.l[j] = key % 13 == 5 ? -b.v[j] : random_direction(key, 6);
    b.p[j] = 3.0f * random_direction(key, 8) * random_float(key, 0, 10, 31);
    b.view[j] = brdf_at_view(brdf_params_for_punctual_light(s), b.n[j], b.v[j]);
  }
  return b;
}

// Scalar viewer terms views[0, 8) as lanes (the inputs gltf_brdf_lanes and the scalar
// gltf_brdf then share exactly).
BrdfAtViewLanes<8> load_views(const BrdfAtView* views) {
  alignas(64) float c[13][8];
  for (int j = 0; j < 8; ++j) {
    const BrdfAtView& a = views[j];
    const float fields[13] = {a.base_color.x, a.base_color.y, a.base_color.z, a.f0.x, a.f0.y, a.f0.z, a.alpha,
                              a.cos_nv, a.diffuse_weight, a.dielectric_f0, a.one_minus_e_v, a.one_minus_e_avg,
                              a.smith_view_root};
    for (int k = 0; k < 13; ++k) c[k][j] = fields[k];
  }
  BrdfAtViewLanes<8> out;
  out.base_color = {L::load(c[0]), L::load(c[1]), L::load(c[2])};
  out.f0 = {L::load(c[3]), L::load(c[4]), L::load(c[5])};
  out.alpha = L::load(c[6]), out.cos_nv = L::load(c[7]), out.diffuse_weight = L::load(c[8]);
  out.dielectric_f0 = L::load(c[9]), out.one_minus_e_v = L::load(c[10]), out.one_minus_e_avg = L::load(c[11]);
  out.smith_view_root = L::load(c[12]);
  return out;
}

TEST(BrdfLanes, EveryLaneHasTheBitsOfTheScalarBrdf) {
  std::size_t below = 0, lit = 0;
  for (std::uint32_t i = 0; i < 4000; ++i) {
    const Batch b = batch(i);
    const auto views = load_views(b.view);
    const BrdfValueLanes<8> f = gltf_brdf_lanes(views, V::load(b.n, 8), V::load(b.l, 8), V::load(b.v, 8));
    glm::vec3 diffuse[8], specular[8];
    f.diffuse.store(diffuse, 8);
    f.specular.store(specular, 8);
    for (int j = 0; j < 8; ++j) {
      const BrdfValue expected = gltf_brdf(b.view[j], b.n[j], b.l[j], b.v[j]);
      ASSERT_EQ(diffuse[j], expected.diffuse) << i << " lane " << j;
      ASSERT_EQ(specular[j], expected.specular) << i << " lane " << j;
      (glm::dot(b.n[j], b.l[j]) <= 0.0f ? below : lit) += 1;
    }
  }
  EXPECT_GT(below, 10000u);
  EXPECT_GT(lit, 10000u);
}

TEST(BrdfLanes, ViewerTermsHaveTheBitsOfTheScalarForm) {
  // Every field of BrdfAtView, for parameters past their ranges too (metallic and
  // transmission outside [0, 1], α below the smallest the BRDF evaluates).
  for (std::uint32_t i = 0; i < 4000; ++i) {
    Batch b = batch(i);
    BrdfParams params[8];
    alignas(32) float c[8][8];
    for (int j = 0; j < 8; ++j) {
      params[j] = brdf_params_for_punctual_light(b.s[j]);
      if (j == 2) params[j].metallic = 1.5f, params[j].transmission = -0.5f, params[j].alpha = 1e-6f;
      const BrdfParams& q = params[j];
      const float fields[8] = {q.base_color.x, q.base_color.y, q.base_color.z, q.metallic,
                               q.alpha,        q.dielectric_f0, q.transmission, 0.0f};
      for (int k = 0; k < 8; ++k) c[k][j] = fields[k];
    }
    BrdfParamsLanes<8> lanes;
    lanes.base_color = {L::load(c[0]), L::load(c[1]), L::load(c[2])};
    lanes.metallic = L::load(c[3]), lanes.alpha = L::load(c[4]), lanes.dielectric_f0 = L::load(c[5]);
    lanes.transmission = L::load(c[6]);
    const BrdfAtViewLanes<8> got = brdf_at_view_lanes(lanes, V::load(b.n, 8), V::load(b.v, 8));
    glm::vec3 base[8], f0[8];
    got.base_color.store(base, 8), got.f0.store(f0, 8);
    for (int j = 0; j < 8; ++j) {
      const BrdfAtView e = brdf_at_view(params[j], b.n[j], b.v[j]);
      ASSERT_EQ(base[j], e.base_color) << i << " lane " << j;
      ASSERT_EQ(f0[j], e.f0) << i << " lane " << j;
      const float scalar[9] = {e.alpha, e.cos_nv, e.diffuse_weight, e.dielectric_f0, e.one_minus_e_v,
                               e.one_minus_e_avg, e.smith_view_root, e.scale_at_view, e.bias_at_view};
      const float lane[9] = {got.alpha[j], got.cos_nv[j], got.diffuse_weight[j], got.dielectric_f0[j],
                             got.one_minus_e_v[j], got.one_minus_e_avg[j], got.smith_view_root[j],
                             got.scale_at_view[j], got.bias_at_view[j]};
      for (int k = 0; k < 9; ++k) ASSERT_EQ(std::bit_cast<std::uint32_t>(lane[k]), std::bit_cast<std::uint32_t>(scalar[k])) << i << " lane " << j << " field " << k;
    }
  }
}

TEST(BrdfLanes, AlbedoLookupHasTheBitsOfTheScalarTable) {
  // The grid's ends and cell edges too: μ and α at 0, 1, past them, and on the cell borders.
  alignas(32) float mu[8], alpha[8], f0[8];
  for (std::uint32_t i = 0; i < 3000; ++i) {
    for (int j = 0; j < 8; ++j) {
      const std::uint32_t key = i * 8 + std::uint32_t(j);
      const float edge = float(key % 33) / float(kAlbedoTableSize - 1);
      mu[j] = key % 5 == 0 ? edge : 1.2f * random_float(key, 0, 0, 7) - 0.1f;
      alpha[j] = key % 7 == 0 ? edge * edge : 1.2f * random_float(key, 0, 1, 7) - 0.1f;
      f0[j] = random_float(key, 0, 2, 7);
    }
    alignas(32) float got[8];
    L::store(specular_albedo_lanes<8>(L::load(mu), L::load(alpha), L::load(f0)), got);
    for (int j = 0; j < 8; ++j) ASSERT_EQ(got[j], specular_albedo(mu[j], alpha[j])(f0[j])) << i << " lane " << j;
  }
}

TEST(BrdfLanes, LightSamplersAndShadeLightHaveTheScalarBits) {
  // A point light with a range, an unbounded one, a spot and a directional light; points
  // around them (one exactly at the point light: no direction, no light).
  std::vector<Light> lights(4);
  lights[0].type = LightType::Point, lights[0].position = {0.5f, 1.0f, -0.5f}, lights[0].range = 3.0f;
  lights[0].intensity = 7.0f, lights[0].color = {1.0f, 0.8f, 0.6f};
  lights[1].type = LightType::Point, lights[1].position = {-1.0f, 0.5f, 1.0f}, lights[1].intensity = 2.0f;
  lights[2].type = LightType::Spot, lights[2].position = {0.0f, 2.0f, 0.0f}, lights[2].direction = {0.2f, -1.0f, 0.1f};
  lights[2].inner_cone = 0.3f, lights[2].outer_cone = 0.6f, lights[2].intensity = 20.0f;
  lights[3].type = LightType::Directional, lights[3].direction = {0.3f, -1.0f, 0.2f}, lights[3].intensity = 3.0f;
  std::size_t reached = 0;
  for (std::uint32_t i = 0; i < 3000; ++i) {
    Batch b = batch(i);
    if (i % 10 == 0) b.p[3] = lights[0].position;
    alignas(32) float mirror_flag[8];
    for (int j = 0; j < 8; ++j) mirror_flag[j] = b.s[j].is_mirror_lobe() ? 1.0f : 0.0f;
    const auto views = load_views(b.view);
    const V p = V::load(b.p, 8), n = V::load(b.n, 8), v = V::load(b.v, 8);
    for (const Light& light : lights) {
      const LightSampler sampler(light);
      V dir, irradiance;
      sampler.sample(p, dir, irradiance);
      const V shaded = shade_light_lanes<8>(views, L::load(mirror_flag) > 0.0f, n, v, dir, irradiance);
      glm::vec3 got_dir[8], got_irradiance[8], got_shaded[8];
      dir.store(got_dir, 8), irradiance.store(got_irradiance, 8), shaded.store(got_shaded, 8);
      for (int j = 0; j < 8; ++j) {
        const LightSample expected = sampler(b.p[j]);
        ASSERT_EQ(got_dir[j], expected.direction) << i << " lane " << j;
        ASSERT_EQ(got_irradiance[j], expected.irradiance) << i << " lane " << j;
        ASSERT_EQ(got_shaded[j], shade_light(b.s[j], b.view[j], b.n[j], b.v[j], expected)) << i << " lane " << j;
        reached += expected.irradiance != glm::vec3(0.0f) && glm::dot(b.n[j], expected.direction) > 0.0f;
      }
    }
  }
  EXPECT_GT(reached, 20000u);
}

}  // namespace
}  // namespace speculum
