// Shading benchmarks: the per-sample kernels every feed-forward frame runs, on the
// living-room scene at 640×480 from its main camera — the direct light of the camera's
// G-buffer (three lights with filtered shadow maps, SH ambient, rough lobes' environment
// lookups), the glossy prefiltering cascade of one 256² reflector map (six random faces), and
// the camera's distance-map searches (the distance-map technique's maps of every reflector).
// 1 and 2 threads. Counters: Msamples_s (shaded samples or prefiltered texels per second),
// Msearches_s.
#include <benchmark/benchmark.h>

#include <array>
#include <random>

#include "core/procedural_scenes.h"
#include "raster/direct_light.h"
#include "raster/distance_map_reflect.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace {
using namespace speculum;
using namespace speculum::raster;

par::Executor& executor(int threads) {
  static par::Executor one(1), two(2);
  static const bool quiet = (one.set_recording(false), two.set_recording(false), true);
  (void)quiet;
  return threads == 1 ? one : two;
}

// The living room's camera view, shadow maps and environment, built once.
struct LivingRoomView {
  Scene scene;
  Camera camera;
  GBuffer gbuffer;
  ShadowMaps shadows;
  EnvironmentMap environment;
};

const LivingRoomView& living_room() {
  static const LivingRoomView view = [] {
    LivingRoomView v;
    const BuiltinScene* builtin = find_builtin_scene("living-room");
    BuiltinParams params;
    params.size = builtin->default_size;
    v.scene = builtin->build(params);
    v.camera = v.scene.cameras.front();
    par::Executor& ex = executor(2);
    const VisibilityBuffer vis = render_visibility(ex, v.scene, v.camera, 640, 480);
    v.gbuffer = resolve_gbuffer(ex, v.scene, vis, v.camera.eye);
    v.shadows = render_shadow_maps(ex, v.scene, 512);
    v.environment = build_environment(ex, v.scene.environment);
    return v;
  }();
  return view;
}

void BM_DirectLight(benchmark::State& state) {
  const LivingRoomView& v = living_room();
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    ImageRGBA out = direct_light(ex, v.scene, v.gbuffer, v.camera, v.shadows, v.environment);
    benchmark::DoNotOptimize(out.pixels.data());
  }
  state.counters["Msamples_s"] =
      benchmark::Counter(double(v.gbuffer.width) * v.gbuffer.height * double(state.iterations()) / 1e6,
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DirectLight)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_PrefilterCascade(benchmark::State& state) {
  constexpr int kSide = 256;
  std::array<ImageRGBA, kCubeFaces> faces;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  for (ImageRGBA& f : faces) {
    f = ImageRGBA(kSide, kSide);
    for (glm::vec4& p : f.pixels) p = glm::vec4(u(rng), u(rng), u(rng), 1.0f);
  }
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  constexpr int kLevels = 5;  // what a 256² glossy map of roughness 0.15 is read with
  double texels = 0.0;
  for (int l = 1; l < kLevels; ++l) texels += 6.0 * (kSide >> l) * (kSide >> l);
  for (auto _ : state) {
    // The call takes its level-0 faces by value: their 6 MB copy (about a millisecond) is
    // timed with the cascade.
    EnvironmentMap map = environment_from_faces(ex, faces, false, kLevels);
    benchmark::DoNotOptimize(map.levels.data());
  }
  state.counters["Msamples_s"] = benchmark::Counter(texels * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PrefilterCascade)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_DistanceMapSearch(benchmark::State& state) {
  const LivingRoomView& v = living_room();
  static const ReflectorMaps distances =
      render_reflector_maps(executor(2), v.scene, {}, {}, 256, &v.gbuffer, ReflectorSelection::all, {}, nullptr,
                            searched_distance_maps(true, true));
  par::Executor& ex = executor(static_cast<int>(state.range(0)));
  std::uint64_t searches = 0;
  for (auto _ : state) {
    const DistanceSearches found = distance_map_search(ex, v.gbuffer, distances, DistanceSearchOptions{}, nullptr);
    searches += found.stats.searches;
    benchmark::DoNotOptimize(found.found.data());
  }
  state.counters["Msearches_s"] = benchmark::Counter(double(searches) / 1e6, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DistanceMapSearch)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
