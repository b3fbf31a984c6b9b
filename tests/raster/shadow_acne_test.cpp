// Tests of the shadow test's bias: a large rough plane under a point light with no
// occluder must come out fully lit at every incidence, grazing included (no self-shadowing
// "acne" bands), while a box standing on that plane still casts its shadow right up to its
// base (the bias must not switch contact shadows off).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/image.h"
#include "raster/direct_light.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

constexpr float kPlaneHalfSize = 20.0f;
constexpr int kShadowMapSize = 512;  // ShadowMapPass's default, what the pipelines render

// A white dielectric plane of roughness 1 (y = 0, normal +y), 40 × 40 units.
Scene rough_plane(const glm::vec3& light_position) {
  Scene scene;
  scene.name = "rough plane";
  Material white;
  white.base_color = glm::vec4(1.0f);
  white.metallic = 0.0f;
  white.roughness = 1.0f;
  scene.materials.push_back(white);
  const float h = kPlaneHalfSize;
  testing::add_triangles(scene, {{-h, 0, -h}, {h, 0, -h}, {h, 0, h}, {-h, 0, h}}, {0, 2, 1, 0, 3, 2});
  Light light;
  light.type = LightType::Point;
  light.position = light_position;
  light.intensity = 4.0f;
  scene.lights.push_back(light);
  return scene;
}

// An axis-aligned box [lo, hi] of five faces (no bottom), wound outward.
void add_box(Scene& scene, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 c = 0.5f * (lo + hi), e = 0.5f * (hi - lo);
  // Each face: centre offset along its outward normal n, and half-axes u, v with u × v = n.
  const glm::vec3 x{e.x, 0, 0}, y{0, e.y, 0}, z{0, 0, e.z};
  const glm::vec3 faces[5][3] = {{x, y, z}, {-x, z, y}, {z, x, y}, {-z, y, x}, {y, z, x}};
  for (const auto& f : faces) {
    const glm::vec3 centre = c + f[0], u = f[1], v = f[2];
    testing::add_triangles(scene, {centre - u - v, centre + u - v, centre + u + v, centre - u + v},
                           {0, 1, 2, 0, 2, 3});
  }
}

// The plane from above one end, looking across it: the far part is seen at a low angle
// and lit at grazing incidence.
Camera plane_camera() {
  Camera cam;
  cam.eye = {0.0f, 5.0f, 9.0f};
  cam.target = {0.0f, 0.0f, -3.0f};
  cam.vfov_degrees = 70.0f;
  return cam;
}

constexpr int kWidth = 192, kHeight = 144;

struct Frame {
  GBuffer g;
  ImageRGBA shadowed, unshadowed;  // direct light with and without the shadow maps
  std::vector<ShadowMap> maps;
};

Frame render_frame(par::Executor& ex, const Scene& scene, const Camera& cam) {
  const auto vis = render_visibility(ex, scene, cam, kWidth, kHeight);
  Frame f{resolve_gbuffer(ex, scene, vis, cam.eye), {}, {}, render_shadow_maps(ex, scene, kShadowMapSize)};
  const EnvironmentMap black = build_environment(ex, Environment{}, 8);
  f.shadowed = direct_light(ex, scene, f.g, cam, f.maps, black);
  f.unshadowed = direct_light(ex, scene, f.g, cam, {}, black);
  return f;
}

// The 8-bit sRGB value an image pixel is written as (red channel; the scene is grey).
int srgb8(const ImageRGBA& img, std::size_t i) {
  return static_cast<int>(std::lround(255.0f * linear_to_srgb(std::clamp(img.pixels[i].x, 0.0f, 1.0f))));
}

// Over vertically neighbouring covered pixels: the largest 8-bit step of `img`, and the
// most by which a step of `img` exceeds the same step of `smooth`.
struct ColumnSteps {
  int largest = 0;
  int excess = 0;
};
ColumnSteps column_steps(const ImageRGBA& img, const ImageRGBA& smooth, const GBuffer& g) {
  ColumnSteps s;
  for (int y = 0; y + 1 < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::size_t a = static_cast<std::size_t>(y) * img.width + x, b = a + img.width;
      if (!g.covered(a) || !g.covered(b)) continue;
      const int step = std::abs(srgb8(img, a) - srgb8(img, b));
      s.largest = std::max(s.largest, step);
      s.excess = std::max(s.excess, step - std::abs(srgb8(smooth, a) - srgb8(smooth, b)));
    }
  return s;
}

struct LightCase {
  const char* name;
  glm::vec3 position;
};
class UnoccludedPlane : public ::testing::TestWithParam<LightCase> {};

TEST_P(UnoccludedPlane, IsFullyLitAtEveryIncidence) {
  const Scene scene = rough_plane(GetParam().position);
  par::Executor ex(2);
  const Frame f = render_frame(ex, scene, plane_camera());
  std::size_t checked = 0, grazing = 0, self_shadowed = 0, darkened = 0;
  for (std::size_t i = 0; i < f.g.object.size(); ++i) {
    if (!f.g.covered(i)) continue;
    const glm::vec3 p = f.g.position.pixels[i], n = f.g.normal.pixels[i];
    const LightSample ls = sample_light(scene.lights[0], p);
    const float cos_theta = glm::dot(n, ls.direction);
    if (cos_theta <= 0.0f) continue;
    ++checked;
    grazing += cos_theta < 0.2f;  // beyond ~78° from the normal
    self_shadowed += f.maps[0].visibility(p, n, ls.direction) != 1.0f;
    darkened += f.shadowed.pixels[i] != f.unshadowed.pixels[i];
  }
  EXPECT_EQ(self_shadowed, 0u) << "of " << checked << " lit plane pixels";
  EXPECT_EQ(darkened, 0u) << "of " << checked << " lit plane pixels";
  EXPECT_GT(checked, std::size_t(kWidth * kHeight) / 2);
  EXPECT_GT(grazing, 500u);  // the case the bias has to survive is actually in view
  // No bands: no step between rows exceeds the unshadowed lighting's own step there.
  const ColumnSteps steps = column_steps(f.shadowed, f.unshadowed, f.g);
  EXPECT_EQ(steps.excess, 0) << "largest row-to-row step " << steps.largest << "/255, unshadowed "
                             << column_steps(f.unshadowed, f.unshadowed, f.g).largest << "/255";
}

// Lights low over the plane (grazing over most of the view), beside the view axis, and high.
INSTANTIATE_TEST_SUITE_P(LightPositions, UnoccludedPlane,
                         ::testing::Values(LightCase{"Low", {0.0f, 0.5f, 0.0f}},
                                           LightCase{"Beside", {2.0f, 1.0f, -1.0f}},
                                           LightCase{"Skimming", {-3.0f, 0.25f, 4.0f}},
                                           LightCase{"High", {1.0f, 3.0f, -4.0f}}),
                         [](const auto& info) { return std::string(info.param.name); });

// Whether the segment from p to q crosses the box [lo, hi] (slab test).
bool segment_crosses_box(const glm::vec3& p, const glm::vec3& q, const glm::vec3& lo, const glm::vec3& hi) {
  float t0 = 0.0f, t1 = 1.0f;
  const glm::vec3 d = q - p;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12f) {
      if (p[k] < lo[k] || p[k] > hi[k]) return false;
      continue;
    }
    float a = (lo[k] - p[k]) / d[k], b = (hi[k] - p[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

// A box standing on the plane beside the light, lo.x > 0 (the light is at x = 0).
struct Occluder {
  const char* name;
  glm::vec3 lo, hi;
};
class OccluderOnPlane : public ::testing::TestWithParam<Occluder> {};

TEST_P(OccluderOnPlane, KeepsItsShadowUpToItsBase) {
  const glm::vec3 light{0.0f, 1.5f, 0.0f};
  const auto [name, lo, hi] = GetParam();
  Scene scene = rough_plane(light);
  add_box(scene, lo, hi);
  par::Executor ex(2);
  // Straight down onto the shadow, x ∈ [1.8, 3] on the plane.
  Camera cam;
  cam.eye = {2.4f, 2.5f, 0.8f};
  cam.target = {2.4f, 0.0f, 0.0f};
  const Frame f = render_frame(ex, scene, cam);
  // Beyond the box the plane is ≈ 2.3 units from the light: a cube texel there is
  // 2·2.3/512 ≈ 0.009 units wide. Pixels whose shadow ray passes 4 texels inside the box's
  // top and sides are umbra, 4 texels outside them lit. The box's base stays in the umbra:
  // the plane touches it there, which is where too large a bias would let light under it.
  const float margin = 0.036f;
  const glm::vec3 inside_lo = lo + glm::vec3(0, 0, margin), inside_hi = hi - glm::vec3(0, margin, margin);
  const glm::vec3 outside_lo = lo - glm::vec3(margin), outside_hi = hi + glm::vec3(margin);
  std::size_t umbra = 0, contact = 0, lit = 0, umbra_lit = 0, contact_lit = 0, lit_shadowed = 0;
  for (std::size_t i = 0; i < f.g.object.size(); ++i) {
    if (!f.g.covered(i) || f.g.object.pixels[i] != 0) continue;  // plane pixels only
    const glm::vec3 p = f.g.position.pixels[i], n = f.g.normal.pixels[i];
    const LightSample ls = sample_light(scene.lights[0], p);
    const float v = f.maps[0].visibility(p, n, ls.direction);
    if (segment_crosses_box(p, light, inside_lo, inside_hi)) {
      ++umbra;
      umbra_lit += v != 0.0f;
      if (p.x < hi.x + 0.05f) {  // within ≈ 5 texels of the box's far face
        ++contact;
        contact_lit += f.shadowed.pixels[i] != glm::vec4(0, 0, 0, 1);
      }
    } else if (!segment_crosses_box(p, light, outside_lo, outside_hi)) {
      ++lit;
      lit_shadowed += v != 1.0f;
    }
  }
  EXPECT_EQ(umbra_lit, 0u) << "of " << umbra << " umbra pixels";
  EXPECT_EQ(contact_lit, 0u) << "of " << contact << " pixels at the box's base";
  EXPECT_EQ(lit_shadowed, 0u) << "of " << lit << " pixels the box does not shadow";
  EXPECT_GT(umbra, 1000u);
  EXPECT_GT(contact, 50u);
  EXPECT_GT(lit, std::size_t(kWidth * kHeight) / 2);
}

// A 0.6 cube, and a panel two texels thick: behind the panel the nearest occluding surface
// is only 0.02 units in front of the plane, so a depth bias of more than about two texel
// footprints would light the plane right behind it.
INSTANTIATE_TEST_SUITE_P(Boxes, OccluderOnPlane,
                         ::testing::Values(Occluder{"Cube", {1.2f, 0.0f, -0.3f}, {1.8f, 0.6f, 0.3f}},
                                           Occluder{"Panel", {1.78f, 0.0f, -0.3f}, {1.8f, 0.6f, 0.3f}}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace speculum::raster
