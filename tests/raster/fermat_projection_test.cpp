// The 2-D secant search for the Fermat point of a star-shaped reflector (ROGER §2.2.3):
// against the analytic reflection point of a sphere (a 1-D minimization on the arc AB,
// ROGER Fig.2.10) and a brute-force minimizer of |EP| + |PV| over an ellipsoid's parameter
// grid refined by Newton, plus the iteration counts ROGER §2.3.2 reports.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "raster/fermat_projection.h"

namespace speculum::raster {
namespace {


struct Ellipsoid {
  glm::dvec3 centre{0.0};
  glm::dvec3 radii{1.0};
  ReflectorSample operator()(const glm::dvec3& u) const {
    const glm::dvec3 q = u / radii;
    const double r = 1.0 / std::sqrt(glm::dot(q, q));
    ReflectorSample s;
    s.valid = true;
    s.point = centre + r * u;
    s.normal = glm::normalize((s.point - centre) / (radii * radii));
    return s;
  }
  glm::dvec3 at(double theta, double phi) const {
    return centre + radii * glm::dvec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
  }
};

// A projection so fine (1e-7 units per pixel) that the pixel stop is below the test bound.
glm::dvec2 fine(const glm::dvec3& p) { return glm::dvec2(p.x + 0.37 * p.z, p.y - 0.21 * p.z) * 1e7; }

FermatSettings tight() {
  FermatSettings s;
  s.max_iterations = 32;
  s.residual = 1e-8;
  return s;
}

double path(const glm::dvec3& e, const glm::dvec3& p, const glm::dvec3& v) {
  return glm::length(p - e) + glm::length(v - p);
}

// Sphere: the reflection point lies on the great arc from A (towards V) to B (towards E);
// golden-section search of ℓ along it.
glm::dvec3 sphere_reflection(const glm::dvec3& o, double r, const glm::dvec3& e, const glm::dvec3& v) {
  const glm::dvec3 a = glm::normalize(v - o), b = glm::normalize(e - o);
  const double angle = std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0));
  const glm::dvec3 w = glm::normalize(b - a * glm::dot(a, b));
  auto at = [&](double t) { return o + r * (std::cos(t) * a + std::sin(t) * w); };
  double lo = 0.0, hi = angle;
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  for (int i = 0; i < 200; ++i) {
    const double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo);
    if (path(e, at(m1), v) < path(e, at(m2), v)) hi = m2;
    else lo = m1;
  }
  return at(0.5 * (lo + hi));
}

TEST(FermatProjection, SphereMatchesTheAnalyticReflectionPoint) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const glm::dvec3 o(0.3, 1.5, -0.2);
  const double r = 1.5;
  Ellipsoid sphere{o, glm::dvec3(r)};
  auto outside = [&](double lo, double hi) {
    for (;;) {
      const glm::dvec3 d{uni(rng), uni(rng), uni(rng)};
      const double l = glm::length(d);
      if (l < 0.1 || l > 1.0) continue;
      return o + d / l * (lo + (hi - lo) * std::fabs(uni(rng)));
    }
  };
  int tested = 0;
  double worst = 0.0;
  for (int i = 0; i < 400; ++i) {
    const glm::dvec3 e = outside(2.0 * r, 5.0 * r), v = outside(1.05 * r, 4.0 * r);
    // Only pairs that see each other over the sphere have a reflection (E and V on the
    // same side of the tangent plane at P).
    const glm::dvec3 want = sphere_reflection(o, r, e, v);
    const glm::dvec3 n = (want - o) / r;
    if (glm::dot(e - want, n) <= 0.0 || glm::dot(v - want, n) <= 0.0) continue;
    const FermatResult got = fermat_project(sphere, o, e, v, fine, tight());
    ASSERT_EQ(got.status, ProjectionStatus::Converged) << i;
    EXPECT_EQ(got.extremum, PathExtremum::Minimum);
    worst = std::max(worst, glm::length(got.point - want) / r);
    ++tested;
  }
  EXPECT_GT(tested, 150);
  EXPECT_LT(worst, 1e-4);
}

// Newton on (θ, φ) with central differences, from the best point of a fine grid.
glm::dvec3 ellipsoid_reflection(const Ellipsoid& el, const glm::dvec3& e, const glm::dvec3& v) {
  auto f = [&](double t, double p) { return path(e, el.at(t, p), v); };
  double bt = 0.0, bp = 0.0, best = 1e300;
  const int n = 400;
  for (int i = 1; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double t = std::numbers::pi * i / n, p = std::numbers::pi * j / n;
      const glm::dvec3 x = el.at(t, p);
      const glm::dvec3 nn = glm::normalize((x - el.centre) / (el.radii * el.radii));
      if (glm::dot(e - x, nn) <= 0.0 || glm::dot(v - x, nn) <= 0.0) continue;
      const double l = f(t, p);
      if (l < best) best = l, bt = t, bp = p;
    }
  const double h = 1e-5;
  for (int k = 0; k < 30; ++k) {
    const double ft = (f(bt + h, bp) - f(bt - h, bp)) / (2 * h), fp = (f(bt, bp + h) - f(bt, bp - h)) / (2 * h);
    const double ftt = (f(bt + h, bp) - 2 * f(bt, bp) + f(bt - h, bp)) / (h * h);
    const double fpp = (f(bt, bp + h) - 2 * f(bt, bp) + f(bt, bp - h)) / (h * h);
    const double ftp = (f(bt + h, bp + h) - f(bt + h, bp - h) - f(bt - h, bp + h) + f(bt - h, bp - h)) / (4 * h * h);
    const double det = ftt * fpp - ftp * ftp;
    if (!(std::fabs(det) > 0.0)) break;
    bt -= (fpp * ft - ftp * fp) / det;
    bp -= (ftt * fp - ftp * ft) / det;
  }
  return el.at(bt, bp);
}

TEST(FermatProjection, EllipsoidMatchesABruteForceMinimizer) {
  const Ellipsoid el{glm::dvec3(0.0, 1.2, 0.0), glm::dvec3(1.6, 1.0, 0.7)};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  int tested = 0;
  double worst = 0.0;
  for (int i = 0; i < 60 && tested < 25; ++i) {
    const glm::dvec3 e = el.centre + glm::dvec3{uni(rng) * 2.0, 1.5 + uni(rng), 4.0 + uni(rng)};
    const glm::dvec3 v = el.centre + glm::normalize(glm::dvec3{uni(rng), uni(rng), uni(rng) + 0.8}) * 2.5;
    const glm::dvec3 want = ellipsoid_reflection(el, e, v);
    const FermatResult got = fermat_project(el, el.centre, e, v, fine, tight());
    if (got.status == ProjectionStatus::Hidden) continue;
    ASSERT_EQ(got.status, ProjectionStatus::Converged) << i;
    worst = std::max(worst, glm::length(got.point - want));
    ++tested;
  }
  EXPECT_GE(tested, 20);
  EXPECT_LT(worst, 1e-4 * 0.7);  // the smallest radius
}

TEST(FermatProjection, IterationsAreFewAtTheCentreAndBoundedAtTheSilhouette) {
  // A camera 640 pixels wide looking at a unit sphere; scene vertices on a sphere of radius
  // 4 around it. Zones by the angle of incidence at P: centre under 15°, silhouette over
  // 75° (measured here: centre median 4, silhouette median 8, max 18; the median over
  // incidence under 30° is 5 — three replacements are the least the longest-edge stop
  // allows, and the first secant step over a triangle spanning ~1 rad is rarely a pixel off).
  const glm::dvec3 o(0.0), eye(0.0, 0.5, 5.0);
  Ellipsoid sphere{o, glm::dvec3(1.0)};
  const glm::dmat4 vp = glm::perspective(glm::radians(45.0), 4.0 / 3.0, 0.1, 100.0) *
                        glm::lookAt(eye, o, glm::dvec3(0, 1, 0));
  auto project = [&](const glm::dvec3& p) {
    const glm::dvec4 c = vp * glm::dvec4(p, 1.0);
    return glm::dvec2((c.x / c.w * 0.5 + 0.5) * 640.0, (c.y / c.w * 0.5 + 0.5) * 480.0);
  };
  std::vector<int> centre, silhouette;
  const int n = 60;
  for (int i = 1; i < n; ++i)
    for (int j = 0; j < 2 * n; ++j) {
      const double t = std::numbers::pi * i / n, p = std::numbers::pi * j / n;
      const glm::dvec3 v = 4.0 * glm::dvec3(std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p));
      const FermatResult r = fermat_project(sphere, o, eye, v, project, FermatSettings{});
      if (r.status != ProjectionStatus::Converged) continue;
      const double c = glm::dot(r.normal, glm::normalize(eye - r.point));
      if (c > std::cos(std::numbers::pi / 12)) centre.push_back(r.iterations);
      else if (c < std::cos(std::numbers::pi * 75 / 180)) silhouette.push_back(r.iterations);
    }
  ASSERT_GT(centre.size(), 50u);
  ASSERT_GT(silhouette.size(), 50u);
  std::sort(centre.begin(), centre.end());
  std::sort(silhouette.begin(), silhouette.end());
  EXPECT_LT(centre[centre.size() / 2], 5);
  EXPECT_LE(silhouette.back(), 20);
}

TEST(FermatProjection, ConcaveBowlZones) {
  // Inside a spherical mirror of radius 2 (normals towards the centre), the eye above the
  // centre: V near the bottom is a minimum of ℓ (near zone), V far above the rim beyond the
  // centre a maximum (far zone), V near the centre-eye line between them a saddle.
  const glm::dvec3 o(0.0);
  Ellipsoid inner{o, glm::dvec3(2.0)};
  auto bowl = [&](const glm::dvec3& u) {
    ReflectorSample s = inner(u);
    s.valid = u.y < -0.25;  // a cap below the centre
    s.normal = -s.normal;
    return s;
  };
  const glm::dvec3 eye(0.1, 0.6, 0.0);
  const FermatResult near = fermat_project(bowl, o, eye, glm::dvec3(0.3, -1.7, 0.1), fine, tight());
  EXPECT_EQ(near.status, ProjectionStatus::Converged);
  EXPECT_EQ(near.extremum, PathExtremum::Minimum);
  const FermatResult far = fermat_project(bowl, o, eye, glm::dvec3(-0.2, 1.9, 0.3), fine, tight());
  EXPECT_EQ(far.status, ProjectionStatus::Converged);
  EXPECT_EQ(far.extremum, PathExtremum::Maximum);
  // The small starting triangle the renderer uses on concave reflectors finds the same points.
  FermatSettings small = tight();
  small.max_start_side = 0.1;
  const FermatResult near_small = fermat_project(bowl, o, eye, glm::dvec3(0.3, -1.7, 0.1), fine, small);
  EXPECT_EQ(near_small.extremum, PathExtremum::Minimum);
  EXPECT_LT(glm::length(near_small.point - near.point), 1e-6);
  const FermatResult far_small = fermat_project(bowl, o, eye, glm::dvec3(-0.2, 1.9, 0.3), fine, small);
  EXPECT_EQ(far_small.extremum, PathExtremum::Maximum);
  EXPECT_LT(glm::length(far_small.point - far.point), 1e-6);
}

}  // namespace
}  // namespace speculum::raster
