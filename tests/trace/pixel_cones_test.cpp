// Tests of the pixel cones (ROGER §5.2.2) on one-pixel G-buffer planes: a flat mirror's
// reflected cone has the pixel's own half-angle (the reflected eye is its apex); a convex
// spot widens it by 2κw; a strongly concave spot would make a double cone and is traced as a
// ray, counted; a glossy lobe adds the angle that holds the asked share of its Phong lobe.
#include "core/sampling.h"
#include "trace/cone_tracing.h"

#include <cmath>

#include <gtest/gtest.h>

namespace speculum::trace {
namespace {

struct OnePixel {
  Buffer2D<glm::vec3> position{1, 1}, normal{1, 1};
  SurfacePlane surface = SurfacePlane::per_sample(Buffer2D<SurfaceParams>(1, 1));
  IdBuffer object{1, 1, 0}, triangle{1, 1, 7};
  ImageF curvature{1, 1, 0.0f};
  Camera camera;
  OnePixel(float kappa, float roughness, float phong) {
    position.pixels[0] = glm::vec3(0.0f);
    normal.pixels[0] = glm::normalize(glm::vec3(0.0f, 1.0f, 1.0f));
    SurfaceParams s;
    s.metallic = 1.0f;
    s.roughness = roughness;
    s.phong_exponent = phong;
    surface.own.pixels[0] = s;
    curvature.pixels[0] = kappa;
    camera.eye = {0.0f, 0.0f, 4.0f};
    camera.target = {0.0f, 0.0f, 0.0f};
    camera.vfov_degrees = 10.0f;  // one pixel spans the whole 10° field
  }
  PixelCones cones(const PixelConeOptions& o = {}) const {
    par::Executor ex(1);
    return pixel_cones(ex, position, normal, surface, object, triangle, curvature, camera, o);
  }
};

TEST(PixelCones, FlatMirrorKeepsThePixelAngleConvexWidensConcaveFallsBack) {
  // Pixel pitch 2 tan 5° at unit distance, on the view axis: Ω = pitch², β = √(Ω/π).
  const float pitch = 2.0f * std::tan(5.0f * speculum::kPi / 180.0f);
  const float beta = std::sqrt(pitch * pitch / speculum::kPi);
  const float w = 4.0f * std::tan(beta);
  const PixelCones flat = OnePixel(0.0f, 0.0f, 0.0f).cones();
  EXPECT_EQ(flat.cones, 1u);
  EXPECT_NEAR(flat.angle[0], beta, 1e-6f);
  EXPECT_NEAR(flat.radius[0], w, 1e-6f);
  EXPECT_EQ(flat.self[0], 7u);
  EXPECT_GT(flat.near[0], 0.0f);

  const PixelCones convex = OnePixel(0.1f, 0.0f, 0.0f).cones();
  EXPECT_NEAR(convex.angle[0], beta + 2.0f * 0.1f * w, 1e-5f);
  EXPECT_EQ(convex.horizon_clamped, 0u);

  // cos θ_i = cos 45°: the in-plane angle β + 2κw / cos θ_i < 0 for κ < −β cos θ_i / (2w).
  const float kappa = -1.1f * beta * std::sqrt(0.5f) / (2.0f * w);
  const PixelCones concave = OnePixel(kappa, 0.0f, 0.0f).cones();
  EXPECT_EQ(concave.ray_fallbacks, 1u);
  EXPECT_EQ(concave.cones, 0u);
  EXPECT_EQ(concave.angle[0], 0.0f);
  EXPECT_EQ(concave.radius[0], 0.0f);
  EXPECT_EQ(concave.axes.count, 1u);  // still traced, as a ray
}

TEST(PixelCones, GlossyAngleHoldsTheAskedShareOfThePhongLobe) {
  // n = 99: 1 − cos^100 θ_g = E. With E = 0.5: cos θ_g = 0.5^(1/100).
  PixelConeOptions o;
  o.footprint = 0.0f;
  o.lobe_energy = 0.5f;
  const PixelCones g = OnePixel(0.0f, 0.3f, 99.0f).cones(o);
  EXPECT_NEAR(g.angle[0], std::acos(std::pow(0.5f, 0.01f)), 1e-5f);
  EXPECT_EQ(g.radius[0], 0.0f);
  // A fixed gloss angle overrides the material; the far plane follows it.
  o.gloss_angle = 0.05f;
  o.far_blur = 0.5f;
  o.scene_radius = 10.0f;
  const PixelCones f = OnePixel(0.0f, 0.0f, 0.0f).cones(o);
  EXPECT_NEAR(f.angle[0], 0.05f, 1e-7f);
  EXPECT_NEAR(f.far[0], 5.0f / std::tan(0.05f), 1e-2f);
  // Zero footprint and zero gloss: a ray.
  o.gloss_angle = 0.0f;
  const PixelCones r = OnePixel(0.0f, 0.0f, 0.0f).cones(o);
  EXPECT_EQ(r.cones, 0u);
  EXPECT_EQ(r.angle[0], 0.0f);
}

}  // namespace
}  // namespace speculum::trace
