// End to end `--technique yu-lod` (YU §3.5) on glossy-plane: the error against the reference
// tracer falls as N grows, LOD stays close to LOD off, and the frame is the same bytes for
// 1 and 2 threads.
#include <cstring>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "raster/composite.h"
#include "trace/reference_tracer.h"

namespace speculum {
namespace {

struct Fixture {
  Scene scene = load_scene("glossy-plane:size=2000");
  pipeline::FrameSettings frame(int n, float alpha) const {
    pipeline::FrameSettings f;
    f.width = 80;
    f.height = 60;
    f.spp = n;
    f.alpha = alpha;
    f.camera = scene.cameras.front();
    f.params["env_samples"] = 16;
    return f;
  }
  ImageRGBA render(int n, float alpha, par::Executor& ex) const {
    return pipeline::render_frame(scene, pipeline::find_technique("yu-lod"), frame(n, alpha), ex).display;
  }
  ImageRGBA reference(par::Executor& ex) const {
    trace::ReferenceOptions o;
    o.width = 80;
    o.height = 60;
    o.spp = 256;
    o.seed = 99;
    return raster::tonemap(ex, trace::render_reference(scene, scene.cameras.front(), o, ex));
  }
};

TEST(YuEndToEnd, ErrorAgainstTheReferenceFallsAsNGrows) {
  par::Executor ex(2);
  const Fixture fx;
  const ImageRGBA ref = fx.reference(ex);
  const double e1 = image_error(fx.render(1, 0.0f, ex), ref).rmse;
  const double e4 = image_error(fx.render(4, 0.0f, ex), ref).rmse;
  const double e32 = image_error(fx.render(32, 0.0f, ex), ref).rmse;
  EXPECT_LT(e4, e1);
  EXPECT_LT(e32, e4);
  EXPECT_LT(e32, 0.8 * e1);
  // LOD (α = 10) stays near LOD off at the same N.
  const double lod32 = image_error(fx.render(32, 10.0f, ex), ref).psnr;
  EXPECT_GT(lod32, image_error(fx.render(32, 0.0f, ex), ref).psnr - 1.5);
}

TEST(YuEndToEnd, SameBytesForOneAndTwoThreads) {
  const Fixture fx;
  par::Executor one(1), two(2);
  for (float alpha : {0.0f, 3.0f}) {
    const pipeline::Technique& t = pipeline::find_technique("yu-lod");
    const auto a = pipeline::render_frame(fx.scene, t, fx.frame(6, alpha), one);
    const auto b = pipeline::render_frame(fx.scene, t, fx.frame(6, alpha), two);
    ASSERT_EQ(a.radiance.size(), b.radiance.size());
    EXPECT_EQ(0, std::memcmp(a.radiance.pixels.data(), b.radiance.pixels.data(),
                             a.radiance.size() * sizeof(glm::vec4)))
        << "alpha " << alpha;
    EXPECT_EQ(a.report.find("lod_trace")->counters, b.report.find("lod_trace")->counters);
  }
}

}  // namespace
}  // namespace speculum
