// Tests of shadow maps and direct light: the filtered shadow test against a geometric
// oracle (a square occluder over a floor under a point light, and a directional light),
// and unshadowed direct light equal to the shared shading model.
#include "raster/shadow_map.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

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

// `footprint`: half-width (in scene units) of the 3×3 PCF kernel plus bias, where the
// filtered result is legitimately fractional.
void check_against_oracle(const Light& light, float footprint) {
  const Scene scene = floor_and_occluder(light);
  par::Executor ex(2);
  const auto maps = render_shadow_maps(ex, scene, 256);
  ASSERT_EQ(maps.size(), 1u);
  Camera cam;
  cam.eye = {0.5f, 6.0f, 4.0f};
  cam.target = {0, 0, 0};
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
  Camera cam;
  cam.eye = {0.5f, 6.0f, 4.0f};
  cam.target = {0, 0, 0};
  const auto vis = render_visibility(ex, scene, cam, 64, 48);
  const GBuffer g = resolve_gbuffer(ex, scene, vis, cam.eye);
  const ImageRGBA direct = direct_light(ex, scene, g, cam, {}, env);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < direct.size(); ++i) {
    if (!g.covered(i)) continue;
    const glm::vec3 p = g.position.pixels[i], n = g.normal.pixels[i], v = g.view_direction(i);
    const LightSample ls = sample_light(l, p);
    const glm::vec3 expected = glm::dot(n, ls.direction) > 0.0f
                                   ? shade_light(g.surface.pixels[i], n, v, ls)
                                   : glm::vec3(0.0f);
    EXPECT_NEAR(direct.pixels[i].x, expected.x, 1e-5f + 1e-5f * expected.x);
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
}

}  // namespace
}  // namespace speculum::raster
