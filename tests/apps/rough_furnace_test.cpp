// The white furnace through a whole rasterized frame: a white dielectric sphere too rough
// for any reflection pass, under a uniform environment of radiance L, shades to L — the
// direct_light node's ambient diffuse (1 − E) L and its prefiltered rough specular E L
// (core/shading.h) add up to what arrives, as the reference's do.
#include <gtest/gtest.h>

#include <cmath>

#include "apps/techniques/render_frame.h"
#include "apps/techniques/technique_table.h"
#include "parallel/executor.h"
#include "tests/trace/reference_scenes.h"

namespace speculum::pipeline {
namespace {

TEST(RoughFurnace, WhiteRoughSphereShadesToTheEnvironmentRadiance) {
  const float L = 0.6f;
  for (float roughness : {1.0f, 0.8f, 0.6f}) {
    Scene s;
    s.name = "rough-furnace";
    const auto m = trace::testing::add_material(s, glm::vec3(1.0f), 0.0f, roughness);
    trace::testing::add_sphere(s, glm::vec3(0.0f), 1.0f, 48, 96, m);
    s.objects.push_back(Object{"sphere", 0, static_cast<std::uint32_t>(s.mesh.triangle_count()), m});
    s.environment.constant = glm::vec3(L);
    FrameSettings f;
    f.width = 16;
    f.height = 16;
    f.camera.eye = {0, 0, 4};
    f.camera.target = {0, 0, 0};
    f.camera.vfov_degrees = 14;  // the sphere covers the whole image
    par::Executor ex(2);
    for (const char* technique : {"envmap", "distance-map"}) {
      const ImageRGBA img = render_frame(s, find_technique(technique), f, ex).radiance;
      for (const glm::vec4& p : img.pixels)
        EXPECT_NEAR(p.x, L, 0.02f * L) << technique << " roughness " << roughness;
    }
  }
}

}  // namespace
}  // namespace speculum::pipeline
