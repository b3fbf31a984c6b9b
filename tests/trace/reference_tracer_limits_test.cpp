// Reference tracer limits: a ray that misses everything
// returns the environment radiance in its direction (constant and equirect), with no light,
// shadow or specular work; and the Whitted depth limit between two facing mirrors: each
// extra bounce adds exactly one more reflected emission term, the specular ray count is
// depth × camera rays, and every path is counted as depth-limited.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "trace/reference_tracer.h"
#include "tests/trace/reference_scenes.h"

namespace speculum::trace {
namespace {

using namespace testing;

TEST(ReferenceTracer, MissReturnsTheEnvironmentRadiance) {
  Scene s;
  const auto grey = add_material(s, glm::vec3(0.8f), 0, 0.9f, glm::vec3(5.0f));
  add_quad(s, {-1, -1, 5}, {1, -1, 5}, {1, 1, 5}, {-1, 1, 5}, grey);  // behind the camera
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = glm::vec3(0, -1, 0);
  sun.intensity = 3;
  s.lights.push_back(sun);  // lights must not reach rays that miss
  Camera cam;
  cam.eye = {0, 0, 0};
  cam.target = {0.3f, 0.2f, -1};
  cam.vfov_degrees = 90;
  ReferenceOptions opt;
  opt.width = 24;
  opt.height = 16;
  opt.spp = 2;
  par::Executor ex(2);

  s.environment.constant = glm::vec3(0.2f, 0.3f, 0.5f);
  s.environment.intensity = 2.0f;
  ReferenceStats st;
  const ImageRGBA flat = render_reference(s, cam, opt, ex, &st);
  for (const glm::vec4& p : flat.pixels) {
    EXPECT_FLOAT_EQ(p.x, 0.4f);
    EXPECT_FLOAT_EQ(p.y, 0.6f);
    EXPECT_FLOAT_EQ(p.z, 1.0f);
  }
  EXPECT_EQ(st.camera_rays, static_cast<std::uint64_t>(opt.width * opt.height * opt.spp));
  EXPECT_EQ(st.shadow_rays, 0u);
  EXPECT_EQ(st.specular_rays, 0u);

  // An equirect environment: each pixel is the environment in its ray's direction.
  ImageRGBA env(16, 8, glm::vec4(0.0f));
  for (int y = 0; y < env.height; ++y)
    for (int x = 0; x < env.width; ++x) env.at(x, y) = glm::vec4(0.1f * x, 0.2f * y, 0.05f * (x ^ y), 1.0f);
  s.environment.equirect = env;
  s.environment.intensity = 1.5f;
  const ImageRGBA img = render_reference(s, cam, opt, ex);
  float lo = 1e30f, hi = -1e30f;
  for (int y = 0; y < opt.height; ++y)
    for (int x = 0; x < opt.width; ++x) {
      const Ray r = primary_ray(cam, opt.width, opt.height, x + 0.5f, y + 0.5f);
      const glm::vec3 e = environment_radiance(s.environment, r.direction);
      const glm::vec4 p = img.at(x, y);
      EXPECT_NEAR(p.x, e.x, 1e-5f * (1 + e.x)) << x << "," << y;
      EXPECT_NEAR(p.y, e.y, 1e-5f * (1 + e.y)) << x << "," << y;
      EXPECT_NEAR(p.z, e.z, 1e-5f * (1 + e.z)) << x << "," << y;
      lo = std::min(lo, p.x + p.y + p.z);
      hi = std::max(hi, p.x + p.y + p.z);
    }
  EXPECT_GT(hi - lo, 0.5f);  // the directions really differ
}

// A glossy plane filling the view under a uniform environment of radiance L: a metal
// returns the specular lobe's albedo E(F0) L (core/brdf.h's table, an independent estimate
// of the integral the tracer samples with visible normals), and a white dielectric returns
// exactly L, its coupled diffuse taking the (1 − E) the specular layer leaves.
TEST(ReferenceTracer, GlossyFurnaceMatchesTheLobeAlbedo) {
  const float L = 0.7f;
  for (float roughness : {0.1f, 0.3f, 0.5f}) {
    for (float metallic : {1.0f, 0.0f}) {
      Scene s;
      const glm::vec3 base = metallic > 0.5f ? glm::vec3(0.9f, 0.6f, 0.3f) : glm::vec3(1.0f);
      const auto m = add_material(s, base, metallic, roughness);
      add_quad(s, {-50, 0, -50}, {-50, 0, 50}, {50, 0, 50}, {50, 0, -50}, m);
      s.environment.constant = glm::vec3(L);
      Camera cam;
      cam.eye = {0, 1, 0};
      cam.target = {0, 0, -1};  // 45° to the plane at the image centre
      cam.vfov_degrees = 10;
      ReferenceOptions opt;
      opt.width = 8;
      opt.height = 8;
      opt.spp = 512;
      par::Executor ex(2);
      const ImageRGBA img = render_reference(s, cam, opt, ex);
      glm::dvec3 sum(0.0);
      for (const glm::vec4& p : img.pixels) sum += glm::dvec3(glm::vec3(p));
      const glm::vec3 mean = glm::vec3(sum / double(img.pixels.size()));
      SurfaceParams sp = surface_params(s.materials[m]);
      const float cos_nv = std::cos(kPi / 4.0f);
      const glm::vec3 expected =
          metallic > 0.5f ? specular_reflectance(sp, cos_nv) * L : glm::vec3(L);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(mean[c], expected[c], 0.02f * expected[c])
            << "roughness " << roughness << " metallic " << metallic << " channel " << c;
    }
  }
}

// The white furnace of environment lighting: a white dielectric sphere of any roughness
// under a uniform environment of radiance L returns L at every pixel — its coupled diffuse
// lobe (occluded, cosine-sampled) and its specular lobe (traced when glossy, environment-
// sampled when rough) share exactly what arrives (core/brdf.h, core/shading.h).
TEST(ReferenceTracer, WhiteSphereInAUniformEnvironmentReturnsItsRadiance) {
  const float L = 0.6f;
  for (float roughness : {1.0f, 0.7f, 0.3f}) {
    Scene s;
    const auto m = add_material(s, glm::vec3(1.0f), 0.0f, roughness);
    add_sphere(s, glm::vec3(0.0f), 1.0f, 96, 192, m);
    s.environment.constant = glm::vec3(L);
    Camera cam;
    cam.eye = {0, 0, 4};
    cam.target = {0, 0, 0};
    cam.vfov_degrees = 14;  // the sphere (half-angle 14.5°) covers the whole 8×8 image
    ReferenceOptions opt;
    opt.width = 8;
    opt.height = 8;
    opt.spp = 1024;
    par::Executor ex(2);
    const ImageRGBA img = render_reference(s, cam, opt, ex);
    double sum = 0.0;
    for (const glm::vec4& p : img.pixels) {
      EXPECT_NEAR(p.x, L, 0.06f * L) << "roughness " << roughness;
      sum += p.x;
    }
    EXPECT_NEAR(sum / double(img.pixels.size()), L, 0.015 * L) << "roughness " << roughness;
  }
}

TEST(ReferenceTracer, DepthLimitBetweenFacingMirrors) {
  // Two facing emissive mirrors (z = -1 and z = 1), the camera between them looking down
  // -z with a narrow view: every camera ray bounces between them until the depth limit.
  Scene s;
  const glm::vec3 e(0.1f, 0.2f, 0.3f);
  const auto mirror = add_material(s, glm::vec3(0.5f), 1, 0, e);
  add_quad(s, {-50, -50, -1}, {50, -50, -1}, {50, 50, -1}, {-50, 50, -1}, mirror);
  add_quad(s, {-50, -50, 1}, {-50, 50, 1}, {50, 50, 1}, {50, -50, 1}, mirror);
  s.environment.constant = glm::vec3(7.0f);  // never seen: the corridor is closed to it
  Camera cam;
  cam.eye = {0, 0, 0};
  cam.target = {0, 0, -1};
  cam.vfov_degrees = 4;
  ReferenceOptions opt;
  opt.width = opt.height = 9;
  opt.spp = 1;
  opt.environment_lighting = false;
  par::Executor ex(2);
  const std::uint64_t n = 81;
  // At normal incidence each bounce scales by F = F(cos 1): L_D = e · Σ_{k=0..D} F^k.
  const glm::vec3 F = specular_reflectance(surface_params(s.materials[mirror]), 1.0f);
  ASSERT_GT(F.x, 0.1f);
  ASSERT_LT(F.x, 0.9f);
  glm::vec3 expected(0.0f), Fk(1.0f), previous(-1.0f);
  for (int depth = 0; depth <= 6; ++depth) {
    expected += e * Fk;
    Fk *= F;
    opt.max_depth = depth;
    ReferenceStats st;
    const ImageRGBA img = render_reference(s, cam, opt, ex, &st);
    SCOPED_TRACE("max_depth " + std::to_string(depth));
    EXPECT_EQ(st.camera_rays, n);
    EXPECT_EQ(st.specular_rays, n * static_cast<std::uint64_t>(depth));
    EXPECT_EQ(st.depth_limited, n);  // every path was cut, once
    EXPECT_EQ(st.shadow_rays, 0u);
    const glm::vec4 c = img.at(4, 4);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], expected[k], 1e-4f * expected[k]);
    EXPECT_GT(c.x, previous.x);  // one more bounce, more light
    previous = glm::vec3(c);
    for (const glm::vec4& p : img.pixels) EXPECT_NEAR(p.x, c.x, 1e-3f * c.x);  // narrow view: ~normal incidence
  }
}

}  // namespace
}  // namespace speculum::trace
