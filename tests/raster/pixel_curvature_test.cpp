// Tests of the `pixel_curvature` node: a tessellated sphere's visible samples read its mean
// curvature 1/r seen from outside and −1/r seen from inside (the per-vertex cotangent values
// interpolated with the visibility buffer's barycentrics).
#include "raster/pixel_curvature.h"

#include <cmath>

#include <gtest/gtest.h>

#include "core/mesh_processing/mean_curvature.h"
#include "core/procedural_geometry.h"

namespace speculum::raster {
namespace {

Scene sphere_scene(float radius, int rings) {
  procedural::SceneBuilder b("sphere");
  const auto mat = b.add_material(procedural::mirror("m"));
  b.add_object("ball", mat, procedural::sphere({0.5f, -0.25f, 0.0f}, radius, rings));
  return b.take();
}

struct Stats {
  std::size_t samples = 0;
  double max_rel = 0.0, mean = 0.0;
};

Stats measure(const Scene& s, const Camera& cam, double want) {
  par::Executor ex(2);
  const int w = 96, h = 72;
  const VisibilityBuffer vis = render_visibility(ex, s, cam, w, h);
  const ImageF k = pixel_mean_curvature(ex, s, mesh::scene_mean_curvature(s), vis, cam.eye);
  Stats st;
  for (std::size_t i = 0; i < k.pixels.size(); ++i) {
    if (vis.triangle.pixels[i] == kNoId) {
      EXPECT_EQ(k.pixels[i], 0.0f);
      continue;
    }
    ++st.samples;
    st.mean += k.pixels[i];
    st.max_rel = std::max(st.max_rel, std::fabs(k.pixels[i] - want) / std::fabs(want));
  }
  if (st.samples) st.mean /= double(st.samples);
  return st;
}

TEST(PixelCurvature, SphereSeenFromOutsideReadsOneOverR) {
  // 64 rings (~16K triangles): the cotangent operator is within 2% of 1/r at every vertex of
  // a UV sphere this fine (its error shrinks with the ring count, mesh_processing_test), and a
  // barycentric blend of three such values stays within the same bound.
  const float r = 2.0f;
  const Scene s = sphere_scene(r, 64);
  Camera cam;
  cam.eye = {0.5f, 1.0f, 9.0f};
  cam.target = {0.5f, -0.25f, 0.0f};
  const Stats st = measure(s, cam, 1.0 / r);
  EXPECT_GT(st.samples, 1000u);
  EXPECT_LT(st.max_rel, 0.02) << "mean " << st.mean;
  EXPECT_NEAR(st.mean, 1.0 / r, 0.005 / r);
}

TEST(PixelCurvature, SphereSeenFromInsideIsNegative) {
  // From inside the same sphere bends towards the viewer: −1/r.
  const float r = 3.0f;
  const Scene s = sphere_scene(r, 64);
  Camera cam;
  cam.eye = {0.5f, -0.25f, 1.0f};
  cam.target = {0.5f, -0.25f, -3.0f};
  const Stats st = measure(s, cam, -1.0 / r);
  EXPECT_EQ(st.samples, 96u * 72u);
  EXPECT_LT(st.max_rel, 0.02) << "mean " << st.mean;
}

}  // namespace
}  // namespace speculum::raster
