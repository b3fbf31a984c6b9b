// Tests of the `gbuffer` node: world position, uv and normal-mapped shading normal of a
// textured quad against the analytic ray–plane intersection.
#include "raster/gbuffer.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

TEST(GBuffer, PositionUvAndNormalMapOnAQuad) {
  Scene scene;
  scene.name = "quad";
  Material m;
  m.base_color = glm::vec4(0.5f, 0.25f, 1.0f, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.8f;
  m.normal_texture.texture = 0;
  scene.materials.push_back(m);
  // A constant tangent-space normal (0.6, 0, 0.8), stored as (n + 1) / 2.
  scene.textures.push_back(ImageRGBA(2, 2, glm::vec4(0.8f, 0.5f, 0.9f, 1.0f)));
  testing::add_triangles(scene, {{-2, -1, 0}, {2, -1, 0}, {2, 1, 0}, {-2, 1, 0}}, {0, 1, 2, 0, 2, 3},
                         {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  scene.mesh.tangents.assign(scene.mesh.positions.size(), glm::vec4(1, 0, 0, 1));
  Camera cam;
  cam.eye = {0.7f, -0.4f, 3.0f};
  cam.target = {0.2f, 0.1f, 0.0f};
  const int w = 96, h = 64;
  par::Executor ex(2);
  const auto vis = render_visibility(ex, scene, cam, w, h);
  const GBuffer g = resolve_gbuffer(ex, scene, vis, cam.eye);
  const glm::vec3 mapped = glm::normalize(glm::vec3(0.6f, 0.0f, 0.8f));
  std::size_t checked = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      if (!g.covered(i)) continue;
      const Ray r = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
      const float t = -r.origin.z / r.direction.z;
      const glm::vec3 p = r.origin + t * r.direction;
      EXPECT_LT(glm::length(g.position.pixels[i] - p), 2e-3f);
      EXPECT_NEAR(g.uv.pixels[i].x, (p.x + 2) / 4, 1e-3f);
      EXPECT_NEAR(g.uv.pixels[i].y, (p.y + 1) / 2, 1e-3f);
      EXPECT_LT(glm::length(g.normal.pixels[i] - mapped), 1e-5f);
      EXPECT_EQ(g.surface.pixels[i].base_color, glm::vec3(0.5f, 0.25f, 1.0f));
      EXPECT_EQ(g.reflector.pixels[i], kNoId);  // rough dielectric: not a reflector
      ++checked;
    }
  EXPECT_GT(checked, std::size_t(w * h / 3));
}

}  // namespace
}  // namespace speculum::raster
