// Tests of shadow maps and direct light: the filtered shadow test against a geometric
// oracle (a square occluder over a floor under a point light, and a directional light),
// and unshadowed direct light equal to the shared shading model; a spot light's cone,
// falloff and shadow in direct_light, and its SH ambient term; a spot light's cube, which
// holds only the faces its cone reaches, against a point light's whole cube; and the pass's
// SurfaceShader (one point and eight at a time) against shade_surface's per-call form, and
// eight shadow tests at once against one at a time, bit for bit.
#include "raster/shadow_map.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/brdf.h"
#include "core/optics.h"
#include "core/sampling.h"
#include "raster/direct_light.h"
#include "raster/gbuffer.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

Scene floor_and_occluder(const Light& light) {
  Scene scene;
  scene.name = "occluder";
  testing::add_triangles(scene, {{-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}}, {0, 2, 1, 0, 3, 2});
  testing::add_triangles(scene, {{-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}},
                         {0, 2, 1, 0, 3, 2});
  scene.lights.push_back(light);
  return scene;
}

// Signed distance of the occluder's square edge from where the shadow ray of p crosses y=1
// (positive: inside the square, i.e. shadowed).
float occluder_margin(const glm::vec3& p, const glm::vec3& towards_light) {
  const float t = (1.0f - p.y) / towards_light.y;
  const glm::vec3 q = p + t * towards_light;
  return std::min(0.5f - std::abs(q.x), 0.5f - std::abs(q.z));
}

// The floor seen from above and in front: the camera every test here looks through.
Camera overhead_camera() {
  Camera cam;
  cam.eye = {0.5f, 6.0f, 4.0f};
  cam.target = {0, 0, 0};
  return cam;
}

// The G-buffer of `scene` from overhead_camera() at width × height, and its direct light.
struct LitFrame {
  GBuffer g;
  ImageRGBA direct;
};
LitFrame light_frame(par::Executor& ex, const Scene& scene, int width, int height, const std::vector<ShadowMap>& maps,
                     const EnvironmentMap& env) {
  const Camera cam = overhead_camera();
  const auto vis = render_visibility(ex, scene, cam, width, height);
  LitFrame f{resolve_gbuffer(ex, scene, vis, cam.eye), {}};
  f.direct = direct_light(ex, scene, f.g, cam, maps, env);
  return f;
}

// `footprint`: half-width (in scene units) of the 3×3 PCF kernel plus bias, where the
// filtered result is legitimately fractional.
void check_against_oracle(const Light& light, float footprint) {
  const Scene scene = floor_and_occluder(light);
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, 256);
  ASSERT_EQ(maps.size(), 1u);
  const Camera cam = overhead_camera();
  const auto vis = render_visibility(ex, scene, cam, 320, 240);
  const GBuffer g = resolve_gbuffer(ex, scene, vis, cam.eye);
  std::size_t shadowed = 0, lit = 0, penumbra = 0;
  for (std::size_t i = 0; i < g.object.size(); ++i) {
    if (!g.covered(i) || g.object.pixels[i] != 0) continue;
    const glm::vec3 p = g.position.pixels[i];
    const LightSample ls = sample_light(light, p);
    const float margin = occluder_margin(p, ls.direction);
    const float v = maps[0].visibility(p, g.normal.pixels[i], ls.direction);
    if (std::abs(margin) < footprint) { ++penumbra; continue; }
    if (margin > 0) { EXPECT_EQ(v, 0.0f) << p.x << "," << p.z; ++shadowed; }
    else { EXPECT_EQ(v, 1.0f) << p.x << "," << p.z; ++lit; }
  }
  EXPECT_GT(shadowed, 300u);
  EXPECT_GT(lit, 8000u);
  EXPECT_LT(penumbra, lit / 10);
}

TEST(ShadowMap, PointLightShadowMatchesGeometricOracle) {
  Light l;
  l.type = LightType::Point;
  l.position = {0.2f, 3.0f, 0.1f};
  l.intensity = 10.0f;
  check_against_oracle(l, 0.06f);  // cube texel ≈ 2·3/256 ≈ 0.023 units at the floor
}

TEST(ShadowMap, DirectionalLightShadowMatchesGeometricOracle) {
  Light l;
  l.type = LightType::Directional;
  l.direction = glm::normalize(glm::vec3(0.3f, -1.0f, 0.2f));
  l.intensity = 2.0f;
  check_against_oracle(l, 0.15f);  // the map spans the scene's 14-unit sphere: texel ≈ 0.055
}

TEST(DirectLight, UnshadowedEqualsSharedShadingModel) {
  Light l;
  l.type = LightType::Point;
  l.position = {1.0f, 2.0f, 0.5f};
  l.intensity = 5.0f;
  Scene scene = floor_and_occluder(l);
  par::Executor ex(1);
  Environment black;
  const EnvironmentMap env = build_environment(ex, black, 8);
  const auto [g, direct] = light_frame(ex, scene, 64, 48, {}, env);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < direct.size(); ++i) {
    if (!g.covered(i)) continue;
    const glm::vec3 p = g.position.pixels[i], n = g.normal.pixels[i], v = g.view_direction(i);
    const LightSample ls = sample_light(l, p);
    const glm::vec3 expected = glm::dot(n, ls.direction) > 0.0f
                                   ? shade_light(g.surface[i], n, v, ls)
                                   : glm::vec3(0.0f);
    EXPECT_NEAR(direct.pixels[i].x, expected.x, 1e-5f + 1e-5f * expected.x);
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
}

// A spot straight down over the floor, beside the blocker's centre: on the floor its inner
// cone has radius ≈ 1.09 and its outer cone ≈ 2.53 around (0.2, 0.1).
Light overhead_spot() {
  Light l;
  l.type = LightType::Spot;
  l.position = {0.2f, 3.0f, 0.1f};
  l.direction = {0.0f, -1.0f, 0.0f};
  l.intensity = 10.0f;
  l.inner_cone = 0.35f;
  l.outer_cone = 0.7f;
  return l;
}

TEST(ShadowMap, SpotLightShadowMatchesGeometricOracle) {
  // Spot lights share the point lights' distance cube: the shadow test ignores the cone.
  check_against_oracle(overhead_spot(), 0.06f);
}

// The glTF KHR_lights_punctual spot falloff, written out independently of core/shading.cpp:
// E = I/d² · clamp((cos θ − cos outer)/(cos inner − cos outer), 0, 1)², θ from the axis.
float documented_spot_irradiance(const Light& l, const glm::vec3& p, float* cone_out) {
  const glm::vec3 from_light = p - l.position;
  const float d2 = glm::dot(from_light, from_light);
  const float cos_theta = glm::dot(glm::normalize(from_light), glm::normalize(l.direction));
  const float a = std::clamp((cos_theta - std::cos(l.outer_cone)) /
                                 (std::cos(l.inner_cone) - std::cos(l.outer_cone)),
                             0.0f, 1.0f);
  *cone_out = a;
  return l.intensity * a * a / d2;
}

TEST(DirectLight, SpotLightConeFalloffAndShadow) {
  // A spot above a floor with a square blocker: floor points in the blocker's shadow and
  // points outside the cone get no direct light; lit points inside the cone get the shading
  // model with the documented falloff (full I/d² inside the inner cone).
  Light l = overhead_spot();
  l.color = {1.0f, 0.5f, 0.25f};
  Scene scene = floor_and_occluder(l);
  scene.materials[0].metallic = 0.0f;  // a diffuse floor (glTF's default is metallic)
  scene.materials[0].base_color = {0.8f, 0.8f, 0.8f, 1.0f};
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, 256);
  Environment black;
  const EnvironmentMap env = build_environment(ex, black, 8);  // no ambient light
  const auto [g, direct] = light_frame(ex, scene, 320, 240, maps, env);
  std::size_t outside = 0, shadowed = 0, inner = 0, falloff = 0;
  for (std::size_t i = 0; i < g.object.size(); ++i) {
    if (!g.covered(i) || g.object.pixels[i] != 0) continue;
    const glm::vec3 p = g.position.pixels[i], n = g.normal.pixels[i], v = g.view_direction(i);
    const glm::vec3 c = glm::vec3(direct.pixels[i]);
    float a = 0.0f;
    const float e = documented_spot_irradiance(l, p, &a);
    const glm::vec3 to_light = glm::normalize(l.position - p);
    if (a == 0.0f) {
      ASSERT_EQ(c, glm::vec3(0.0f)) << "outside the cone: " << p.x << "," << p.z;
      ++outside;
      continue;
    }
    const float margin = occluder_margin(p, to_light);
    if (std::abs(margin) < 0.06f) continue;  // penumbra of the 3×3 PCF
    if (margin > 0.0f) {
      ASSERT_EQ(c, glm::vec3(0.0f)) << "in the shadow: " << p.x << "," << p.z;
      ++shadowed;
      continue;
    }
    LightSample ls;
    ls.direction = to_light;
    ls.distance = glm::length(l.position - p);
    ls.irradiance = l.color * e;
    const glm::vec3 expected = shade_light(g.surface[i], n, v, ls);
    ASSERT_GT(expected.x, 0.0f);
    for (int ch = 0; ch < 3; ++ch)
      ASSERT_NEAR(c[ch], expected[ch], 1e-4f * expected[ch] + 1e-7f) << p.x << "," << p.z;
    ++(a == 1.0f ? inner : falloff);
  }
  EXPECT_GT(outside, 20000u);
  EXPECT_GT(shadowed, 1000u);
  EXPECT_GT(inner, 1000u);
  EXPECT_GT(falloff, 10000u);
}

TEST(DirectLight, ConstantEnvironmentGivesLambertAmbient) {
  // No lights; a constant environment of radiance L has irradiance π·L on every normal, so
  // the ambient term is f_d·E = (1 − E_d(N·V)) base_color/π · π·L (the coupled Lambert lobe,
  // core/brdf.h), and a rough surface's specular lobe adds E(F0)·L (every prefiltered level
  // of a constant environment is L).
  Light unused;
  Scene scene = floor_and_occluder(unused);
  scene.lights.clear();
  scene.materials[0].metallic = 0.0f;
  scene.materials[0].base_color = {0.8f, 0.6f, 0.4f, 1.0f};
  Environment sky;
  sky.constant = {0.5f, 1.0f, 2.0f};
  par::Executor ex(2);
  const EnvironmentMap env = build_environment(ex, sky, 8);
  const auto [g, direct] = light_frame(ex, scene, 64, 48, {}, env);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < direct.size(); ++i) {
    if (!g.covered(i)) continue;
    const SurfaceParams& s = g.surface[i];
    const float cos_nv = glm::dot(g.normal.pixels[i], g.view_direction(i));
    const float e_d = specular_albedo(cos_nv, brdf_params_for_punctual_light(s).alpha)(fresnel_f0(s.ior));
    glm::vec3 expected = (1.0f - e_d) * glm::vec3(0.8f, 0.6f, 0.4f) * sky.constant;
    if (s.has_rough_specular_lobe()) expected += specular_reflectance(s, cos_nv) * sky.constant;
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(direct.pixels[i][ch], expected[ch], 0.01f * expected[ch]) << i << " ch " << ch;
    ++checked;
  }
  EXPECT_GT(checked, 1000u);

  // A metal has no diffuse term, hence no SH ambient: its environment light is the
  // specular layer's alone, E(base_color)·L when it is too rough for a reflection pass.
  scene.materials[0].metallic = 1.0f;
  const auto [gm, metal] = light_frame(ex, scene, 64, 48, {}, env);
  std::size_t rough = 0;
  for (std::size_t i = 0; i < metal.size(); ++i) {
    if (!gm.covered(i)) continue;
    const SurfaceParams& s = gm.surface[i];
    glm::vec3 expected(0.0f);
    if (s.has_rough_specular_lobe()) {
      expected = specular_reflectance(s, glm::dot(gm.normal.pixels[i], gm.view_direction(i))) * sky.constant;
      ++rough;
    }
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(metal.pixels[i][ch], expected[ch], 0.01f * expected[ch] + 1e-7f) << i << " ch " << ch;
  }
  EXPECT_GT(rough, 1000u);
}

// A spot light at the overhead spot's place turned by `tilt` radians about +Z, and a point
// light at the same place: the point light's shadow cube has every face, rendered with the
// same options, so its taps are what the spot's must be wherever the spot lights a point.
Scene spot_and_point_at_one_place(float tilt, float outer_cone) {
  Light spot = overhead_spot();
  spot.direction = {std::sin(tilt), -std::cos(tilt), 0.0f};
  spot.outer_cone = outer_cone;
  spot.inner_cone = 0.5f * outer_cone;
  Scene scene = floor_and_occluder(spot);
  Light point = spot;
  point.type = LightType::Point;
  scene.lights.push_back(point);
  return scene;
}

int rendered_faces(const CubeMap& cube) {
  int faces = 0;
  for (const ImageF& face : cube.distance)
    faces += std::any_of(face.pixels.begin(), face.pixels.end(), [](float d) { return std::isfinite(d); });
  return faces;
}

// Points in the spot's cone, nearest its edge (where the cone crosses onto another face),
// at distances before and beyond the floor, with normals at every angle to the light, the
// grazing ones (the largest normal offset) included.
void expect_spot_cube_reads_like_the_whole_cube(const Scene& scene, int size) {
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, size);
  ASSERT_EQ(maps.size(), 2u);
  const Light& spot = scene.lights[0];
  const Onb frame(glm::normalize(spot.direction));
  std::size_t shadowed = 0, lit = 0;
  for (std::uint32_t i = 0; i < 40000; ++i) {
    const glm::vec2 u = random_float2(i, 0, 0, 5);
    const float angle = spot.outer_cone * std::sqrt(u.x);  // denser towards the edge
    const glm::vec3 d = frame.to_world(spherical_local(std::cos(angle), u.y));
    const glm::vec3 p = spot.position + d * (0.5f + 6.0f * random_float(i, 0, 2, 5));
    const LightSample ls = sample_light(spot, p);
    if (ls.irradiance == glm::vec3(0.0f)) continue;
    glm::vec3 n = spherical_local(random_float(i, 0, 3, 5), random_float(i, 0, 4, 5));
    n = Onb(ls.direction).to_world(n);  // any angle to the light, from normal to grazing
    const float expected = maps[1].visibility(p, n, ls.direction);
    ASSERT_EQ(maps[0].visibility(p, n, ls.direction), expected) << i;
    ++(expected == 0.0f ? shadowed : lit);
  }
  EXPECT_GT(shadowed, 1000u);
  EXPECT_GT(lit, 1000u);
}

TEST(ShadowMap, SpotLightCubeHoldsTheFacesItsConeReaches) {
  // Straight down with a 0.7 rad cone: the -Y face alone (its sides start at 45°).
  const Scene down = spot_and_point_at_one_place(0.0f, 0.7f);
  par::Executor ex(2);
  const auto down_maps = render_shadow_maps(ex, down, 128);
  EXPECT_EQ(rendered_faces(down_maps[0].cube), 1);
  EXPECT_GT(rendered_faces(down_maps[1].cube), 1);
  expect_spot_cube_reads_like_the_whole_cube(down, 128);
  // Turned 35° towards +X with a 0.2 rad cone: its edge crosses 10° onto the +X face.
  const Scene tilted = spot_and_point_at_one_place(0.61086524f, 0.2f);
  const auto tilted_maps = render_shadow_maps(ex, tilted, 256);
  EXPECT_LT(rendered_faces(tilted_maps[0].cube), 6);
  expect_spot_cube_reads_like_the_whole_cube(tilted, 256);
}

// The occluder scene under the overhead spot, a point light with a range and a sun: one light
// of each kind, each with its shadow map.
Scene spot_point_and_sun() {
  Scene scene = floor_and_occluder(overhead_spot());
  Light point;
  point.type = LightType::Point;
  point.position = {-1.0f, 2.0f, 1.5f};
  point.intensity = 6.0f;
  point.range = 8.0f;
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = {0.3f, -1.0f, 0.2f};
  scene.lights.push_back(point);
  scene.lights.push_back(sun);
  return scene;
}

TEST(DirectLight, SurfaceShaderGivesTheBitsOfPerCallShading) {
  // A point, a spot and a directional light, each with its shadow map, and an environment
  // with some colour; surfaces of every class (diffuse, glossy, mirror, rough metal,
  // refractor) at random points, normals and viewers.
  const Scene scene = spot_point_and_sun();
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, 128);
  Environment sky;
  sky.constant = {0.2f, 0.3f, 0.5f};
  const EnvironmentMap env = build_environment(ex, sky, 16);
  const SurfaceShader shader(scene, maps, env);
  std::size_t shaded = 0;
  SurfaceParams batch_s[8];
  glm::vec3 batch_p[8], batch_n[8], batch_v[8], batch_expected[8];
  int filled = 0, batch_size = 1;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    SurfaceParams s;
    const glm::vec2 a = random_float2(i, 0, 0, 9);
    s.roughness = std::array<float, 5>{1.0f, 0.3f, 0.0f, 0.8f, 0.0f}[i % 5];
    s.metallic = i % 5 == 3 ? 1.0f : a.x;
    s.transmission = i % 5 == 4 ? 1.0f : 0.0f;
    s.base_color = glm::vec3(a.y, 0.5f, 1.0f - a.y);
    s.emissive = glm::vec3(i % 11 == 0 ? 0.25f : 0.0f);
    Material m;
    m.roughness = s.roughness;
    s.phong_exponent = m.phong_exponent();
    const glm::vec2 across = random_float2(i, 0, 2, 9);
    const glm::vec3 p(6.0f * across.x - 3.0f, 2.0f * random_float(i, 0, 4, 9), 6.0f * across.y - 3.0f);
    const glm::vec3 n = spherical_local(1.0f - 2.0f * random_float(i, 0, 5, 9), random_float(i, 0, 6, 9));
    const glm::vec3 v = spherical_local(1.0f - 2.0f * random_float(i, 0, 7, 9), random_float(i, 0, 8, 9));
    // shade_surface per call, written out: every light sampled and shaded on its own.
    glm::vec3 nn = glm::dot(n, v) < 0.0f ? -n : n;
    glm::vec3 expected = s.emissive;
    for (std::size_t k = 0; k < scene.lights.size(); ++k) {
      const LightSample ls = sample_light(scene.lights[k], p);
      if (ls.irradiance == glm::vec3(0.0f) || glm::dot(nn, ls.direction) <= 0.0f) continue;
      const float lit = maps[k].visibility(p, nn, ls.direction);
      if (lit > 0.0f) expected += lit * shade_light(s, nn, v, ls);
    }
    expected += diffuse_albedo_over_pi(s, glm::dot(nn, v)) * env.irradiance(nn);
    if (s.has_rough_specular_lobe())
      expected += specular_reflectance(s, glm::dot(nn, v)) * env.radiance(reflect(-v, nn), s.phong_exponent);
    ASSERT_EQ(shader(s, p, n, v), expected) << i;
    ASSERT_EQ(shade_surface(scene, s, p, n, v, maps, env), expected) << i;
    shaded += expected != s.emissive;
    // Batches of 1 to 8 points, this one last: each point's radiance is its own.
    batch_s[filled] = s, batch_p[filled] = p, batch_n[filled] = n, batch_v[filled] = v, batch_expected[filled] = expected;
    if (++filled == batch_size) {
      const SurfaceParams* sp[8];
      for (int j = 0; j < filled; ++j) sp[j] = &batch_s[j];
      glm::vec3 got[8];
      shader.shade8(sp, batch_p, batch_n, batch_v, filled, got);
      for (int j = 0; j < filled; ++j) ASSERT_EQ(got[j], batch_expected[j]) << i << " lane " << j;
      filled = 0;
      batch_size = batch_size % 8 + 1;
    }
  }
  EXPECT_GT(shaded, 15000u);
}

TEST(ShadowMap, EightTestsAtOnceGiveTheBitsOfOneAtATime) {
  // Point, spot and directional maps; points anywhere around the lights (on face edges and
  // corners of the cubes too), normals at every angle to the light, 1 to 8 points a call.
  const Scene scene = spot_point_and_sun();
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, 64);
  std::size_t partly_lit = 0;
  for (std::size_t k = 0; k < maps.size(); ++k) {
    const Light& light = scene.lights[k];
    for (std::uint32_t i = 0; i < 4000; ++i) {
      const int count = static_cast<int>(i % 8) + 1;
      glm::vec3 p[8], n[8], l[8];
      float expected[8], got[8];
      for (int j = 0; j < count; ++j) {
        const std::uint32_t key = i * 8 + std::uint32_t(j);
        glm::vec3 d = spherical_local(1.0f - 2.0f * random_float(key, 0, 0, 21), random_float(key, 0, 1, 21));
        if (key % 5 == 0) d = glm::normalize(glm::vec3(1.0f, key % 2 ? 1.0f : -1.0f, key % 3 ? 0.5f : 1.0f));  // face edges
        p[j] = (light.type == LightType::Directional ? glm::vec3(0.0f) : light.position) +
               d * (0.05f + 5.0f * random_float(key, 0, 2, 21));
        l[j] = light.type == LightType::Directional ? -glm::normalize(light.direction) : glm::normalize(light.position - p[j]);
        n[j] = Onb(l[j]).to_world(spherical_local(random_float(key, 0, 3, 21), random_float(key, 0, 4, 21)));
        expected[j] = maps[k].visibility(p[j], n[j], l[j]);
        partly_lit += expected[j] > 0.0f && expected[j] < 1.0f;
      }
      // The lanes asked: the first `count`, some calls every other one of them.
      const unsigned lanes = ((1u << count) - 1u) & (i % 3 == 0 ? 0x55u : 0xffu);
      using V = Vec3Lanes<8>;
      const V pv = V::load(p, count), nv = V::load(n, count), lv = V::load(l, count);
      maps[k].visibility_lanes(pv, nv, lv, lanes, got);
      ShadowMap::Taps taps[8];
      maps[k].taps_lanes(pv, nv, lv, lanes, taps);
      for (int j = 0; j < count; ++j) {
        if (!((lanes >> j) & 1u)) continue;
        ASSERT_EQ(got[j], expected[j]) << "light " << k << " call " << i << " lane " << j;
        // Where the taps lie and what they are compared with, not only how many pass.
        const ShadowMap::Taps one = maps[k].taps(p[j], n[j], l[j]);
        ASSERT_EQ(taps[j].img, one.img) << "light " << k << " call " << i << " lane " << j;
        ASSERT_EQ(taps[j].cx, one.cx);
        ASSERT_EQ(taps[j].cy, one.cy);
        ASSERT_EQ(taps[j].biased, one.biased) << "light " << k << " call " << i << " lane " << j;
      }
    }
  }
  EXPECT_GT(partly_lit, 100u);
}

}  // namespace
}  // namespace speculum::raster
