// ROGER §2.2: the reflection of a scene vertex V seen from E in a star-shaped reflector
// P(u) = O + r(u) u is the point where the optical path ℓ = |EP| + |PV| is stationary
// (Fermat's principle); it is found by a 2-D secant iteration on the directions u.
//
// Conventions (the corrected form of ROGER §2.2.3's eq.2.2 is used): with the interpolated
// unit normal n at P, the reflector's log-radius gradient is ∇ln r = u − n/(n·u) (ROGER's
// ∇r is r times it), e = (P−E)/|P−E| + (P−V)/|P−V| (ROGER prints PV = V−P, a sign error
// that breaks eq.2.2 even on a sphere), and the gradient used is
// g(u) = (u·e) ∇ln r + (I − u uᵀ) e — the true gradient of ℓ over the sphere of directions
// divided by r (ROGER's eq.2.2 with a corrected e is still wrong off the sphere); both vanish
// exactly at the reflection point.
//
// Iteration (ROGER §2.2.3 "Finding a better estimate"): samples A, B, C with gradients;
// a = g_A − g_C, b = g_B − g_C, c = g_C; δ = a²b² − (a·b)²; α = ((a·b)(b·c) − b²(a·c))/δ,
// β = ((a·b)(a·c) − a²(b·c))/δ; D = αA + βB + (1−α−β)C normalized back onto the direction
// sphere (so P(D) is on the reflector) replaces the sample with the largest |g|. δ ≈ 0
// backtracks: the last discarded sample replaces the worst sample other than the newest.
// Safeguards (ours): a step is at most max_step radians; a D no better than the sample it
// would replace is pulled towards the best sample, and if that fails the triangle contracts
// towards the best sample instead.
// Start: A = radial direction of V, B = of E, C completing an equilateral triangle off the
// plane OEV. Stop (ROGER appendix A.2.2, tightened): the longest edge of the projected
// triangle P(A)P(B)P(C) is under `pixel_tolerance` pixels AND the smallest |g| is under
// `residual` (area alone stops on slivers far from the point).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace speculum::raster {

// What a reflector parameterization returns towards unit direction u from its centre.
struct ReflectorSample {
  bool valid = false;     // false: no reflector surface in that direction
  glm::dvec3 point{0.0};  // P(u) = O + r(u) u
  glm::dvec3 normal{0.0}; // unit interpolated normal at P (either orientation)
};

enum class ProjectionStatus : std::uint8_t {
  Converged,     // stop criterion met
  NotConverged,  // max_iterations reached (or the secant system stayed degenerate)
  OffReflector,  // a sample fell where the reflector has no surface (e.g. past a bowl's rim)
  Hidden,        // E or V lies behind the tangent plane at P: the path crosses the reflector
};

// The kind of stationary point of ℓ over the reflector (its Hessian's signature): convex
// reflectors give minima; a concave one gives minima in its near zone, maxima in its far
// zone and saddles (or singular points) in the middle zone between (ROGER §2.3.3).
enum class PathExtremum : std::uint8_t { Minimum, Maximum, Saddle };

struct FermatSettings {
  int max_iterations = 32;
  double pixel_tolerance = 1.0;  // longest projected edge of ABC, pixels
  // |g| at the best sample (dimensionless: g is a sum of unit vectors). A bilinearly looked
  // up parameterization leaves |g| ≈ 1e-3 at the true point, so the bound sits above that.
  double residual = 3e-3;
  double max_step = 0.5;         // radians a secant step may move from the best sample
  // Longest side of the starting triangle (radians): B is pulled towards A when farther. A
  // concave reflector seen from its mirror side has several stationary points per vertex;
  // a small triangle at V's radial projection finds the one nearest V (the near zone's).
  double max_start_side = 4.0;
  // Classify the stationary point by its Hessian (two more lookups). Off for a reflector
  // known to be convex, whose every reflection is a minimum: a bilinear lookup's kinks
  // would otherwise read a few points as saddles.
  bool classify = true;
  // A closed reflector is seen from outside only: E and V must both lie outside the tangent
  // plane at P (on the side away from the centre O). An open one (a bowl, a shell) reflects
  // on both sides: E and V on one side of it.
  bool closed = false;
};

struct FermatResult {
  ProjectionStatus status = ProjectionStatus::NotConverged;
  PathExtremum extremum = PathExtremum::Minimum;
  glm::dvec3 point{0.0};   // P (best sample)
  glm::dvec3 normal{0.0};
  glm::dvec3 direction{0.0};
  int iterations = 0;      // secant steps (new samples D)
  int backtracks = 0;
  int contractions = 0;    // steps that shrank the triangle instead of adding D
  double residual = 0.0;   // |g| at P
};

namespace fermat_detail {

struct Sample {
  bool valid = false;
  glm::dvec3 u{0.0}, p{0.0}, n{0.0}, g{0.0};
  double gn = 0.0;  // |g|
};

template <class Reflector>
Sample evaluate(const Reflector& reflector, const glm::dvec3& u, const glm::dvec3& eye, const glm::dvec3& vertex) {
  Sample s;
  const ReflectorSample r = reflector(u);
  if (!r.valid) return s;
  const double nu = glm::dot(r.normal, u);
  if (!(std::fabs(nu) > 1e-9)) return s;  // the ray from O grazes the surface
  const glm::dvec3 pe = r.point - eye, pv = r.point - vertex;
  const double le = glm::length(pe), lv = glm::length(pv);
  if (!(le > 0.0) || !(lv > 0.0)) return s;
  const glm::dvec3 e = pe / le + pv / lv;
  const glm::dvec3 grad_log_r = u - r.normal / nu;
  const double ue = glm::dot(u, e);
  s.valid = true;
  s.u = u;
  s.p = r.point;
  s.n = r.normal;
  s.g = ue * grad_log_r + (e - ue * u);
  s.gn = glm::length(s.g);
  return s;
}

inline glm::dvec3 any_perpendicular(const glm::dvec3& u) {
  const glm::dvec3 a = std::fabs(u.x) < 0.6 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(u, a));
}

}  // namespace fermat_detail

// `reflector(u)` → ReflectorSample for a unit direction u from `centre`; `project(p)` → the
// pixel position of world point p (glm::dvec2). E = eye, V = vertex.
template <class Reflector, class Project>
FermatResult fermat_project(const Reflector& reflector, const glm::dvec3& centre, const glm::dvec3& eye,
                            const glm::dvec3& vertex, const Project& project, const FermatSettings& settings) {
  using fermat_detail::Sample;
  FermatResult out;
  auto eval = [&](const glm::dvec3& u) { return fermat_detail::evaluate(reflector, u, eye, vertex); };
  // Start directions: radial projections of V and E, each flipped if the reflector has no
  // surface that way (the centre of a bowl sees its surface only below it).
  auto radial = [&](const glm::dvec3& x, const glm::dvec3& fallback) {
    const glm::dvec3 d = x - centre;
    const double l = glm::length(d);
    glm::dvec3 u = l > 0.0 ? d / l : fallback;
    if (!reflector(u).valid) u = -u;
    return u;
  };
  const glm::dvec3 ua = radial(vertex, glm::dvec3(0, 1, 0));
  glm::dvec3 ub = radial(eye, fermat_detail::any_perpendicular(ua));
  // The triangle's side: the arc AB, kept between a small and a large fraction of the sphere
  // so that a vertex on the line OE still starts from a proper triangle.
  double side = glm::length(ua - ub);
  glm::dvec3 axis = glm::cross(ua, ub);
  if (glm::length(axis) < 1e-9) axis = fermat_detail::any_perpendicular(ua);
  axis = glm::normalize(axis);
  if (side < 1e-3) {
    side = 1e-2;
    ub = glm::normalize(ua + side * glm::cross(axis, ua));
  }
  if (side > settings.max_start_side) {
    const double keep = 2.0 * std::asin(std::min(1.0, settings.max_start_side / 2.0));  // chord → angle
    ub = std::cos(keep) * ua + std::sin(keep) * glm::normalize(glm::cross(axis, ua));
    side = glm::length(ua - ub);
  }
  side = std::min(side, 1.0);
  const glm::dvec3 mid = 0.5 * (ua + ub);
  const glm::dvec3 uc = glm::normalize(mid + axis * (side * std::sqrt(3.0) / 2.0));
  Sample s[3] = {eval(ua), eval(ub), eval(uc)};
  for (const Sample& x : s)
    if (!x.valid) {
      out.status = ProjectionStatus::OffReflector;
      return out;
    }
  Sample discarded;
  int newest = -1;
  auto best_index = [&] {
    int b = 0;
    for (int k = 1; k < 3; ++k)
      if (s[k].gn < s[b].gn) b = k;
    return b;
  };
  auto finish = [&](ProjectionStatus status) {
    const Sample& b = s[best_index()];
    out.status = status;
    out.point = b.p;
    out.normal = b.n;
    out.direction = b.u;
    out.residual = b.gn;
    return out;
  };
  for (;;) {
    const int best = best_index();
    if (s[best].gn < settings.residual) {
      const glm::dvec2 pa = project(s[0].p), pb = project(s[1].p), pc = project(s[2].p);
      const double longest = std::max({glm::length(pa - pb), glm::length(pb - pc), glm::length(pc - pa)});
      // An exact zero gradient ends the iteration too (the secant would only collapse).
      if (longest < settings.pixel_tolerance || s[best].gn < 1e-12) break;
    }
    if (out.iterations >= settings.max_iterations) return finish(ProjectionStatus::NotConverged);
    const glm::dvec3 a = s[0].g - s[2].g, b = s[1].g - s[2].g, c = s[2].g;
    const double aa = glm::dot(a, a), bb = glm::dot(b, b), ab = glm::dot(a, b);
    const double delta = aa * bb - ab * ab;
    ++out.iterations;  // a backtrack counts too, so the loop stays bounded
    if (!(delta > 1e-14 * aa * bb) || !(aa * bb > 0.0)) {
      if (!discarded.valid) return finish(ProjectionStatus::NotConverged);
      int worst = -1;
      for (int k = 0; k < 3; ++k)
        if (k != newest && (worst < 0 || s[k].gn > s[worst].gn)) worst = k;
      std::swap(s[worst], discarded);
      ++out.backtracks;
      continue;
    }
    const double ac = glm::dot(a, c), bc = glm::dot(b, c);
    const double alpha = (ab * bc - bb * ac) / delta;
    const double beta = (ab * ac - aa * bc) / delta;
    glm::dvec3 d = alpha * s[0].u + beta * s[1].u + (1.0 - alpha - beta) * s[2].u;
    if (!(glm::length(d) > 1e-12)) return finish(ProjectionStatus::NotConverged);
    d = glm::normalize(d);
    // A step far beyond the samples extrapolates a linear model of g where it no longer
    // holds: at most max_step radians from the best sample.
    if (const double cosine = glm::dot(d, s[best].u); cosine < std::cos(settings.max_step)) {
      const glm::dvec3 w = glm::normalize(d - cosine * s[best].u);
      d = std::cos(settings.max_step) * s[best].u + std::sin(settings.max_step) * w;
    }
    Sample sd = eval(d);
    // Off the surface (past a rim) or grazing: pull D back halfway towards the best sample,
    // a bounded number of times.
    for (int k = 0; k < 4 && !sd.valid; ++k) {
      d = glm::normalize(d + s[best].u);
      sd = eval(d);
    }
    if (!sd.valid) return finish(ProjectionStatus::OffReflector);
    int worst = 0;
    for (int k = 1; k < 3; ++k)
      if (s[k].gn > s[worst].gn) worst = k;
    // A D no better than the sample it replaces (the linear model of g failed, near grazing
    // paths) is pulled halfway back towards the best sample, a bounded number of times, so
    // the same point cannot re-enter forever.
    for (int k = 0; k < 4 && sd.gn >= s[worst].gn; ++k) {
      const Sample half = eval(glm::normalize(sd.u + s[best].u));
      if (!half.valid) break;
      sd = half;
    }
    if (sd.gn >= s[worst].gn) {
      // Still no better: g is far from linear over the triangle (a vertex almost touching
      // the reflector). Contract the other samples halfway towards the best one, so the
      // linear model is asked again over a smaller triangle.
      ++out.contractions;
      for (int k = 0; k < 3; ++k) {
        if (k == best) continue;
        const Sample half = eval(glm::normalize(s[k].u + s[best].u));
        if (half.valid) s[k] = half;
      }
      discarded = Sample{};
      newest = -1;
      continue;
    }
#ifdef FERMAT_TRACE
    std::printf("it %d: |g| %.3g %.3g %.3g D |g| %.3g a %.3g b %.3g delta %.3g u %.3f %.3f %.3f\n", out.iterations, s[0].gn, s[1].gn, s[2].gn, sd.gn, alpha, beta, delta, sd.u.x, sd.u.y, sd.u.z);
#endif
    discarded = s[worst];
    s[worst] = sd;
    newest = worst;
  }
  finish(ProjectionStatus::Converged);
  // Both E and V must see P from the reflector's side: otherwise the stationary path passes
  // through the reflector (V behind it, or P beyond the silhouette seen from E).
  const double se = glm::dot(eye - out.point, out.normal), sv = glm::dot(vertex - out.point, out.normal);
  const double outward = glm::dot(out.point - centre, out.normal) >= 0.0 ? 1.0 : -1.0;
  if (settings.closed ? !(se * outward > 0.0 && sv * outward > 0.0) : !(se * sv > 0.0))
    out.status = ProjectionStatus::Hidden;
  // The stationary point's kind from the Hessian of ℓ/r in a tangent basis at u, by forward
  // differences of g (two more samples).
  if (!settings.classify) {
    out.extremum = PathExtremum::Minimum;
    return out;
  }
  const glm::dvec3 t1 = fermat_detail::any_perpendicular(out.direction);
  const glm::dvec3 t2 = glm::cross(out.direction, t1);
  constexpr double h = 1e-4;
  const Sample g1 = eval(glm::normalize(out.direction + h * t1));
  const Sample g2 = eval(glm::normalize(out.direction + h * t2));
  const glm::dvec3 g0 = s[best_index()].g;
  if (g1.valid && g2.valid) {
    const double h11 = glm::dot(g1.g - g0, t1) / h, h12 = glm::dot(g2.g - g0, t1) / h;
    const double h21 = glm::dot(g1.g - g0, t2) / h, h22 = glm::dot(g2.g - g0, t2) / h;
    const double off = 0.5 * (h12 + h21);
    const double det = h11 * h22 - off * off, trace = h11 + h22;
    out.extremum = det <= 1e-6 * trace * trace ? PathExtremum::Saddle
                   : trace > 0.0              ? PathExtremum::Minimum
                                              : PathExtremum::Maximum;
  } else {
    out.extremum = PathExtremum::Saddle;
  }
  return out;
}

}  // namespace speculum::raster
