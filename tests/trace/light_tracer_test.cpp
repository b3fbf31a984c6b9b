// The reference's caustics (trace/light_tracer.h) against analytic optics: a planar mirror's
// caustic is a virtual point light, a ball lens focuses paraxial light at νD/(4(ν−1)) from
// its centre, the light-traced image converges as photons grow, and the bytes do not depend
// on the thread count; the photon map estimates the mirror caustic too.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "core/optics.h"
#include "core/procedural_geometry.h"
#include "core/scene_loader.h"
#include "core/shading.h"
#include "parallel/executor.h"
#include "trace/bvh.h"
#include "trace/light_tracer.h"
#include "trace/photon_map.h"
#include "trace/reference_tracer.h"

namespace speculum::trace {
namespace {

using namespace procedural;

Light point(glm::vec3 p, float intensity) {
  Light l;
  l.type = LightType::Point;
  l.position = p;
  l.intensity = intensity;
  return l;
}

// A 4×4 mirror facing down at y = 2 over a diffuse floor at y = 0, a point light at y = 1
// between them: the mirror's image of the light is L' = (0, 3, 0).
Scene mirror_over_floor() {
  SceneBuilder b("mirror over floor");
  const auto floor_m = b.add_material(diffuse("floor", glm::vec3(0.8f)));
  const auto mirror_m = b.add_material(mirror("mirror", glm::vec3(0.9f)));
  b.add_object("floor", floor_m, quad({-10, 0, 10}, {20, 0, 0}, {0, 0, -20}, 4, 4));
  b.add_object("mirror", mirror_m, quad({-2, 2, -2}, {4, 0, 0}, {0, 0, 4}, 2, 2));
  Scene s = b.take();
  s.lights.push_back(point({0.0f, 1.0f, 0.0f}, 10.0f));
  Camera c;
  c.eye = {0, 1.5f, 6};
  c.target = {0, 0, 0};
  s.cameras.push_back(c);
  return s;
}

TEST(LightTracer, PlanarMirrorCausticIsTheVirtualPointLight) {
  const Scene s = mirror_over_floor();
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.mesh, ex);
  PhotonOptions o;
  o.photons = 1 << 21;
  PhotonStats stats;
  const std::vector<PhotonHit> hits = trace_caustic_photons(s, bvh, o, ex, &stats);
  ASSERT_GT(hits.size(), 100000u);
  // Irradiance in 1×1 cells of the floor, |x|, |z| < 1.5, against F(θ) I cosθ / |x − L'|²
  // averaged over the cell (32×32 midpoints), F the mirror's Schlick reflectance at θ.
  const SurfaceParams mirror_s = surface_params(s.materials[1]);
  const glm::vec3 virtual_light(0.0f, 3.0f, 0.0f);
  double cell_flux[3][3] = {};
  for (const PhotonHit& h : hits) {
    if (s.mesh.triangle_object[h.triangle] != 0) continue;
    EXPECT_EQ(h.bounces, 1u);
    const int cx = static_cast<int>(std::floor(h.p.x + 1.5f)), cz = static_cast<int>(std::floor(h.p.z + 1.5f));
    if (cx >= 0 && cx < 3 && cz >= 0 && cz < 3) cell_flux[cx][cz] += h.flux.x;
  }
  for (int cx = 0; cx < 3; ++cx)
    for (int cz = 0; cz < 3; ++cz) {
      double expected = 0.0;
      for (int i = 0; i < 32; ++i)
        for (int k = 0; k < 32; ++k) {
          const glm::vec3 x(-1.5f + cx + (i + 0.5f) / 32.0f, 0.0f, -1.5f + cz + (k + 0.5f) / 32.0f);
          const glm::vec3 d = virtual_light - x;
          const float r2 = glm::dot(d, d), cos_t = d.y / std::sqrt(r2);
          expected += specular_reflectance(mirror_s, cos_t).x * 10.0f * cos_t / r2;
        }
      expected /= 32.0 * 32.0;
      // About 14000 photons per cell: a 1 % standard error; 4 % is four of them.
      EXPECT_NEAR(cell_flux[cx][cz], expected, 0.04 * expected) << "cell " << cx << "," << cz;
    }
}

// A glass ball lens (ν = 1.5, radius 1 at the origin) under parallel light along −x, a wall
// at x = −4: each photon refracted in and out crosses the axis at a distance from the centre
// that falls from νD/(4(ν−1)) (paraxial) as its height grows (spherical aberration).
TEST(LightTracer, BallLensFocusesParaxialLightAtNuDOver4NuMinus1) {
  SceneBuilder b("ball lens");
  const auto wall_m = b.add_material(diffuse("wall", glm::vec3(0.8f)));
  const auto glass_m = b.add_material(glass("glass", 1.5f));
  b.add_object("wall", wall_m, quad({-4, -6, 6}, {0, 0, -12}, {0, 12, 0}, 4, 4));
  b.add_object("ball", glass_m, sphere({0, 0, 0}, 1.0f, 256));
  Scene s = b.take();
  Light sun;
  sun.type = LightType::Directional;
  sun.direction = {-1, 0, 0};
  sun.intensity = 1.0f;
  s.lights.push_back(sun);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.mesh, ex);
  PhotonOptions o;
  o.photons = 1 << 18;
  const std::vector<PhotonHit> hits = trace_caustic_photons(s, bvh, o, ex);
  std::vector<float> focus;
  for (const PhotonHit& h : hits) {
    if (h.bounces != 2 || s.mesh.triangle_object[h.triangle] != 0) continue;
    // The exit ray p + t wi is meridional: it meets the x axis where y² + z² is least.
    const float t = -(h.p.y * h.wi.y + h.p.z * h.wi.z) / (h.wi.y * h.wi.y + h.wi.z * h.wi.z);
    focus.push_back(-(h.p.x + t * h.wi.x));
  }
  std::sort(focus.begin(), focus.end());
  ASSERT_GT(focus.size(), 100000u);
  const float nu = 1.5f, D = 2.0f, paraxial = nu * D / (4.0f * (nu - 1.0f));  // 1.5
  // The farthest crossings are the paraxial ones (the 99.9th percentile: a photon within
  // ~3 % of the radius from the axis).
  EXPECT_NEAR(focus[focus.size() * 999 / 1000], paraxial, 0.015f);
  EXPECT_LE(focus.back(), paraxial + 0.02f);
  // Marginal rays focus shorter: the median crossing lies well inside the paraxial focus.
  EXPECT_LT(focus[focus.size() / 2], paraxial - 0.1f);
}

// Root mean square difference: an unbiased estimator's falls like 1/sqrt(photons) however
// sparse the photons are (a mean absolute difference does not fall until most pixels get some).
double rms_difference(const ImageRGBA& a, const ImageRGBA& b) {
  double sum = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = a.pixels[i][c] - b.pixels[i][c];
      sum += d * d;
    }
  return std::sqrt(sum / (3.0 * static_cast<double>(a.pixels.size())));
}

TEST(LightTracer, CausticImageConvergesAsPhotonsGrow) {
  const Scene s = load_scene("glass-sphere:size=8000");
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.mesh, ex);
  PhotonOptions truth;
  truth.photons = 1 << 21;
  truth.seed = 99;
  const ImageRGBA ref = render_caustics(s, bvh, s.cameras.front(), 64, 48, truth, ex);
  double previous = 1e30;
  std::vector<double> errors;
  for (std::uint64_t n : {1u << 13, 1u << 15, 1u << 17}) {
    PhotonOptions o;
    o.photons = n;
    const double e = rms_difference(render_caustics(s, bvh, s.cameras.front(), 64, 48, o, ex), ref);
    errors.push_back(e);
    EXPECT_LT(e, previous) << n << " photons";
    previous = e;
  }
  // Monte Carlo: 16× the photons, about 1/4 the error (well under 1/2).
  EXPECT_LT(errors.back(), 0.5 * errors.front());
  // The caustic is there at all: the reference's image is not black.
  double total = 0.0;
  for (const auto& p : ref.pixels) total += p.x;
  EXPECT_GT(total, 1.0);
}

TEST(LightTracer, ReferenceWithCausticsIsTheSameForOneAndTwoThreads) {
  const Scene s = load_scene("bowl:size=4000");
  ReferenceOptions o;
  o.width = 48;
  o.height = 36;
  o.spp = 2;
  o.caustic_photons = 1 << 14;
  par::Executor one(1), two(2);
  ReferenceStats st1, st2;
  const ImageRGBA a = render_reference(s, s.cameras.front(), o, one, &st1);
  const ImageRGBA b = render_reference(s, s.cameras.front(), o, two, &st2);
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])));
  EXPECT_EQ(st1.caustic_splats, st2.caustic_splats);
  EXPECT_GT(st1.caustic_splats, 0u);
  // And the caustics add light: the image with them is brighter than without.
  ReferenceOptions none = o;
  none.caustic_photons = 0;
  const ImageRGBA c = render_reference(s, s.cameras.front(), none, two);
  double with = 0.0, without = 0.0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    with += a.pixels[i].x;
    without += c.pixels[i].x;
  }
  EXPECT_GT(with, without);
}

TEST(LightTracer, BadPhotonCountIsAnInputError) {
  const Scene s = mirror_over_floor();
  par::Executor ex(1);
  const Bvh bvh = Bvh::build(s.mesh, ex);
  PhotonOptions o;
  o.photons = 0;
  EXPECT_THROW(trace_caustic_photons(s, bvh, o, ex), InputError);
}

}  // namespace
}  // namespace speculum::trace

namespace speculum::trace {
namespace {

// The photon map's density estimate of the planar mirror's caustic: the floor's radiance is
// f · F(θ) I cosθ / |x − L'|², averaged over nine points (the estimate of one point has the
// noise of its k photons and the blur of their disc).
TEST(LightTracer, PhotonMapEstimatesThePlanarMirrorCaustic) {
  const Scene s = mirror_over_floor();
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.mesh, ex);
  PhotonOptions o;
  o.photons = 1 << 21;
  const PhotonMap map(trace_caustic_photons(s, bvh, o, ex), 256, 0.5f);
  const SurfaceParams floor_s = surface_params(s.materials[0]), mirror_s = surface_params(s.materials[1]);
  const glm::vec3 virtual_light(0.0f, 3.0f, 0.0f), n(0.0f, 1.0f, 0.0f), v = glm::normalize(glm::vec3(0, 1, 1));
  double estimated = 0.0, expected = 0.0;
  for (float x : {-1.0f, 0.0f, 1.0f})
    for (float z : {-1.0f, 0.0f, 1.0f}) {
      const glm::vec3 p(x, 0.0f, z), d = virtual_light - p;
      const float r2 = glm::dot(d, d), cos_t = d.y / std::sqrt(r2);
      LightSample ls;
      ls.direction = d / std::sqrt(r2);
      ls.irradiance = glm::vec3(specular_reflectance(mirror_s, cos_t).x * 10.0f / r2);
      expected += shade_light(floor_s, n, v, ls).x;
      estimated += map.radiance(p, n, v, floor_s).x;
    }
  EXPECT_NEAR(estimated, expected, 0.05 * expected);
}

}  // namespace
}  // namespace speculum::trace
