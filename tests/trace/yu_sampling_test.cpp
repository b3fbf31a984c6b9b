// YU §3.3–3.4 sampling and footprint formulas: Phong-lobe directions of glossy_rays follow
// eq.4 (χ² on θ), the pdf integrates to 1, the mean Ω_s (eq.5) is 2π/N, eq.6 against the
// exact solid angle of the box's bounding sphere, eq.8–9 on a plane.
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/brdf.h"
#include "core/optics.h"
#include "core/sampling.h"
#include "parallel/executor.h"
#include "trace/bvh.h"
#include "trace/glossy_rays.h"
#include "trace/hit_radiance.h"
#include "trace/lod_bvh.h"

namespace speculum::trace {
namespace {

// One glossy pixel at the origin facing +Z, seen from straight above: R = N = +Z.
GlossyRays one_pixel_rays(int n_rays, float exponent, par::Executor& ex, glm::vec3 eye = {0, 0, 3}) {
  Buffer2D<glm::vec3> pos(1, 1, glm::vec3(0.0f)), nrm(1, 1, glm::vec3(0, 0, 1));
  SurfaceParams s;
  s.roughness = 0.3f;
  s.phong_exponent = exponent;
  const SurfacePlane surf = SurfacePlane::uniform(1, 1, s);
  IdBuffer obj(1, 1, 0u);
  GlossyRayOptions o;
  o.rays_per_pixel = n_rays;
  o.seed = 7;
  return generate_glossy_rays(ex, pos, nrm, surf, obj, eye, o);
}

// χ² of the rays' polar angles about +Z against the node's lobe of `exponent`, in `bins`
// bins of equal probability. With R = N the node's mixture (glossy_rays.h) has the CDF
// P(θ' < θ) = (1 − s)(1 − cos^(n+1) θ) + s (1 − cos² θ), s = kDefensiveShare.
double chi_square_theta(const GlossyRays& g, float exponent, int bins) {
  std::vector<double> count(bins, 0.0);
  for (std::size_t i = 0; i < g.ray_count(); ++i) {
    const glm::vec3 d = glm::normalize(glm::vec3(g.rays.dx[i], g.rays.dy[i], g.rays.dz[i]));
    const double s = kDefensiveShare;
    const double cdf = (1.0 - s) * (1.0 - std::pow(double(d.z), double(exponent) + 1.0)) +
                       s * (1.0 - double(d.z) * double(d.z));
    count[std::min(bins - 1, static_cast<int>(cdf * bins))] += 1.0;
  }
  const double expected = static_cast<double>(g.ray_count()) / bins;
  double chi2 = 0.0;
  for (double c : count) chi2 += (c - expected) * (c - expected) / expected;
  return chi2;
}

TEST(YuSampling, DirectionsFollowThePhongLobeEq4) {
  par::Executor ex(2);
  const float n = 20.0f;
  const GlossyRays g = one_pixel_rays(4000, n, ex);
  ASSERT_EQ(g.ray_count(), 4000u);
  EXPECT_EQ(g.below_horizon, 0u);  // R = N: the whole lobe is above the surface
  // 20 equiprobable bins, 19 dof: 43.8 is the 99.9% point of χ².
  EXPECT_LT(chi_square_theta(g, n, 20), 43.8);
  // The same test rejects a lobe of the wrong width.
  EXPECT_GT(chi_square_theta(g, 2.0f * n, 20), 43.8);
  EXPECT_GT(chi_square_theta(g, 0.5f * n, 20), 43.8);
}

TEST(YuSampling, PdfIntegratesToOneOverTheHemisphere) {
  for (float n : {0.0f, 1.0f, 10.0f, 100.0f, 1000.0f}) {
    // ∫ p dω = ∫_0^{π/2} p(θ) 2π sinθ dθ, midpoint rule in θ.
    const int steps = 200000;
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
      const double th = (i + 0.5) * (kPi / 2) / steps;
      sum += phong_lobe_pdf(static_cast<float>(std::cos(th)), n) * 2.0 * kPi * std::sin(th);
    }
    EXPECT_NEAR(sum * (kPi / 2) / steps, 1.0, 1e-3) << "exponent " << n;
  }
}

TEST(YuSampling, MeanSolidAngleIsTwoPiOverN) {
  par::Executor ex(2);
  const int N = 4096;
  // Sampled: Ω_s = 1/(N p) of the node's rays averages to 2π/N, the measure of the pdf's
  // support (the paper's 4π/N would be off by 2×). The sampled check uses flat lobes, where
  // 1/p stays bounded; the mixture's pdf is that of every ray.
  for (float n : {0.0f, 0.25f}) {
    const GlossyRays g = one_pixel_rays(N, n, ex);
    double sum = 0.0;
    for (float w : g.solid_angle) sum += w;
    EXPECT_NEAR(sum / N / (2.0 * kPi / N), 1.0, 0.02) << "exponent " << n;
    const glm::vec3 d = glm::normalize(glm::vec3(g.rays.dx[5], g.rays.dy[5], g.rays.dz[5]));
    EXPECT_FLOAT_EQ(g.solid_angle[5], 1.0f / (N * glossy_mixture_pdf(d.z, d.z, n)));
  }
  // Any exponent, by quadrature: E_p[Ω_s] = ∫ (1/(N p)) p dω = 2π/N over the hemisphere.
  for (float n : {1.0f, 10.0f, 100.0f}) {
    const int steps = 200000;
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
      const double th = (i + 0.5) * (kPi / 2) / steps;
      const float c = static_cast<float>(std::cos(th));
      const double p = phong_lobe_pdf(c, n);
      // Where p underflows (n = 100 at the rim) Ω_s overflows: the integrand is 1/N there too.
      const double term = p > 1e-30 ? double(sample_solid_angle(c, n, N)) * p : 1.0 / N;
      sum += term * 2.0 * kPi * std::sin(th);
    }
    EXPECT_NEAR(sum * (kPi / 2) / steps / (2.0 * kPi / N), 1.0, 1e-3) << "exponent " << n;
  }
}

// The node's estimate E Σ w L / Σ w (glossy_rays.h) of the reflection integral ∫ f L cos
// for an environment that varies across the lobe, L(ω) = 1 + 4 max(ω·a, 0)², against the
// same integral estimated independently by sampling GGX's visible normals (2^16 points).
// Also: the weights alone estimate the lobe's albedo E (unbiased, looser bound: the Phong
// pdf covers GGX's long tails only through the defensive share).
TEST(YuSampling, WeightedRaysEstimateTheReflectionIntegral) {
  par::Executor ex(2);
  const glm::vec3 a = glm::normalize(glm::vec3(0.5f, 0.2f, 1.0f));
  auto env = [&](const glm::vec3& w) { const float c = std::max(glm::dot(w, a), 0.0f); return 1.0f + 4.0f * c * c; };
  for (float roughness : {0.1f, 0.25f, 0.45f}) {
    for (float theta_v : {0.0f, 0.6f, 1.1f}) {
      Buffer2D<glm::vec3> pos(1, 1, glm::vec3(0.0f)), nrm(1, 1, glm::vec3(0, 0, 1));
      Material m;
      m.roughness = roughness;
      m.metallic = 1.0f;
      m.base_color = glm::vec4(0.9f, 0.6f, 0.3f, 1.0f);
      const SurfaceParams sp = surface_params(m);
      const SurfacePlane surf = SurfacePlane::uniform(1, 1, sp);
      IdBuffer obj(1, 1, 0u);
      GlossyRayOptions o;
      o.rays_per_pixel = 4096;
      const glm::vec3 v(std::sin(theta_v), 0.0f, std::cos(theta_v));
      const GlossyRays g = generate_glossy_rays(ex, pos, nrm, surf, obj, 3.0f * v, o);
      glm::dvec3 wl(0.0), w(0.0);
      for (std::size_t i = 0; i < g.ray_count(); ++i) {
        const glm::vec3 d(g.rays.dx[i], g.rays.dy[i], g.rays.dz[i]);
        wl += glm::dvec3(g.weight[i]) * double(env(d));
        w += glm::dvec3(g.weight[i]);
      }
      // Independent: E[F G2/G1 L] over visible normals.
      const float alpha = roughness * roughness;
      const glm::vec3 f0 = specular_f0(sp);
      glm::dvec3 exact(0.0);
      const std::uint32_t K = 1u << 16;
      for (std::uint32_t k = 0; k < K; ++k) {
        const glm::vec3 h = sample_ggx_visible_normal(v, alpha, hamersley(k, K));
        const glm::vec3 l = 2.0f * glm::dot(v, h) * h - v;
        const float wt = ggx_sample_weight(l.z, v.z, alpha);
        if (wt > 0.0f) exact += glm::dvec3(fresnel_schlick(glm::dot(v, h), f0) * (wt * env(glm::normalize(l))));
      }
      exact /= double(K);
      const glm::vec3 albedo = g.albedo[0];
      for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(::testing::Message() << "r " << roughness << " θv " << theta_v << " channel " << c);
        EXPECT_NEAR(albedo[c] * wl[c] / w[c], exact[c], 0.02 * exact[c]);
        EXPECT_NEAR(w[c] / 4096.0, albedo[c], 0.12 * albedo[c]);
      }
    }
  }
}

TEST(YuSampling, BelowHorizonSamplesAreRejectedAndCounted) {
  par::Executor ex(1);
  // Grazing view: R lies 5° above the surface, so a wide lobe puts samples under it.
  const glm::vec3 eye(std::cos(5.0f * kPi / 180.0f) * 3.0f, 0.0f, std::sin(5.0f * kPi / 180.0f) * 3.0f);
  const GlossyRays g = one_pixel_rays(256, 5.0f, ex, eye);
  std::uint64_t inactive = 0;
  for (std::size_t i = 0; i < g.ray_count(); ++i) {
    const bool active = g.solid_angle[i] > 0.0f;
    if (!active) {
      ++inactive;
      EXPECT_GT(g.rays.tmin[i], g.rays.tmax[i]);
    } else {
      EXPECT_GT(g.rays.dz[i], 0.0f);
    }
  }
  EXPECT_GT(g.below_horizon, 0u);
  EXPECT_EQ(inactive, g.below_horizon);
}

TEST(YuSampling, Eq6AgainstTheBoundingSphereSolidAngle) {
  // eq.6 is π r²/D² for the bounding sphere of radius r = |pmax-pmin|/2 at distance D: the
  // small-angle (projected disc) form of the exact 2π(1 - sqrt(1 - r²/D²)). It never exceeds
  // the exact value and their ratio is 1 + x/4 + O(x²), x = r²/D².
  // eq.6 as the LOD trace evaluates it: the node's numerator k = π |pmax-pmin|²/4 against
  // budget × D². Two triangles spanning the box's diagonal make it the root node's box.
  Aabb box;
  box.lo = glm::vec3(-1.0f, -0.5f, -2.0f);
  box.hi = glm::vec3(1.0f, 0.5f, 2.0f);
  par::Executor ex(1);
  const std::vector<glm::vec3> corners{box.lo, {box.hi.x, box.lo.y, box.lo.z}, box.hi, {box.lo.x, box.hi.y, box.hi.z}};
  const Bvh bvh = Bvh::build(corners, {0, 1, 2, 0, 2, 3}, ex);
  const LodBvh lod = build_lod_bvh(bvh, std::vector<glm::vec3>(2, glm::vec3(1.0f)));
  ASSERT_EQ(bvh.threaded_nodes()[0].box.lo, box.lo);
  ASSERT_EQ(bvh.threaded_nodes()[0].box.hi, box.hi);
  const double r = glm::length(box.hi - box.lo) / 2.0;
  for (double D : {1.05 * r, 1.5 * r, 3.0 * r, 10.0 * r, 100.0 * r, 1000.0 * r}) {
    const glm::vec3 x = box.center() + glm::normalize(glm::vec3(0.3f, 0.9f, -0.2f)) * static_cast<float>(D);
    const glm::vec3 to_center = box.center() - x;
    const double eq6 = lod.nodes[0].box_solid_angle_k / glm::dot(to_center, to_center);
    const double xx = r * r / (D * D);
    const double exact = 2.0 * kPi * (1.0 - std::sqrt(1.0 - xx));
    EXPECT_NEAR(eq6, kPi * xx, 1e-5 * kPi * xx);
    EXPECT_LE(eq6, exact * (1.0 + 1e-6));
    EXPECT_GE(eq6, exact * (1.0 - xx / 4.0 - xx * xx - 1e-6));  // ratio 1 + x/4 + ...
  }
}

TEST(YuSampling, Eq8FootprintOfANarrowConeOnAPlane) {
  // A cone of solid angle Ω (half-angle β, Ω = 2π(1-cosβ)) from a point at distance d along a
  // direction inclined θ to the plane's normal: its intersection with the plane, measured as
  // a polygon, has area → d² Ω / cosθ (eq.8) as β → 0.
  for (float theta_deg : {0.0f, 30.0f, 60.0f}) {
    const float th = theta_deg * kPi / 180.0f;
    const float d = 2.5f, beta = 0.004f;
    const glm::vec3 dir(std::sin(th), 0.0f, -std::cos(th));  // towards the plane z = 0
    const glm::vec3 origin = -d * dir;                        // hit at the origin, distance d
    const Onb frame(dir);
    const int k = 720;
    std::vector<glm::vec2> poly;
    for (int i = 0; i < k; ++i) {
      const float ph = 2.0f * kPi * i / k;
      const glm::vec3 w = frame.to_world({std::sin(beta) * std::cos(ph), std::sin(beta) * std::sin(ph), std::cos(beta)});
      const float t = -origin.z / w.z;
      const glm::vec3 p = origin + t * w;
      poly.push_back({p.x, p.y});
    }
    double area = 0.0;
    for (int i = 0; i < k; ++i) {
      const glm::vec2 a = poly[i], b = poly[(i + 1) % k];
      area += 0.5 * (double(a.x) * b.y - double(b.x) * a.y);
    }
    const float omega = 2.0f * kPi * (1.0f - std::cos(beta));
    EXPECT_NEAR(std::fabs(area) / footprint_area(d, omega, std::cos(th)), 1.0, 2e-3) << theta_deg;
  }
}

TEST(YuSampling, Eq9LevelOnAPlaneWithKnownTexelArea) {
  // A plane tessellated into cells of side h (two triangles each): texel area h²/2. A
  // footprint covering 4^l texels is level l; l = 0 at one texel.
  const float h = 0.05f, texel = h * h / 2.0f;
  const float d = 3.0f;
  for (int l = 0; l <= 6; ++l) {
    const float omega = texel * std::pow(4.0f, static_cast<float>(l)) / (d * d);  // head-on
    EXPECT_NEAR(mip_level(footprint_area(d, omega, 1.0f), texel), static_cast<float>(l), 1e-4f);
  }
  // At 60° incidence the footprint doubles: half a level coarser.
  const float omega = texel * 16.0f / (d * d);
  EXPECT_NEAR(mip_level(footprint_area(d, omega, 0.5f), texel), 2.5f, 1e-4f);
  // Footprints smaller than a texel clamp to the finest level in the lookup (negative l).
  EXPECT_LT(mip_level(footprint_area(d, omega / 64.0f, 1.0f), texel), 0.0f);
}

}  // namespace
}  // namespace speculum::trace
