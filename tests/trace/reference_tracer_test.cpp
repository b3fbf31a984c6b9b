// Reference tracer tests: a mirror sphere against the analytic reflection of a
// checker plane, a glass slab's lateral shift, a prism's total internal reflection,
// bit-identical images for 1, 2 and 8 threads, and error falling like 1/sqrt(spp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/camera_rays.h"
#include "core/sampling.h"
#include "trace/reference_tracer.h"
#include "tests/trace/reference_scenes.h"

namespace speculum::trace {
namespace {

using namespace testing;

// Emissive checker of unit squares on the plane y = h over [-n, n]^2.
void add_checker(Scene& s, float h, int n, std::uint32_t white, std::uint32_t black) {
  for (int i = -n; i < n; ++i)
    for (int k = -n; k < n; ++k)
      add_quad(s, {float(i), h, float(k)}, {float(i), h, float(k + 1)}, {float(i + 1), h, float(k + 1)},
               {float(i + 1), h, float(k)}, ((i + k) & 1) ? black : white);
}

TEST(ReferenceTracer, MirrorSphereMatchesAnalyticReflection) {
  Scene s;
  const auto white = add_material(s, glm::vec3(0), 0, 1, glm::vec3(1));
  const auto black = add_material(s, glm::vec3(0), 0, 1, glm::vec3(0));
  const auto mirror = add_material(s, glm::vec3(1), 1, 0);  // F0 = 1: F = 1 at every angle
  add_checker(s, -2.0f, 12, white, black);
  add_sphere(s, glm::vec3(0), 1.0f, 96, 192, mirror);
  Camera cam;
  cam.eye = glm::vec3(0.5f, 1.0f, 4.0f);
  cam.target = glm::vec3(0, -0.3f, 0);
  cam.vfov_degrees = 30;
  ReferenceOptions opt;
  opt.width = opt.height = 96;
  opt.spp = 1;
  opt.environment_lighting = false;
  par::Executor ex(2);
  const ImageRGBA img = render_reference(s, cam, opt, ex);
  int compared = 0, wrong = 0;
  for (int y = 0; y < opt.height; ++y)
    for (int x = 0; x < opt.width; ++x) {
      const Ray r = primary_ray(cam, opt.width, opt.height, x + 0.5f, y + 0.5f);
      // Analytic sphere hit; skip the silhouette, where the tessellation differs.
      const float b = glm::dot(r.origin, r.direction), c = glm::dot(r.origin, r.origin) - 1.0f;
      const float disc = b * b - c;
      if (disc < 0.02f) continue;
      const float t = -b - std::sqrt(disc);
      const glm::vec3 p = r.origin + t * r.direction, n = glm::normalize(p);
      const glm::vec3 refl = r.direction - 2 * glm::dot(r.direction, n) * n;
      float expected = 0.0f;
      if (refl.y < 0) {
        const float tp = (-2.0f - p.y) / refl.y;
        const glm::vec3 q = p + tp * refl;
        if (std::fabs(q.x) >= 12 || std::fabs(q.z) >= 12) continue;
        const float fx = q.x - std::floor(q.x), fz = q.z - std::floor(q.z);
        const float edge = std::min({fx, 1 - fx, fz, 1 - fz});
        if (edge < 0.05f * tp) continue;  // near a checker edge: normal interpolation may flip it
        expected = ((static_cast<int>(std::floor(q.x)) + static_cast<int>(std::floor(q.z))) & 1) ? 0.0f : 1.0f;
      }
      ++compared;
      if (std::fabs(img.at(x, y).x - expected) > 0.02f) ++wrong;
    }
  EXPECT_GT(compared, 1500);
  EXPECT_LE(wrong, compared / 200) << wrong << " of " << compared;
}

// Edge position (count of bright pixels) along the middle row.
int bright_count(const ImageRGBA& img) {
  int n = 0;
  for (int x = 0; x < img.width; ++x) n += img.at(x, img.height / 2).x > 0.3f;
  return n;
}

TEST(ReferenceTracer, GlassSlabShiftsRaysLaterally) {
  const float theta_i = glm::radians(40.0f), thickness = 1.0f, ior = 1.5f;
  auto scene = [&](bool with_slab) {
    Scene s;
    const auto light = add_material(s, glm::vec3(0), 0, 1, glm::vec3(1));
    const auto dark = add_material(s, glm::vec3(0), 0, 1, glm::vec3(0));
    const auto glass = add_material(s, glm::vec3(1), 0, 0, {}, 1.0f, ior);
    add_quad(s, {-50, -50, -2}, {0, -50, -2}, {0, 50, -2}, {-50, 50, -2}, light);  // x < 0 bright
    add_quad(s, {0, -50, -2}, {50, -50, -2}, {50, 50, -2}, {0, 50, -2}, dark);
    if (with_slab) add_box(s, {-40, -40, -thickness * 0.5f}, {40, 40, thickness * 0.5f}, glass);
    return s;
  };
  Camera cam;
  const float D = 2000.0f;
  cam.target = glm::vec3(0, 0, -2.0f);  // the edge, seen straight without the slab
  cam.eye = cam.target + D * glm::vec3(std::sin(theta_i), 0, std::cos(theta_i));
  cam.vfov_degrees = 0.001f;  // a nearly parallel fan of rays, 400 x 8 square pixels
  cam.znear = 1.0f;
  cam.zfar = 1e5f;
  ReferenceOptions opt;
  opt.width = 400;
  opt.height = 8;
  opt.spp = 1;
  opt.environment_lighting = false;
  par::Executor ex(2);
  const int without = bright_count(render_reference(scene(false), cam, opt, ex));
  const ImageRGBA with_img = render_reference(scene(true), cam, opt, ex);
  const int with = bright_count(with_img);
  const float pixel = 2.0f * D * std::tan(glm::radians(cam.vfov_degrees) * 0.5f) / opt.height;
  const float theta_t = std::asin(std::sin(theta_i) / ior);
  const float expected = thickness * std::sin(theta_i - theta_t) / std::cos(theta_t);  // SURVEY §4.4 check
  EXPECT_NEAR(std::abs(with - without) * pixel, expected, 2.0f * pixel) << with << " vs " << without;
  EXPECT_GT(std::abs(with - without), 40);  // the shift is well resolved
}

TEST(ReferenceTracer, PrismTotalInternalReflection) {
  auto render_centre = [](float ior) {
    Scene s;
    const auto red = add_material(s, glm::vec3(0), 0, 1, glm::vec3(1, 0, 0));
    const auto green = add_material(s, glm::vec3(0), 0, 1, glm::vec3(0, 1, 0));
    const auto glass = add_material(s, glm::vec3(1), 0, 0, {}, 1.0f, ior);
    // Right prism: cross-section A(0,0) B(1,0) C(0,1) in xz, extruded over y in [-1, 1].
    const glm::vec3 A0(0, -1, 0), B0(1, -1, 0), C0(0, -1, 1), A1(0, 1, 0), B1(1, 1, 0), C1(0, 1, 1);
    // Wound outward: a refractor's geometric normal tells entering from leaving.
    add_tri(s, B0, C0, A0, glass);
    add_tri(s, C1, B1, A1, glass);
    add_quad(s, A1, B1, B0, A0, glass);
    add_quad(s, B1, C1, C0, B0, glass);
    add_quad(s, C1, A1, A0, C0, glass);
    add_quad(s, {-5, -5, -3}, {5, -5, -3}, {5, 5, -3}, {-5, 5, -3}, red);   // where TIR sends it
    add_quad(s, {3, -5, -2}, {3, 5, -2}, {3, 5, 5}, {3, -5, 5}, green);      // straight through
    Camera cam;
    cam.eye = glm::vec3(-5, 0, 0.3f);
    cam.target = glm::vec3(0, 0, 0.3f);
    cam.vfov_degrees = 1.0f;
    ReferenceOptions opt;
    opt.width = opt.height = 8;
    opt.spp = 1;
    opt.environment_lighting = false;
    par::Executor ex(1);
    return glm::vec3(render_reference(s, cam, opt, ex).at(4, 4));
  };
  const glm::vec3 tir = render_centre(1.5f);  // 45° > critical 41.8°: all reflected
  EXPECT_NEAR(tir.x, 0.96f * 0.96f, 0.01f);   // two normal-incidence Fresnel losses only
  EXPECT_LT(tir.y, 0.01f);
  const glm::vec3 through = render_centre(1.2f);  // critical 56.4°: mostly transmitted
  EXPECT_GT(through.y, 0.5f);
  EXPECT_LT(through.x, 0.3f);
}

Scene mixed_scene() {
  Scene s;
  const auto floor = add_material(s, glm::vec3(0.7f), 0, 0.9f);
  const auto glossy = add_material(s, glm::vec3(0.9f, 0.8f, 0.6f), 1, 0.3f);
  const auto mirror = add_material(s, glm::vec3(0.95f), 1, 0.0f);
  const auto glass = add_material(s, glm::vec3(1), 0, 0, {}, 1.0f, 1.5f);
  const auto lamp = add_material(s, glm::vec3(0), 0, 1, glm::vec3(4, 3, 2));
  const auto white = add_material(s, glm::vec3(0), 0, 1, glm::vec3(1));
  const auto black = add_material(s, glm::vec3(0), 0, 1, glm::vec3(0.05f));
  add_quad(s, {-4, -1, -4}, {-4, -1, 4}, {4, -1, 4}, {4, -1, -4}, floor);
  add_checker(s, -1.01f, 0, white, black);
  add_sphere(s, {-1.2f, 0, 0}, 0.8f, 16, 32, glossy);
  add_sphere(s, {1.2f, 0, 0}, 0.8f, 16, 32, mirror);
  add_box(s, {-0.4f, -1, 0.8f}, {0.4f, 0.2f, 1.4f}, glass);
  add_quad(s, {-1, 3, -1}, {1, 3, -1}, {1, 3, 1}, {-1, 3, 1}, lamp);
  Light l;
  l.type = LightType::Point;
  l.position = {2, 4, 3};
  l.intensity = 30;
  s.lights.push_back(l);
  Light d;
  d.type = LightType::Directional;
  d.direction = glm::normalize(glm::vec3(-1, -2, -1));
  d.intensity = 1.5f;
  s.lights.push_back(d);
  s.environment.constant = glm::vec3(0.2f, 0.3f, 0.5f);
  return s;
}

TEST(ReferenceTracer, BitIdenticalForAnyThreadCount) {
  const Scene s = mixed_scene();
  Camera cam;
  cam.eye = {0, 1.5f, 6};
  cam.target = {0, 0, 0};
  ReferenceOptions opt;
  opt.width = 64;
  opt.height = 48;
  opt.spp = 4;
  opt.pixel_jitter = true;
  std::vector<ImageRGBA> images;
  for (int threads : {1, 2, 8}) {
    par::Executor ex(threads);
    images.push_back(render_reference(s, cam, opt, ex));
  }
  for (int k = 1; k < 3; ++k)
    EXPECT_EQ(0, std::memcmp(images[0].pixels.data(), images[k].pixels.data(), images[0].size() * sizeof(glm::vec4)));
  double sum = 0;
  for (const auto& p : images[0].pixels) sum += p.x + p.y + p.z;
  EXPECT_GT(sum, 0.0);  // not an empty image
}

TEST(ReferenceTracer, ErrorFallsLikeInverseSqrtSpp) {
  const Scene s = mixed_scene();
  Camera cam;
  cam.eye = {-1.2f, 0.5f, 3};  // fill the view with the glossy sphere
  cam.target = {-1.2f, 0, 0};
  cam.vfov_degrees = 20;
  ReferenceOptions opt;
  opt.width = opt.height = 16;
  opt.environment_lighting = true;
  par::Executor ex(2);
  opt.spp = 2048;
  opt.seed = 99;
  const ImageRGBA truth = render_reference(s, cam, opt, ex);
  auto rmse = [&](int spp) {
    double e = 0;
    int runs = 0;
    for (std::uint32_t seed = 1; seed <= 4; ++seed, ++runs) {
      opt.spp = spp;
      opt.seed = seed;
      const ImageRGBA img = render_reference(s, cam, opt, ex);
      for (std::size_t i = 0; i < img.size(); ++i) {
        const glm::vec3 d = glm::vec3(img.pixels[i] - truth.pixels[i]);
        e += glm::dot(d, d);
      }
    }
    return std::sqrt(e / (runs * truth.size()));
  };
  const double e4 = rmse(4), e16 = rmse(16), e64 = rmse(64);
  EXPECT_GT(e4, 1e-3);  // the case is noisy at all
  EXPECT_NEAR(e4 / e16, 2.0, 0.5) << e4 << " " << e16;
  EXPECT_NEAR(e16 / e64, 2.0, 0.5) << e16 << " " << e64;
}

}  // namespace
}  // namespace speculum::trace
