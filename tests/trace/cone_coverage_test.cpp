// Tests of the cone–triangle intersection (ROGER §5.2.5): the exact area and centroid of
// triangle ∩ unit disc against a clipping of the triangle by a 1024-gon for thousands of
// random triangles covering all 8 cases of Fig.5.8, a circular segment against its closed
// form away from θ = π, and abutting triangles covering a cone summing to coverage 1.
#include "trace/cone_coverage.h"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

namespace speculum::trace {
namespace {


struct Moments {
  double area = 0.0;
  glm::dvec2 centroid{0.0};
};

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// The triangle clipped by the N-gon whose area equals the unit disc's (radius
// sqrt(2π / (N sin(2π/N)))), by Sutherland–Hodgman: an independent, high-resolution oracle.
Moments polygon_clip_oracle(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c, int sides = 1024) {
  if (cross2(b - a, c - a) < 0.0) std::swap(b, c);
  std::vector<glm::dvec2> poly = {a, b, c};
  const double r = std::sqrt(2.0 * std::numbers::pi / (sides * std::sin(2.0 * std::numbers::pi / sides)));
  for (int k = 0; k < sides && !poly.empty(); ++k) {
    const double a0 = 2.0 * std::numbers::pi * k / sides, a1 = 2.0 * std::numbers::pi * (k + 1) / sides;
    const glm::dvec2 p0(r * std::cos(a0), r * std::sin(a0)), p1(r * std::cos(a1), r * std::sin(a1));
    std::vector<glm::dvec2> next;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const glm::dvec2 s = poly[i], e = poly[(i + 1) % poly.size()];
      const double ds = cross2(p1 - p0, s - p0), de = cross2(p1 - p0, e - p0);
      if (ds >= 0.0) next.push_back(s);
      if ((ds >= 0.0) != (de >= 0.0)) next.push_back(s + (ds / (ds - de)) * (e - s));
    }
    poly = std::move(next);
  }
  Moments m;
  glm::dvec2 moment(0.0);
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const glm::dvec2 u = poly[i], v = poly[(i + 1) % poly.size()];
    const double w = cross2(u, v);
    m.area += 0.5 * w;
    moment += (w / 6.0) * (u + v);
  }
  if (m.area > 0.0) m.centroid = moment / m.area;
  return m;
}

glm::dvec2 polar(double r, double a) { return {r * std::cos(a), r * std::sin(a)}; }

TEST(ConeCoverage, AreaAndCentroidMatchA1024GonClippingInAllEightCases) {
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::map<std::pair<int, int>, int> cases;
  int checked = 0;
  for (int trial = 0; trial < 6000; ++trial) {
    glm::dvec2 v[3];
    const int kind = trial % 4;
    for (auto& p : v) {
      double r;
      if (kind == 0) r = 2.5 * u01(rng);                        // anything
      else if (kind == 1) r = u01(rng) < 0.5 ? u01(rng) : 1.0 + 0.6 * u01(rng);  // near the circle
      else if (kind == 2) r = 1.05 + 0.25 * u01(rng);           // just outside: hexagons
      else r = 1.5 + 3.0 * u01(rng);                            // far: discs inside triangles
      p = polar(r, 2.0 * std::numbers::pi * u01(rng));
    }
    if (std::fabs(cross2(v[1] - v[0], v[2] - v[0])) < 1e-3) continue;
    const DiscCoverage got = disc_triangle_coverage(v[0], v[1], v[2]);
    const Moments want = polygon_clip_oracle(v[0], v[1], v[2]);
    ++cases[{got.inside, got.crossings}];
    // The 1024-gon differs from the circle by at most 5e-6 of the radius: the area of a part
    // by at most its arc length times that.
    ASSERT_NEAR(got.area, want.area, 1e-4) << trial;
    if (want.area > 1e-2) {
      EXPECT_NEAR(got.centroid.x, want.centroid.x, 1e-3) << trial;
      EXPECT_NEAR(got.centroid.y, want.centroid.y, 1e-3) << trial;
    }
    ++checked;
  }
  EXPECT_GT(checked, 5000);
  const std::pair<int, int> all8[] = {{0, 0}, {0, 2}, {0, 4}, {0, 6}, {1, 2}, {1, 4}, {2, 2}, {3, 0}};
  for (const auto& k : all8) EXPECT_GT(cases[k], 20) << "case (" << k.first << "," << k.second << ")";
  int total = 0;
  for (const auto& k : all8) total += cases[k];
  EXPECT_EQ(total, checked) << "a case outside ROGER Fig.5.8";
}

TEST(ConeCoverage, CircularSegmentAwayFromHalfDisc) {
  // The part of the disc above y = h, cut by one edge of a huge triangle: θ = 2 acos h (≠ π
  // for h ≠ 0, where the sin^{3/2} misprint of eq.5.10 would differ), area (θ − sin θ)/2,
  // centroid at 2 (1 − h²)^{3/2} / (3 A) (the sin³(θ/2) form).
  for (double h : {-0.7, -0.3, 0.2, 0.5, 0.9}) {
    const DiscCoverage c = disc_triangle_coverage({-50.0, h}, {50.0, h}, {0.0, 80.0});
    const double theta = 2.0 * std::acos(h);
    const double area = 0.5 * (theta - std::sin(theta));
    EXPECT_EQ(c.inside, 0);
    EXPECT_EQ(c.crossings, 2);
    EXPECT_NEAR(c.area, area, 1e-12) << h;
    EXPECT_NEAR(c.centroid.x, 0.0, 1e-12) << h;
    EXPECT_NEAR(c.centroid.y, 2.0 * std::pow(1.0 - h * h, 1.5) / (3.0 * area), 1e-12) << h;
  }
  // Disc inside the triangle: all of it, centred.
  const DiscCoverage full = disc_triangle_coverage({-10, -10}, {10, -10}, {0, 10});
  EXPECT_EQ(full.area, std::numbers::pi);
  // Triangle inside the disc: its own area and centroid.
  const DiscCoverage small = disc_triangle_coverage({0.1, 0.1}, {0.5, 0.1}, {0.1, 0.4});
  EXPECT_NEAR(small.area, 0.5 * 0.4 * 0.3, 1e-15);
  EXPECT_NEAR(small.centroid.x, 0.7 / 3.0, 1e-15);
  EXPECT_NEAR(small.centroid.y, 0.6 / 3.0, 1e-15);
}

TEST(ConeCoverage, AbuttingTrianglesCoveringTheConeSumToOne) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    Cone cone;
    cone.origin = glm::vec3{float(u(rng)), float(u(rng)), float(u(rng))};
    cone.axis = glm::normalize(glm::vec3{float(u(rng)), float(u(rng)), 1.5f + float(u(rng))});
    cone.radius = 0.01f + 0.05f * float(u(rng) + 1.0);
    cone.tan_angle = std::tan(0.2f * float(u(rng) + 1.0));
    cone.near = 0.05f;
    // A plane crossing the cone obliquely at distance 2–3, covered by a jittered grid of
    // triangles much larger than the cone's cross-section there.
    const glm::vec3 centre = cone.origin + float(2.5 + 0.5 * u(rng)) * cone.axis;
    const glm::vec3 n = glm::normalize(cone.axis + 0.5f * glm::vec3{float(u(rng)), float(u(rng)), float(u(rng))});
    const glm::vec3 t1 = glm::normalize(glm::cross(n, glm::vec3(0.3f, 1.0f, 0.2f)));
    const glm::vec3 t2 = glm::cross(n, t1);
    const int grid = 8;
    const float extent = 6.0f;
    std::vector<glm::vec3> pts;
    for (int j = 0; j <= grid; ++j)
      for (int i = 0; i <= grid; ++i) {
        float x = -extent + 2.0f * extent * float(i) / grid, y = -extent + 2.0f * extent * float(j) / grid;
        if (i > 0 && i < grid && j > 0 && j < grid) {
          x += 0.3f * float(u(rng));
          y += 0.3f * float(u(rng));
        }
        pts.push_back(centre + x * t1 + y * t2);
      }
    double sum = 0.0;
    int parts = 0;
    for (int j = 0; j < grid; ++j)
      for (int i = 0; i < grid; ++i) {
        const glm::vec3 a = pts[j * (grid + 1) + i], b = pts[j * (grid + 1) + i + 1];
        const glm::vec3 c = pts[(j + 1) * (grid + 1) + i], d = pts[(j + 1) * (grid + 1) + i + 1];
        for (const auto& tri : {std::array<glm::vec3, 3>{a, b, d}, std::array<glm::vec3, 3>{a, d, c}}) {
          ConeTriangleHit h;
          if (cone_triangle_coverage(cone, tri[0], tri[1], tri[2], h)) {
            sum += h.coverage;
            ++parts;
          }
        }
      }
    EXPECT_NEAR(sum, 1.0, 1e-5) << trial << " (" << parts << " triangles)";
  }
}

TEST(ConeCoverage, NearPlaneAndCentroidPoint) {
  // A cylinder (tan 0) of radius 1 along +z and a big triangle in the plane z = 3: full
  // coverage, the centroid on the axis, 3 away.
  Cone cone;
  cone.radius = 1.0f;
  cone.near = 0.5f;
  ConeTriangleHit h;
  const glm::vec3 a(-10, -10, 3), b(10, -10, 3), c(0, 10, 3);
  ASSERT_TRUE(cone_triangle_coverage(cone, a, b, c, h));
  EXPECT_NEAR(h.coverage, 1.0f, 1e-6f);
  EXPECT_NEAR(h.distance, 3.0f, 1e-5f);
  const glm::vec3 x = (1.0f - h.u - h.v) * a + h.u * b + h.v * c;
  EXPECT_LT(glm::length(x - glm::vec3(0, 0, 3)), 1e-5f);
  // Behind the near plane: nothing. Beyond the far plane: nothing.
  cone.near = 3.5f;
  EXPECT_FALSE(cone_triangle_coverage(cone, a, b, c, h));
  cone.near = 0.5f;
  cone.far = 2.0f;
  EXPECT_FALSE(cone_triangle_coverage(cone, a, b, c, h));
  // A cone widening from radius 0.5 by tan 0.5: at z = 3 the disc has radius 2; the half
  // plane x >= 0 covers half of it, its centroid at x = 4·2/(3π) (the plane is orthogonal to the axis,
  // so the projection is a uniform scaling).
  cone.far = 3.4e38f;
  cone.radius = 0.5f;
  cone.tan_angle = 0.5f;
  const glm::vec3 p(0, -10, 3), q(10, -10, 3), r(0, 10, 3);
  ASSERT_TRUE(cone_triangle_coverage(cone, p, q, r, h));
  EXPECT_NEAR(h.coverage, 0.5f, 1e-5f);
  const glm::vec3 y = (1.0f - h.u - h.v) * p + h.u * q + h.v * r;
  EXPECT_NEAR(y.x, 8.0f / (3.0f * 3.14159265f), 1e-4f);
  EXPECT_NEAR(y.y, 0.0f, 1e-4f);
}

}  // namespace
}  // namespace speculum::trace
