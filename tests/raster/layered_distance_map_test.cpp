// Tests of layered distance maps (SURVEY §4.5): the peeled layers against the rasterized
// cube map and their ordering, fewer errors with more layers on an occluded set-up (against
// the reference tracer), and thread-count independence.
#include "raster/layered_distance_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "tests/raster/frame_test_util.h"

namespace speculum::raster {
namespace {

TEST(LayeredDistanceMap, FirstLayerIsTheRasterizedCubeMapAndLayersAreOrdered) {
  const Scene s = load_scene("sphere-in-room:size=3000");
  par::Executor ex(2);
  const EnvironmentMap env = build_environment(ex, s.environment, 8);
  const glm::vec3 centre(1.9f, 3.0f, 2.3f);
  LayeredMapOptions o;
  o.size = 48;
  o.layers = 3;
  const LayeredDistanceMap layered = render_layered_distance_map(ex, s, centre, {}, env, o);
  CubeMapOptions co;
  co.size = o.size;
  const CubeMap cube = render_cube_map(ex, s, centre, co);
  std::size_t agree = 0, total = 0, second_layer = 0;
  for (int face = 0; face < kCubeFaces; ++face)
    for (std::size_t i = 0; i < cube.distance[face].size(); ++i) {
      const float a = layered.layers[0].distance[face].pixels[i], b = cube.distance[face].pixels[i];
      ++total;
      agree += std::abs(a - b) <= 1e-3f * b;
      const float d1 = layered.layers[1].distance[face].pixels[i];
      const float d2 = layered.layers[2].distance[face].pixels[i];
      EXPECT_LE(a, d1);
      EXPECT_LE(d1, d2);
      second_layer += std::isfinite(d1);
    }
  // Texels differ only where an edge falls between the two rasterizers' coverage rules.
  EXPECT_GT(double(agree), 0.99 * double(total));
  // The spheres and the box cover about 8% of the directions from this point.
  EXPECT_GT(second_layer, total / 20) << "surfaces behind surfaces";
}

pipeline::FrameSettings small_layered_frame(const Scene& s) {
  pipeline::FrameSettings f;
  f.width = 96;
  f.height = 72;
  f.shadow_map_size = 256;
  f.camera = s.cameras.front();
  f.params["layer_size"] = 64;
  return f;
}

// Mean absolute difference (display values × 255) over the pixels where `mask_a` and
// `mask_b` differ: the pixels a change of the technique's parameter affects.
double error_where_they_differ(const ImageRGBA& img, const ImageRGBA& reference, const ImageRGBA& mask_a,
                               const ImageRGBA& mask_b, std::size_t* count) {
  double sum = 0.0;
  *count = 0;
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    const glm::vec4 d = glm::abs(mask_a.pixels[i] - mask_b.pixels[i]);
    if (std::max({d.x, d.y, d.z}) * 255.0f < 1.0f) continue;
    const glm::vec4 e = glm::abs(img.pixels[i] - reference.pixels[i]) * 255.0f;
    sum += (e.x + e.y + e.z) / 3.0;
    ++*count;
  }
  return *count ? sum / double(*count) : 0.0;
}

TEST(LayeredDistanceMap, MoreLayersReduceTheErrorOnAnOccludedSetUp) {
  // sphere-in-room seen from the layered map's reference point: the big sphere and the box
  // hide parts of the room that the mirror spheres reflect. Measured where the layer count
  // changes the image (the whole frame's error is dominated by what both share).
  const Scene s = load_scene("sphere-in-room:size=4000");
  pipeline::FrameSettings f = small_layered_frame(s);
  f.width = 192;
  f.height = 144;
  f.params["layer_size"] = 128;
  pipeline::FrameSettings ref = f;
  ref.spp = 4;
  ref.params.clear();  // the reference takes no technique parameters
  const ImageRGBA reference = render_display(s, "reference", ref);
  f.params["layers"] = 1;
  const ImageRGBA img_one = render_display(s, "layered-distance-map", f);
  f.params["layers"] = 3;
  const ImageRGBA img_three = render_display(s, "layered-distance-map", f);
  std::size_t changed = 0;
  const double one = error_where_they_differ(img_one, reference, img_one, img_three, &changed);
  const double three = error_where_they_differ(img_three, reference, img_one, img_three, &changed);
  EXPECT_GT(changed, 20u) << "the extra layers must change the image";
  EXPECT_LT(three, one) << changed << " pixels changed";
  EXPECT_LT(image_error(img_three, reference).mae8, 30.0) << "mae8 of the whole 192×144 frame against a 4-spp reference";
}

TEST(LayeredDistanceMap, SameBytesForOneAndTwoThreads) {
  const Scene s = load_scene("sphere-in-room:size=3000");
  const pipeline::FrameSettings f = small_layered_frame(s);
  const ImageRGBA a = render_display(s, "layered-distance-map", f, 1), b = render_display(s, "layered-distance-map", f, 2);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.size() * sizeof(a.pixels[0])), 0);
}

}  // namespace
}  // namespace speculum::raster
