// Tests of layered distance maps (SURVEY §4.5): the peeled layers against the rasterized
// cube map and their ordering, fewer errors with more layers on an occluded set-up (against
// the reference tracer), and thread-count independence.
#include "raster/layered_distance_map.h"

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "apps/techniques/render_frame.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"

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

pipeline::FrameSettings small_frame(const Scene& s) {
  pipeline::FrameSettings f;
  f.width = 96;
  f.height = 72;
  f.shadow_map_size = 256;
  f.camera = s.cameras.front();
  f.params["layer_size"] = 64;
  return f;
}

ImageRGBA frame(const Scene& s, const std::string& t, const pipeline::FrameSettings& f,
                int threads = 2) {
  par::Executor ex(threads);
  return pipeline::render_frame(s, pipeline::find_technique(t), f, ex).display;
}

TEST(LayeredDistanceMap, MoreLayersReduceTheErrorOnAnOccludedSetUp) {
  // sphere-in-room seen from the layered map's reference point: the big sphere and the box
  // hide parts of the room that the mirror spheres reflect.
  const Scene s = load_scene("sphere-in-room:size=4000");
  pipeline::FrameSettings f = small_frame(s);
  pipeline::FrameSettings ref = f;
  ref.spp = 4;
  ref.params.clear();  // the reference takes no technique parameters
  const ImageRGBA reference = frame(s, "reference", ref);
  f.params["layers"] = 1;
  const double one = image_error(frame(s, "layered-distance-map", f), reference).mae8;
  f.params["layers"] = 3;
  const double three = image_error(frame(s, "layered-distance-map", f), reference).mae8;
  EXPECT_LT(three, one);
  EXPECT_LT(three, 30.0) << "mae8 of the whole 96×72 frame against a 4-spp reference";
}

TEST(LayeredDistanceMap, SameBytesForOneAndTwoThreads) {
  const Scene s = load_scene("sphere-in-room:size=3000");
  const pipeline::FrameSettings f = small_frame(s);
  const ImageRGBA a = frame(s, "layered-distance-map", f, 1), b = frame(s, "layered-distance-map", f, 2);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.size() * sizeof(a.pixels[0])), 0);
}

}  // namespace
}  // namespace speculum::raster
