// The distributions of the benchmark ray sets (`--emit-rays`, trace/ray_generation.h),
// with fixed seeds: reflect-cone30 directions uniform in solid angle within the 30° cone
// about the mirror direction, hemisphere directions cosine-weighted about the geometric
// normal, both with uniform azimuth; secondary origins offset along the normal on the
// incident side (so rays leaving a convex closed mesh never hit it again).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "core/optics.h"
#include "trace/ray_generation.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

// Pearson's chi-square of counts against a uniform histogram.
double chi_square_uniform(const std::vector<int>& counts) {
  double n = 0;
  for (int c : counts) n += c;
  const double e = n / static_cast<double>(counts.size());
  double x2 = 0;
  for (int c : counts) x2 += (c - e) * (c - e) / e;
  return x2;
}
// 99.99th percentile of chi-square with 9 degrees of freedom (10 bins): a correct sampler
// fails with probability 1e-4 for a given seed, and the seeds are fixed.
constexpr double kChi2_9dof = 33.7;

int bin10(double x) { return std::clamp(static_cast<int>(x * 10.0), 0, 9); }

// Azimuth of unit d about unit axis a in [0, 1), in a frame independent of the generator's
// (uniformity of the azimuth does not depend on the frame).
double azimuth01(const glm::vec3& d, const glm::vec3& a) {
  const glm::vec3 helper = std::fabs(a.x) < 0.6f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 t = glm::normalize(glm::cross(a, helper)), b = glm::cross(a, t);
  const double phi = std::atan2(static_cast<double>(glm::dot(d, b)), static_cast<double>(glm::dot(d, t)));
  return (phi + kPi) / (2.0 * kPi);
}

struct Samples {
  std::vector<float> cone_cos, hemi_cos;   // cos to the mirror direction / to the normal
  std::vector<float> cone_az, hemi_az;
  int below = 0, sideways = 0, rehits = 0, grazing = 0;
  std::size_t n = 0;
};

Samples collect(std::uint32_t seed) {
  // A closed, convex, finely tessellated sphere filling much of a 128² view.
  const testing::Soup s = testing::uv_sphere(48, 96, glm::vec3(0.1f, -0.2f, 0.05f), 1.0f);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  Camera cam;
  cam.eye = {0.3f, 0.5f, 3.5f};
  cam.target = {0.1f, -0.2f, 0.05f};
  cam.vfov_degrees = 40;
  const int w = 128, h = 128;
  const RayStream primary = generate_rays(RaySetKind::Primary, bvh, cam, w, h, seed, ex);
  const RayStream cone = generate_rays(RaySetKind::ReflectCone30, bvh, cam, w, h, seed, ex);
  const RayStream hemi = generate_rays(RaySetKind::Hemisphere, bvh, cam, w, h, seed, ex);
  Samples out;
  std::size_t k = 0;
  for (std::size_t i = 0; i < primary.size(); ++i) {
    const Ray p = primary.get(i);
    const Hit hit = closest_hit(bvh, p);
    if (!hit.hit()) continue;
    if (k >= cone.size() || k >= hemi.size()) break;
    const glm::vec3 a = s.positions[s.indices[3 * hit.triangle]], b = s.positions[s.indices[3 * hit.triangle + 1]],
                    c = s.positions[s.indices[3 * hit.triangle + 2]];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::vec3 d = glm::normalize(p.direction);
    if (glm::dot(n, d) > 0) n = -n;  // the incident side
    const glm::vec3 mirror = glm::normalize(reflect(d, n));
    const glm::vec3 x = p.origin + hit.t * p.direction;
    const Ray rc = cone.get(k), rh = hemi.get(k);
    ++k;
    for (const Ray& r : {rc, rh}) {
      const glm::vec3 off = r.origin - x;
      if (!(glm::dot(off, n) > 0.0f)) ++out.below;
      // Along the normal: the lateral part is float noise, far below the offset.
      if (glm::length(off - glm::dot(off, n) * n) > 0.1f * glm::dot(off, n)) ++out.sideways;
      // Leaving a convex closed mesh from its outer side never hits it again (tmin = 0).
      const glm::vec3 dir = glm::normalize(r.direction);
      if (glm::dot(dir, n) > 1e-3f) {
        if (closest_hit(bvh, r).hit()) ++out.rehits;
      } else {
        ++out.grazing;
      }
    }
    const glm::vec3 dc = glm::normalize(rc.direction), dh = glm::normalize(rh.direction);
    out.cone_cos.push_back(glm::dot(dc, mirror));
    out.cone_az.push_back(static_cast<float>(azimuth01(dc, mirror)));
    out.hemi_cos.push_back(glm::dot(dh, n));
    out.hemi_az.push_back(static_cast<float>(azimuth01(dh, n)));
  }
  EXPECT_EQ(k, cone.size());
  EXPECT_EQ(k, hemi.size());
  out.n = k;
  return out;
}

TEST(RayGeneration, ReflectCone30IsUniformInSolidAngleWithinTheCone) {
  const Samples smp = collect(7);
  ASSERT_GT(smp.n, 4000u);
  const double c30 = std::cos(30.0 * kPi / 180.0);
  double mean = 0, max_angle_cos = 1;
  std::vector<int> polar(10, 0), az(10, 0);
  for (std::size_t i = 0; i < smp.n; ++i) {
    const double cs = smp.cone_cos[i];
    mean += cs;
    max_angle_cos = std::min(max_angle_cos, cs);
    // Uniform in solid angle within the cone: cos uniform on [cos30, 1].
    ++polar[bin10((1.0 - cs) / (1.0 - c30))];
    ++az[bin10(smp.cone_az[i])];
  }
  mean /= static_cast<double>(smp.n);
  // Mean of cos for uniform-in-solid-angle: (1 + cos30)/2 (0.9330); uniform-in-angle would
  // give sin30/(π/6) = 0.9549. Tolerance: 5 standard errors (std of cos = (1-cos30)/√12).
  const double tol = 5.0 * (1.0 - c30) / std::sqrt(12.0 * static_cast<double>(smp.n));
  EXPECT_NEAR(mean, 0.5 * (1.0 + c30), tol);
  EXPECT_GT(max_angle_cos, c30 - 1e-4);  // nothing outside the cone
  EXPECT_LT(max_angle_cos, c30 + 0.01);  // and the whole cone is used
  EXPECT_LT(chi_square_uniform(polar), kChi2_9dof);
  EXPECT_LT(chi_square_uniform(az), kChi2_9dof);
}

TEST(RayGeneration, HemisphereIsCosineWeightedAboutTheNormal) {
  const Samples smp = collect(7);
  ASSERT_GT(smp.n, 4000u);
  double mean = 0;
  std::vector<int> polar(10, 0), az(10, 0);
  for (std::size_t i = 0; i < smp.n; ++i) {
    const double cs = smp.hemi_cos[i];
    mean += cs;
    // Cosine-weighted: cos²θ uniform on [0, 1].
    ++polar[bin10(cs * cs)];
    ++az[bin10(smp.hemi_az[i])];
  }
  mean /= static_cast<double>(smp.n);
  // E[cosθ] = 2/3 (uniform hemisphere: 1/2); std of cosθ = √(1/2 - 4/9) = √(1/18).
  EXPECT_NEAR(mean, 2.0 / 3.0, 5.0 * std::sqrt(1.0 / 18.0 / static_cast<double>(smp.n)));
  EXPECT_LT(chi_square_uniform(polar), kChi2_9dof);
  EXPECT_LT(chi_square_uniform(az), kChi2_9dof);
}

TEST(RayGeneration, SecondaryOriginsAreOffsetAlongTheNormalOnTheIncidentSide) {
  const Samples smp = collect(7);
  ASSERT_GT(smp.n, 4000u);
  EXPECT_EQ(smp.below, 0) << "origins on or behind the surface";
  EXPECT_EQ(smp.sideways, 0) << "origins offset off the normal";
  EXPECT_EQ(smp.rehits, 0) << "rays leaving the convex sphere hit it again";
  EXPECT_LT(smp.grazing, static_cast<int>(smp.n) / 2);  // the re-hit check covered most rays
}

TEST(RayGeneration, SeedChangesTheSecondaryDirections) {
  const Samples a = collect(7), b = collect(8);
  ASSERT_EQ(a.n, b.n);
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.n; ++i) same += a.cone_cos[i] == b.cone_cos[i] && a.cone_az[i] == b.cone_az[i];
  EXPECT_LT(same, a.n / 100);
}

}  // namespace
}  // namespace speculum::trace
