// Tests of the caustics technique (SURVEY §6): the caustic map keeps the photons' flux for
// any splat radius or filter, a parallel slab under a directional light gives uniform
// irradiance E (1 − F0)², an occluder between the generator and the receiver removes the
// caustic (the distance check), the error against the light-traced reference falls as
// photon_res grows, and the frame is the same for any thread count and lane width.
#include "raster/caustics.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "core/optics.h"
#include "core/procedural_geometry.h"
#include "core/scene_loader.h"
#include "parallel/executor.h"
#include "raster/environment.h"
#include "raster/shadow_map.h"
#include "trace/bvh.h"
#include "trace/light_tracer.h"

namespace speculum::raster {
namespace {

using namespace procedural;

struct PhotonRun {
  ReflectorMaps maps;
  RefractorImpostors impostors;
  CausticPhotons photons;
};

PhotonRun shoot(par::Executor& ex, const Scene& s, int photon_res) {
  PhotonRun r;
  const EnvironmentMap env = build_environment(ex, s.environment, 8);
  const std::vector<ShadowMap> shadows = render_shadow_maps(ex, s, 256);
  r.maps = render_reflector_maps(ex, s, shadows, env, 256, nullptr);
  r.impostors = render_refractor_impostors(ex, s, 128);
  CausticPhotonOptions o;
  o.photon_res = photon_res;
  r.photons = trace_photon_images(ex, s, r.maps, &r.impostors, o);
  return r;
}

// The camera's G-buffer with `excluded` objects left out (to see a receiver under them).
GBuffer camera_gbuffer(par::Executor& ex, const Scene& s, const Camera& cam, int w, int h,
                       std::vector<std::uint32_t> excluded = {}) {
  RasterOptions ro;
  if (!excluded.empty()) {
    ro.excluded_objects.assign(s.objects.size(), 0);
    for (std::uint32_t o : excluded) ro.excluded_objects[o] = 1;
  }
  return resolve_gbuffer(ex, s, render_visibility(ex, s, cam, w, h, ro), cam.eye);
}

ImageRGBA caustic_term(par::Executor& ex, const GBuffer& g, const CausticMaps& maps, float tolerance = 0.05f) {
  return gather_caustics(ex, g, maps, ImageRGBA(g.width, g.height, glm::vec4(0.0f)), tolerance);
}

Light sun_down(float lux) {
  Light l;
  l.type = LightType::Directional;
  l.direction = {0, -1, 0};
  l.intensity = lux;
  return l;
}

// A 2×1×2 glass slab at height 1–2 over a white diffuse floor (tilted about x by `tilt`
// radians), sun straight down.
Scene slab_scene(float tilt = 0.0f) {
  SceneBuilder b("slab");
  const auto floor_m = b.add_material(diffuse("floor", glm::vec3(1.0f)));
  const auto glass_m = b.add_material(glass("glass", 1.5f));
  const float c = std::cos(tilt), sn = std::sin(tilt);
  b.add_object("floor", floor_m, quad({-5, -5 * sn, 5 * c}, {10, 0, 0}, {0, 10 * sn, -10 * c}, 8, 8));
  b.add_object("slab", glass_m, box({-1, 1, -1}, {1, 2, 1}, 2, false));
  Scene s = b.take();
  s.lights.push_back(sun_down(2.0f));
  return s;
}

Camera looking_down() {
  Camera c;
  c.eye = {0, 4, 0.01f};
  c.target = {0, 0, 0};
  c.vfov_degrees = 40.0f;
  c.znear = 0.05f;
  c.zfar = 20.0f;
  return c;
}

TEST(Caustics, MapFluxEqualsStoredPhotonFluxForEveryFilterAndRadius) {
  const Scene s = load_scene("glass-sphere:size=8000");
  par::Executor ex(2);
  const PhotonRun r = shoot(ex, s, 128);
  ASSERT_GT(r.photons.stored, 1000u);
  const double stored = r.photons.stored_flux.x;
  // Stored power is the arriving power times the path's transmittance: below it, and above
  // the (1 − F)² of grazing photons would allow only for a few.
  EXPECT_LT(stored, r.photons.generator_flux.x);
  EXPECT_GT(stored, 0.7 * r.photons.generator_flux.x);
  for (int radius : {0, 1, 3, 8}) {
    CausticMapOptions o;
    o.splat_radius = radius;
    const CausticMaps m = build_caustic_maps(ex, s, r.photons, o);
    ASSERT_EQ(m.cubes.size(), 1u);
    EXPECT_NEAR(caustic_map_flux(m.cubes[0]).x, stored, 1e-4 * stored) << "radius " << radius;
  }
  CausticMapOptions tri;
  tri.filter = CausticFilter::Triangles;
  EXPECT_NEAR(caustic_map_flux(build_caustic_maps(ex, s, r.photons, tri).cubes[0]).x, stored, 1e-4 * stored);
}

// A tilted receiver's irradiance scales with cosθ: the expected value below is shaded with the
// floor's own normal, so the tilted case asserts E (1 − F0)² cosθ.
class SlabReceiver : public ::testing::TestWithParam<float> {};

TEST_P(SlabReceiver, ParallelSlabUnderDirectionalLightGivesUniformIrradiance) {
  const Scene s = slab_scene(GetParam());
  par::Executor ex(2);
  const PhotonRun r = shoot(ex, s, 256);
  // Every photon enters and leaves at normal incidence: power × (1 − F0)². (The distance
  // impostor sees the slab's rim at grazing angles from its centre, so a few rim photons
  // exit through a side face and are lost to total internal reflection: at most 10 %.)
  const float f0 = fresnel_dielectric(1.0f, 1.5f), t = (1.0f - f0) * (1.0f - f0);
  EXPECT_LE(r.photons.stored_flux.x, t * r.photons.generator_flux.x * 1.001);
  EXPECT_GE(r.photons.stored_flux.x, 0.9 * t * r.photons.generator_flux.x);
  for (CausticFilter filter : {CausticFilter::Splat, CausticFilter::Triangles}) {
    CausticMapOptions o;
    o.filter = filter;
    const CausticMaps m = build_caustic_maps(ex, s, r.photons, o);
    const GBuffer g = camera_gbuffer(ex, s, looking_down(), 64, 64, {1});
    const ImageRGBA img = caustic_term(ex, g, m);
    // The floor under the slab's middle (|x|, |z| < 0.6) is lit by E (1 − F0)² from above.
    const SurfaceParams floor_s = surface_params(s.materials[0]);
    LightSample ls;
    ls.direction = {0, 1, 0};
    ls.irradiance = glm::vec3(2.0f * t);
    int n = 0;
    double sum = 0.0;
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      const glm::vec3 p = g.position.pixels[i];
      if (!g.covered(i) || std::fabs(p.x) > 0.5f || std::fabs(p.z) > 0.5f) continue;
      const float expected = shade_light(floor_s, g.normal.pixels[i], g.view_direction(i), ls).x;
      // Per pixel within 15 % (the photon grid aliases against the map's texels, and
      // the triangles' blur reaches across the rim), the mean within 2 %.
      EXPECT_NEAR(img.pixels[i].x, expected, 0.15f * expected) << "filter " << int(filter) << " at " << p.x << "," << p.z;
      sum += img.pixels[i].x / expected;
      ++n;
    }
    EXPECT_NEAR(sum / n, 1.0, 0.02) << "filter " << int(filter);
    EXPECT_GT(n, 400);
  }
}

INSTANTIATE_TEST_SUITE_P(Caustics, SlabReceiver, ::testing::Values(0.0f, 0.5f),
                         [](const auto& info) { return info.param == 0.0f ? "Level" : "TiltedHalfRadian"; });

// A glass ball over a floor under a point light, with or without a diffuse plate just above
// the floor where the caustic falls.
Scene ball_over_floor(bool plate) {
  SceneBuilder b("ball");
  const auto floor_m = b.add_material(diffuse("floor", glm::vec3(1.0f)));
  const auto glass_m = b.add_material(glass("glass", 1.5f));
  const auto plate_m = b.add_material(diffuse("plate", glm::vec3(0.5f)));
  b.add_object("floor", floor_m, quad({-5, 0, 5}, {10, 0, 0}, {0, 0, -10}, 8, 8));
  b.add_object("ball", glass_m, sphere({0, 1.5f, 0}, 0.8f, 64));
  if (plate) b.add_object("plate", plate_m, quad({-1.5f, 0.3f, 1.5f}, {3, 0, 0}, {0, 0, -3}, 2, 2));
  Scene s = b.take();
  Light l;
  l.position = {0.2f, 5.0f, 0.1f};
  l.intensity = 50.0f;
  s.lights.push_back(l);
  return s;
}

TEST(Caustics, AnOccluderBetweenGeneratorAndReceiverRemovesTheCaustic) {
  par::Executor ex(2);
  double floor_light[2] = {0.0, 0.0}, plate_light = 0.0;
  for (int with_plate = 0; with_plate < 2; ++with_plate) {
    const Scene s = ball_over_floor(with_plate == 1);
    const PhotonRun r = shoot(ex, s, 128);
    const CausticMaps m = build_caustic_maps(ex, s, r.photons, CausticMapOptions{});
    // The floor seen with the ball and the plate left out of the camera's view.
    const GBuffer g = camera_gbuffer(ex, s, looking_down(), 64, 64, with_plate ? std::vector<std::uint32_t>{1, 2}
                                                                                 : std::vector<std::uint32_t>{1});
    const ImageRGBA img = caustic_term(ex, g, m);
    for (const glm::vec4& p : img.pixels) floor_light[with_plate] += p.x;
    if (with_plate) {
      const ImageRGBA top = caustic_term(ex, camera_gbuffer(ex, s, looking_down(), 64, 64, {1}), m);
      for (const glm::vec4& p : top.pixels) plate_light += p.x;
    }
  }
  EXPECT_GT(floor_light[0], 1.0);
  EXPECT_EQ(floor_light[1], 0.0);   // the floor under the plate gets none
  EXPECT_GT(plate_light, 0.5 * floor_light[0]);  // the plate catches it instead
}

// The caustic term against the light-traced reference's (trace/light_tracer.h) on the floor
// of glass-sphere, as the photon image grows.
TEST(Caustics, ErrorAgainstTheLightTracedReferenceFallsWithPhotonRes) {
  const Scene s = load_scene("glass-sphere:size=8000");
  par::Executor ex(2);
  const Camera& cam = s.cameras.front();
  constexpr int W = 160, H = 120;
  const trace::Bvh bvh = trace::Bvh::build(s.mesh, ex);
  trace::PhotonOptions po;
  po.photons = 1 << 20;
  const ImageRGBA ref = trace::render_caustics(s, bvh, cam, W, H, po, ex);
  const GBuffer g = camera_gbuffer(ex, s, cam, W, H);
  std::vector<double> errors;
  for (int res : {16, 64, 256}) {
    const PhotonRun r = shoot(ex, s, res);
    const ImageRGBA img = caustic_term(ex, g, build_caustic_maps(ex, s, r.photons, CausticMapOptions{}));
    double e = 0.0, total_ref = 0.0, total = 0.0;
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      if (!g.covered(i) || g.object.pixels[i] != 0) continue;  // the floor
      e += std::fabs(img.pixels[i].x - ref.pixels[i].x);
      total_ref += ref.pixels[i].x;
      total += img.pixels[i].x;
    }
    errors.push_back(e / total_ref);
    // The energy agrees at every resolution (the map keeps the photons' flux): within 10 %.
    EXPECT_NEAR(total, total_ref, 0.1 * total_ref) << "photon_res " << res;
  }
  // Sparse photons leave holes and spikes; 16× the photons roughly halve the error.
  EXPECT_LT(errors[1], errors[0]);
  EXPECT_LT(errors[2], 0.7 * errors[0]);
}

TEST(Caustics, FrameIsTheSameForAnyThreadCountAndLaneWidth) {
  const Scene s = load_scene("glass-sphere:size=4000");
  const pipeline::Technique& t = pipeline::find_technique("caustics");
  pipeline::FrameSettings f;
  f.width = 64;
  f.height = 48;
  f.camera = s.cameras.front();
  f.cube_map_size = 64;
  f.params["photon_res"] = 64;
  f.params["filter"] = 1;
  f = t.with_defaults(f);
  par::Executor one(1, 1);
  const ImageRGBA a = pipeline::render_frame(s, t, f, one).radiance;
  for (auto [threads, lanes] : {std::pair{2, 8}, std::pair{8, 4}}) {
    par::Executor ex(threads, lanes);
    const ImageRGBA b = pipeline::render_frame(s, t, f, ex).radiance;
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(a.pixels[0])))
        << threads << " threads, " << lanes << " lanes";
  }
}

}  // namespace
}  // namespace speculum::raster

namespace speculum::raster {
namespace {

// Caustics in reflections: a mirror beside the glass ball sees the ball's caustic on the
// floor in its cube map once the caustics are gathered on the map's faces, and its bright
// part (over 1 % of the brightest gain: the refracted caustic, not the faint halo of the
// ball's surface reflection) lies on the floor under the ball.
TEST(Caustics, ReflectorMapsShowTheCausticWhereItLies) {
  Scene s = ball_over_floor(false);
  {
    Scene with = s;
    Material m = mirror("mirror");
    with.materials.push_back(m);
    const auto mat = static_cast<std::uint32_t>(with.materials.size() - 1);
    const MeshData q = quad({2.5f, 0.0f, 2.0f}, {0, 0, -4}, {0, 2, 0}, 2, 2);  // facing −x
    Object o;
    o.name = "mirror";
    o.first_triangle = static_cast<std::uint32_t>(with.mesh.triangle_count());
    o.triangle_count = static_cast<std::uint32_t>(q.triangle_count());
    o.material = mat;
    const auto base = static_cast<std::uint32_t>(with.mesh.positions.size());
    for (std::size_t i = 0; i < q.positions.size(); ++i) {
      with.mesh.positions.push_back(q.positions[i]);
      with.mesh.normals.push_back({-1, 0, 0});
      with.mesh.uvs.push_back(q.uvs[i]);
    }
    for (std::uint32_t i : q.indices) with.mesh.indices.push_back(base + i);
    for (std::size_t t = 0; t < q.triangle_count(); ++t) {
      with.mesh.triangle_material.push_back(mat);
      with.mesh.triangle_object.push_back(static_cast<std::uint32_t>(with.objects.size()));
    }
    with.objects.push_back(o);
    s = std::move(with);
  }
  s.validate();
  par::Executor ex(2);
  const PhotonRun r = shoot(ex, s, 128);
  const CausticMaps caustics = build_caustic_maps(ex, s, r.photons, CausticMapOptions{});
  const EnvironmentMap env = build_environment(ex, s.environment, 8);
  const std::vector<ShadowMap> shadows = render_shadow_maps(ex, s, 256);
  const ReflectorMaps plain = render_reflector_maps(ex, s, shadows, env, 128, nullptr);
  const ReflectorMaps lit = render_reflector_maps(ex, s, shadows, env, 128, nullptr, ReflectorSelection::all,
                                                  [&](const GBuffer& face, const ImageRGBA& direct) {
                                                    return gather_caustics(ex, face, caustics, direct, 0.05f);
                                                  });
  const std::uint32_t mirror_object = static_cast<std::uint32_t>(s.objects.size() - 1);
  const int k = plain.map_of_object[mirror_object];
  ASSERT_GE(k, 0);
  const CubeMap& a = plain.cubes[static_cast<std::size_t>(k)];
  const CubeMap& b = lit.cubes[static_cast<std::size_t>(k)];
  double added = 0.0;
  float brightest = 0.0f;
  for (int f = 0; f < kCubeFaces; ++f)
    for (int y = 0; y < a.size; ++y)
      for (int x = 0; x < a.size; ++x) brightest = std::max(brightest, b.colour[f].at(x, y).x - a.colour[f].at(x, y).x);
  int misplaced = 0, bright = 0;
  for (int f = 0; f < kCubeFaces; ++f)
    for (int y = 0; y < a.size; ++y)
      for (int x = 0; x < a.size; ++x) {
        const float gain = b.colour[f].at(x, y).x - a.colour[f].at(x, y).x;
        EXPECT_GE(gain, -1e-6f);
        added += gain;
        if (gain <= 0.01f * brightest) continue;
        ++bright;
        // Where the texel looks: the floor under the ball, within its caustic's reach.
        const glm::vec3 p = a.centre + cube_direction(f, {x + 0.5f, y + 0.5f}, a.size) * a.distance[f].at(x, y);
        if (std::fabs(p.y) > 0.05f || glm::length(glm::vec2(p.x, p.z)) > 2.0f) ++misplaced;
      }
  EXPECT_GT(added, 1.0);
  EXPECT_GT(bright, 5) << misplaced;
  EXPECT_EQ(misplaced, 0);
}

}  // namespace
}  // namespace speculum::raster
