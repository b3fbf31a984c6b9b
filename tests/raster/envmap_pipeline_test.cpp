// Tests of the envmap technique: Fresnel-weighted lookups against the shading model on
// constant environments, and the whole recipe's determinism across threads and lanes.
#include "raster/envmap_reflect.h"

#include <cstring>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "apps/pipeline_envmap.h"
#include "core/optics.h"
#include "core/scene_loader.h"
#include "parallel/lanes.h"
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
  for (const Camera cam : {oblique_camera(), Camera{"below", {0.2f, 1.0f, -2.0f}, {0, 0, 0}}}) {
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
  par::set_default_lanes(lanes);
  par::Executor ex(threads);
  par::Graph graph;
  pipeline::add_envmap_passes(graph, &scene, f);
  graph.request(pipeline::kRadiance);
  graph.run(ex);
  ImageRGBA out = graph.get<ImageRGBA>(pipeline::kRadiance);
  par::set_default_lanes(0);
  return out;
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

}  // namespace
}  // namespace speculum::raster
