// Tests of the envmap technique: Fresnel-weighted lookups against the shading model on
// constant environments, lookup directions against glm::reflect/refract on a direction-
// encoding environment, and the whole recipe's determinism across threads and lanes.
#include "raster/envmap_reflect.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "apps/techniques/technique_table.h"
#include "core/optics.h"
#include "core/scene_loader.h"
#include "raster/composite.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/specular_radiance.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

Scene plane_scene(const Material& material) {
  Scene scene;
  scene.name = "plane";
  scene.materials.push_back(material);
  testing::add_triangles(scene, {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}},
                         {0, 1, 2, 0, 2, 3});
  scene.environment.constant = glm::vec3(0.25f, 0.5f, 2.0f);
  return scene;
}

Camera oblique_camera() {
  Camera c;
  c.eye = {0.3f, -2.0f, 2.5f};
  c.target = {0, 0, 0};
  return c;
}

TEST(EnvmapReflect, MirrorLayerIsSchlickFresnelTimesEnvironment) {
  Material m;
  m.base_color = glm::vec4(0.9f, 0.6f, 0.3f, 1.0f);
  m.metallic = 1.0f;
  m.roughness = 0.0f;
  const Scene scene = plane_scene(m);
  par::Executor ex(2);
  const EnvironmentMap env = build_environment(ex, scene.environment, 8);
  const auto vis = render_visibility(ex, scene, oblique_camera(), 64, 48);
  const GBuffer g = resolve_gbuffer(ex, scene, vis, oblique_camera().eye);
  const ImageRGBA spec = envmap_reflect(ex, g, env);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < spec.size(); ++i) {
    if (!g.covered(i)) {
      EXPECT_EQ(spec.pixels[i], glm::vec4(0, 0, 0, 1));
      continue;
    }
    const float cos_nv = glm::dot(g.normal.pixels[i], g.view_direction(i));
    const glm::vec3 expected = fresnel_schlick(cos_nv, glm::vec3(m.base_color)) * scene.environment.constant;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(spec.pixels[i][c], expected[c], 1e-4f * (1 + expected[c]));
    ++checked;
  }
  EXPECT_GT(checked, spec.size() / 4);
}

TEST(EnvmapReflect, ClearRefractorConservesAConstantEnvironment) {
  // F·L + (1−F)·L = L: with a white refractor and a constant environment the specular layer
  // equals the environment, whatever the angle (also for rays leaving the glass).
  Material m;
  m.base_color = glm::vec4(1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.0f;
  m.transmission = 1.0f;
  m.ior = 1.5f;
  const Scene scene = plane_scene(m);
  par::Executor ex(1);
  const EnvironmentMap env = build_environment(ex, scene.environment, 8);
  for (const Camera& cam : {oblique_camera(), Camera{"below", {0.2f, 1.0f, -2.0f}, {0, 0, 0}}}) {
    const auto vis = render_visibility(ex, scene, cam, 40, 30);
    const GBuffer g = resolve_gbuffer(ex, scene, vis, cam.eye);
    const ImageRGBA spec = envmap_reflect(ex, g, env);
    std::size_t checked = 0;
    for (std::size_t i = 0; i < spec.size(); ++i) {
      if (!g.covered(i)) continue;
      EXPECT_NEAR(spec.pixels[i].z, 2.0f, 1e-4f);
      ++checked;
    }
    EXPECT_GT(checked, 100u);
  }
}

ImageRGBA render_envmap(const Scene& scene, int threads, int lanes) {
  pipeline::FrameSettings f;
  f.width = 96;
  f.height = 64;
  f.supersample = 2;
  f.shadow_map_size = 64;
  f.cube_map_size = 32;
  f.camera = scene.cameras.front();
  par::Executor ex(threads, lanes);
  par::Graph graph;
  const pipeline::FrameOutputs out = pipeline::find_technique("envmap").add_passes(graph, &scene, f);
  graph.request(out.radiance);
  graph.run(ex);
  return graph.get(out.radiance);
}

// A built-in scene's first camera view at 120×90: its G-buffer and environment map.
struct SceneView {
  Scene scene;
  GBuffer g;
  EnvironmentMap env;
  SceneView(par::Executor& ex, const char* name) : scene(load_scene(name)) {
    const Camera cam = scene.cameras.front();
    g = resolve_gbuffer(ex, scene, render_visibility(ex, scene, cam, 120, 90), cam.eye);
    env = build_environment(ex, scene.environment);
  }
};

// The cube faces' shading adds the specular layer onto the direct light in place: the bytes
// of composite(direct, envmap_reflect(...)), on views with mirrors, glossy and refracting
// samples, background, and a direct layer holding negative zeros.
TEST(EnvmapReflect, OntoDirectGivesTheBytesOfTheComposite) {
  par::Executor ex(2);
  for (const char* name : {"living-room", "glass-sphere", "sphere-in-room"}) {
    SCOPED_TRACE(name);
    const SceneView view(ex, name);
    const GBuffer& g = view.g;
    const EnvironmentMap& env = view.env;
    ImageRGBA direct(g.width, g.height);
    std::size_t specular = 0;
    for (std::size_t i = 0; i < direct.pixels.size(); ++i) {
      const float v = float(i % 7) * 0.1f;
      direct.pixels[i] = glm::vec4(i % 5 == 0 ? -0.0f : v, 0.5f * v, 0.25f, i % 3 == 0 ? 0.5f : 1.0f);
      specular += g.covered(i) && is_specular(g.surface[i]);
    }
    EXPECT_GT(specular, 100u);
    const ImageRGBA expected = composite(ex, direct, envmap_reflect(ex, g, env));
    ImageRGBA onto = direct;
    envmap_reflect_onto(ex, g, env, onto);
    ASSERT_EQ(expected.pixels.size(), onto.pixels.size());
    EXPECT_EQ(0, std::memcmp(expected.pixels.data(), onto.pixels.data(), expected.pixels.size() * sizeof(glm::vec4)));
  }
}

// The lookups made eight at a time (consecutive samples of one map, mirrors, glossy lobes and
// refractors mixed, each reflector in its own map) give per sample the bytes of
// specular_radiance with one scalar lookup at a time.
TEST(EnvmapReflect, BatchedLookupsGiveTheBytesOfOneAtATime) {
  par::Executor ex(2);
  for (const char* name : {"living-room", "glass-sphere", "bathroom"}) {
    SCOPED_TRACE(name);
    const SceneView view(ex, name);
    const GBuffer& g = view.g;
    const EnvironmentMap& env = view.env;
    const ReflectorMaps maps = render_reflector_maps(ex, view.scene, render_shadow_maps(ex, view.scene, 64), env, 32, &g);
    for (const ReflectorMaps* reflectors : {static_cast<const ReflectorMaps*>(nullptr), &maps}) {
      const ImageRGBA got = envmap_reflect(ex, g, env, reflectors);
      std::size_t specular = 0, mismatched = 0;
      for (std::size_t i = 0; i < got.pixels.size(); ++i) {
        if (!g.covered(i) || !is_specular(g.surface[i])) continue;
        ++specular;
        const EnvironmentMap* own = reflectors ? reflectors->for_object(g.object.pixels[i]) : nullptr;
        const EnvironmentMap& map = own ? *own : env;
        const glm::vec3 want = specular_radiance(g.surface[i], g.normal.pixels[i], g.view_direction(i),
                                                 [&](const glm::vec3& d, float e) { return map.radiance(d, e); });
        const glm::vec4 expected(want, 1.0f);
        mismatched += std::memcmp(&expected, &got.pixels[i], sizeof expected) != 0;
      }
      EXPECT_GT(specular, 100u);
      EXPECT_EQ(mismatched, 0u);
    }
  }
}

TEST(EnvmapPipeline, BitIdenticalForThreadsAndLanes) {
  const Scene scene = load_scene("sphere-in-room:size=3000");
  const ImageRGBA ref = render_envmap(scene, 1, 0);
  ASSERT_EQ(ref.width, 96);
  auto same = [&](const ImageRGBA& a) {
    return a.size() == ref.size() &&
           std::memcmp(a.pixels.data(), ref.pixels.data(), ref.size() * sizeof(glm::vec4)) == 0;
  };
  EXPECT_TRUE(same(render_envmap(scene, 2, 0)));
  EXPECT_TRUE(same(render_envmap(scene, 8, 0)));
  EXPECT_TRUE(same(render_envmap(scene, 2, 1)));
  EXPECT_TRUE(same(render_envmap(scene, 1, 16)));
  // Not a constant image: the scene is lit and has reflections.
  float lo = 1e30f, hi = -1e30f;
  for (const auto& p : ref.pixels) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
  EXPECT_GT(hi - lo, 0.1f);
}

TEST(RenderCommand, WritesTheImageAndPrintsItsPath) {
  const std::string out = ::testing::TempDir() + "speculum_render_test.png";
  std::remove(out.c_str());
  const std::string cmd = std::string(SPECULUM_BINARY) +
                          " render sphere-in-room:size=2000 --width 64 --height 48 -q -o " + out;
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char line[4096] = {0};
  const bool got_line = std::fgets(line, sizeof line, pipe) != nullptr;
  EXPECT_EQ(pclose(pipe), 0);
  ASSERT_TRUE(got_line);
  EXPECT_NE(std::string(line).find("speculum_render_test.png"), std::string::npos);
  const ImageRGBA img = read_image(out);
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 48);
  const std::string bad = std::string(SPECULUM_BINARY) + " render --technique nosuch -q 2>/dev/null";
  EXPECT_EQ(WEXITSTATUS(std::system(bad.c_str())), 2);
}

// A varying environment that encodes its direction: towards unit d it is (d/‖d‖∞ + 1)/2,
// the point where d leaves the cube [-1,1]³ mapped to [0,1]³. That is affine in the face
// pixel coordinates, so the bilinear lookup of a cube map filled with it is exact away
// from the half texel along face borders, and the colour a mirror sample returns gives
// back its lookup direction.
glm::vec3 direction_colour(const glm::vec3& d) {
  const float m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  return 0.5f * (d / m + 1.0f);
}
glm::vec3 colour_direction(const glm::vec3& c) { return glm::normalize(2.0f * c - 1.0f); }

// Whether d lands at least two texels away from every edge of its face.
bool away_from_face_edges(const glm::vec3& d, int size) {
  const glm::vec3 a = glm::abs(d);
  const float m = std::max({a.x, a.y, a.z});
  const float minor = a.x + a.y + a.z - m - std::min({a.x, a.y, a.z});
  return std::max(minor, std::min({a.x, a.y, a.z})) / m < 1.0f - 4.0f / size;
}

TEST(EnvmapReflect, LookupDirectionsAreGlmReflectAndRefract) {
  constexpr int kSize = 256;
  par::Executor ex(1);
  std::array<ImageRGBA, kCubeFaces> faces;
  for (int f = 0; f < kCubeFaces; ++f) {
    faces[f] = ImageRGBA(kSize, kSize);
    for (int y = 0; y < kSize; ++y)
      for (int x = 0; x < kSize; ++x)
        faces[f].at(x, y) =
            glm::vec4(direction_colour(cube_direction(f, {x + 0.5f, y + 0.5f}, kSize)), 1.0f);
  }
  const EnvironmentMap env = environment_from_faces(ex, faces, false, 1);

  SurfaceParams white_mirror;
  white_mirror.base_color = glm::vec3(1.0f);
  white_mirror.metallic = 1.0f;
  white_mirror.roughness = 0.0f;
  white_mirror.phong_exponent = 1e6f;
  SurfaceParams tinted_mirror = white_mirror;
  tinted_mirror.base_color = {0.9f, 0.6f, 0.3f};
  SurfaceParams glass;
  glass.base_color = {1.0f, 0.5f, 0.25f};
  glass.roughness = 0.0f;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  glass.phong_exponent = 1e6f;

  struct Sample {
    SurfaceParams s;
    glm::vec3 n, v;  // unit normal; unit direction towards the eye
  };
  const glm::vec3 n0 = glm::normalize(glm::vec3(0.2f, 0.3f, 1.0f));
  const glm::vec3 n1 = glm::normalize(glm::vec3(-0.5f, 1.0f, 0.25f));
  const std::vector<Sample> samples = {
      {white_mirror, n0, glm::normalize(glm::vec3(0.6f, -0.3f, 1.0f))},
      {white_mirror, n0, glm::normalize(glm::vec3(-0.8f, 0.1f, 0.5f))},
      {white_mirror, n1, glm::normalize(glm::vec3(0.3f, 0.7f, 0.6f))},
      {tinted_mirror, n0, glm::normalize(glm::vec3(-0.7f, -0.6f, 0.45f))},  // grazing-ish
      {tinted_mirror, n1, glm::normalize(glm::vec3(-0.2f, 0.9f, -0.1f))},
      {glass, n0, glm::normalize(glm::vec3(0.5f, -0.2f, 1.0f))},           // entering
      {glass, n1, glm::normalize(glm::vec3(0.6f, 0.5f, 0.7f))},            // entering, oblique
      {glass, n0, glm::normalize(glm::vec3(0.1f, -0.15f, -1.0f))},         // leaving the glass
      {glass, n1, glm::normalize(glm::vec3(0.98f, 0.05f, -0.09f))},         // leaving: TIR
  };
  GBuffer g;
  g.width = int(samples.size()) + 1;  // the last sample is background
  g.height = 1;
  g.eye = glm::vec3(0.5f, -1.0f, 2.0f);
  g.object = IdBuffer(g.width, 1, kNoId);
  g.reflector = IdBuffer(g.width, 1, kNoId);
  g.position = Buffer2D<glm::vec3>(g.width, 1);
  g.normal = Buffer2D<glm::vec3>(g.width, 1, glm::vec3(0, 0, 1));
  g.uv = Buffer2D<glm::vec2>(g.width, 1);
  g.surface = SurfacePlane::per_sample(Buffer2D<SurfaceParams>(g.width, 1));
  for (std::size_t i = 0; i < samples.size(); ++i) {
    g.object.pixels[i] = g.reflector.pixels[i] = 0;
    g.position.pixels[i] = g.eye - 3.0f * samples[i].v;
    g.normal.pixels[i] = samples[i].n;
    g.surface.own.pixels[i] = samples[i].s;
  }
  const ImageRGBA spec = envmap_reflect(ex, g, env);
  EXPECT_EQ(spec.pixels.back(), glm::vec4(0, 0, 0, 1));

  int refracted = 0, total_internal = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    SCOPED_TRACE("sample " + std::to_string(i));
    const Sample& smp = samples[i];
    const glm::vec3 v = g.view_direction(i);  // as the node sees it (= smp.v up to rounding)
    const glm::vec3 got(spec.pixels[i]);
    glm::vec3 want;
    if (!smp.s.is_refractor()) {
      const glm::vec3 r = glm::reflect(-v, smp.n);
      ASSERT_TRUE(away_from_face_edges(r, kSize)) << "pick another direction";
      const float c = glm::dot(smp.n, v);
      ASSERT_GT(c, 0.0f);
      const glm::vec3 f0 = smp.s.base_color;  // metallic 1: F0 is the base colour
      const glm::vec3 fresnel = f0 + (1.0f - f0) * std::pow(1.0f - c, 5.0f);
      want = fresnel * direction_colour(r);
      if (smp.s.base_color == glm::vec3(1.0f)) {
        // F = 1: the colour is the lookup direction itself.
        EXPECT_LT(glm::length(colour_direction(got) - r), 1e-3f)
            << "looked up along " << colour_direction(got).x << "," << colour_direction(got).y
            << "," << colour_direction(got).z;
      }
    } else {
      // The normal facing the viewer; eta = n_incident / n_transmitted as glm::refract takes it.
      const bool entering = glm::dot(smp.n, v) >= 0.0f;
      const glm::vec3 n = entering ? smp.n : -smp.n;
      const float eta = entering ? 1.0f / smp.s.ior : smp.s.ior;
      const glm::vec3 r = glm::reflect(-v, n);
      const glm::vec3 t = glm::refract(-v, n, eta);
      ASSERT_TRUE(away_from_face_edges(r, kSize)) << "pick another direction";
      if (t == glm::vec3(0.0f)) {  // total internal reflection: all reflected
        ++total_internal;
        want = direction_colour(r);
      } else {
        ++refracted;
        ASSERT_TRUE(away_from_face_edges(t, kSize)) << "pick another direction";
        const float f0 = (smp.s.ior - 1.0f) * (smp.s.ior - 1.0f) /
                         ((smp.s.ior + 1.0f) * (smp.s.ior + 1.0f));  // 0.04
        const float f = f0 + (1.0f - f0) * std::pow(1.0f - glm::dot(n, v), 5.0f);
        want = f * direction_colour(r) + (1.0f - f) * smp.s.base_color * direction_colour(t);
        // The two lookups are told apart: a swapped or unrefracted T would be far off.
        EXPECT_GT(glm::length(direction_colour(t) - direction_colour(-v)), 0.02f);
      }
    }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 2e-4f) << "channel " << c;
  }
  EXPECT_EQ(refracted, 3);
  EXPECT_EQ(total_internal, 1);
}

}  // namespace
}  // namespace speculum::raster
