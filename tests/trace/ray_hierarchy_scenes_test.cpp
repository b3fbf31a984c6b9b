// Ray hierarchy on built-in scenes (ROGER §3.3, §3.3.5): G-buffer-like secondary
// rays (from primary hits), 1–3 bounces and the reversed shadow rays of every light; each
// generation's per-pixel closest hit (t, u, v, triangle) equals the all-pairs oracle bit for
// bit, and the whole run is byte-identical for 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "core/camera_rays.h"
#include "core/scene_loader.h"
#include "trace/bvh.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"

namespace speculum::trace {
namespace {

struct PrimaryPlanes {
  Buffer2D<glm::vec3> position, normal;
  SurfacePlane surface;  // every sample its own parameters
  IdBuffer object;
};

// What the G-buffer holds, from traced primary rays (trace tests do not use raster/):
// opaque normals facing the camera, refractor normals in their geometric orientation.
PrimaryPlanes primary_planes(const Scene& scene, const Bvh& bvh, const Camera& cam, int w, int h) {
  PrimaryPlanes g{{w, h}, {w, h}, SurfacePlane::per_sample(Buffer2D<SurfaceParams>(w, h)), {w, h, kNoId}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray r = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
      const Hit hit = closest_hit(bvh, r);
      if (!hit.hit()) continue;
      const HitSurface hs = hit_surface(scene, hit, r.direction);
      g.position.at(x, y) = hs.p;
      g.normal.at(x, y) = hs.s.is_refractor() && !hs.entering ? -hs.n : hs.n;
      g.surface.own.at(x, y) = hs.s;
      g.object.at(x, y) = scene.mesh.triangle_object[hit.triangle];
    }
  return g;
}

struct Counts {
  std::uint64_t rays = 0, hits = 0, shadow_rays = 0, shadowed = 0, later_bounce_rays = 0, overflow_batches = 0;
};

// All generations' hits concatenated (for the thread comparison).
struct RunBytes {
  std::vector<float> t;
  std::vector<std::uint32_t> tri;
  ImageRGBA specular;  // the shaded generations summed (the technique's specular layer)
};

RunBytes run_and_check(const Scene& scene, int w, int h, int bounces, int threads, Counts& counts,
                       std::size_t capacity = 0, bool check_oracle = true) {
  par::Executor ex(threads);
  const Bvh bvh = Bvh::build(scene.mesh, ex);
  const PrimaryPlanes g = primary_planes(scene, bvh, scene.cameras.front(), w, h);
  SecondaryRays gen = secondary_rays(ex, g.position, g.normal, g.surface, g.object, scene.cameras.front().eye);
  HierarchyTraverseOptions opt;
  if (capacity != 0) opt.pair_capacity = capacity;  // 0: the default (2048² pairs)
  RunBytes bytes;
  bytes.specular = ImageRGBA(w, h, glm::vec4(0.0f));
  auto trace_check = [&](const SecondaryRays& rays, HitStream& hits, bool shadow) {
    const RayHierarchy hi = build_ray_hierarchy(ex, rays.rays, rays.active, w, h);
    HierarchyTraverseStats stats;
    hierarchy_closest_hits(ex, scene.mesh.positions, scene.mesh.indices, hi, rays.rays, hits, opt, &stats);
    EXPECT_EQ(stats.level_passes, std::uint64_t(hi.levels) * stats.batches);
    counts.overflow_batches += stats.overflow_batches;
    bytes.t.insert(bytes.t.end(), hits.t.begin(), hits.t.end());
    bytes.tri.insert(bytes.tri.end(), hits.triangle.begin(), hits.triangle.end());
    for (std::size_t i = 0; i < rays.active.size(); ++i) {
      if (!rays.active[i]) {
        EXPECT_EQ(hits.triangle[i], kNoHit);
        continue;
      }
      (shadow ? counts.shadow_rays : counts.rays) += 1;
      (shadow ? counts.shadowed : counts.hits) += hits.triangle[i] != kNoHit;
      if (!check_oracle) continue;
      const Hit o = closest_hit_oracle(scene.mesh.positions, scene.mesh.indices, rays.rays.get(i));
      ASSERT_EQ(hits.triangle[i], o.triangle) << "pixel " << i << (shadow ? " (shadow)" : "");
      if (o.hit()) {
        EXPECT_EQ(std::memcmp(&hits.t[i], &o.t, 4), 0) << "pixel " << i;
        EXPECT_EQ(std::memcmp(&hits.u[i], &o.u, 4), 0);
        EXPECT_EQ(std::memcmp(&hits.v[i], &o.v, 4), 0);
      }
    }
  };
  for (int b = 0; b < bounces; ++b) {
    if (b > 0) counts.later_bounce_rays += gen.count;
    HitStream hits;
    trace_check(gen, hits, false);
    std::vector<HitStream> shadow_hits(scene.lights.size());
    for (std::size_t l = 0; l < scene.lights.size(); ++l) {
      const SecondaryRays sh = shadow_rays(ex, scene, scene.lights[l], gen, hits);
      trace_check(sh, shadow_hits[l], true);
    }
    shade_hits(ex, scene, gen, hits, shadow_hits, bytes.specular);
    gen = bounce_rays(ex, scene, gen, hits);
  }
  return bytes;
}

class RayHierarchyScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(RayHierarchyScenes, EveryGenerationEqualsOracle) {
  SceneOptions so;
  so.size = 1000;
  const Scene scene = load_scene(GetParam(), so);
  for (int bounces : {1, 3}) {
    Counts c;
    run_and_check(scene, 24, 18, bounces, 1, c);  // 24×18 pads to 32²
    EXPECT_GT(c.rays, 20u) << GetParam();
    EXPECT_GT(c.hits, 0u) << GetParam();
    if (bounces == 3 && GetParam() != "bumpy-sphere:n=4") {
      EXPECT_GT(c.later_bounce_rays, 0u) << GetParam();
    }
    if (!scene.lights.empty()) {
      EXPECT_GT(c.shadow_rays, 0u) << GetParam();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, RayHierarchyScenes,
                         ::testing::Values("sphere-in-room", "mirror-corridor", "glass-sphere",
                                           "bumpy-sphere:n=4", "living-room"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& ch : n)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return n;
                         });

TEST(RayHierarchyScenesDeterminism, TwoBouncesSameBytesForThreadsAndBatches) {
  SceneOptions so;
  so.size = 1000;
  const Scene scene = load_scene("mirror-corridor", so);
  Counts one, two, batched;
  const RunBytes a = run_and_check(scene, 32, 32, 2, 1, one, 0, false);
  const RunBytes b = run_and_check(scene, 32, 32, 2, 2, two, 0, false);
  // 4·32² pairs: a level of the ~1000-triangle stream overflows and the batch is split.
  const RunBytes c = run_and_check(scene, 32, 32, 2, 2, batched, 4096, false);
  EXPECT_EQ(one.overflow_batches, 0u);
  EXPECT_GT(batched.overflow_batches, 0u);
  EXPECT_GT(one.later_bounce_rays, 20u);  // the mirrors face each other: bounce 2 is traced
  EXPECT_GT(one.shadowed, 0u);
  EXPECT_EQ(a.tri, b.tri);
  EXPECT_EQ(a.tri, c.tri);
  ASSERT_EQ(a.t.size(), b.t.size());
  EXPECT_EQ(std::memcmp(a.t.data(), b.t.data(), a.t.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.t.data(), c.t.data(), a.t.size() * 4), 0);
  // The shaded specular layer: byte-identical across threads and batching, and not black.
  const std::size_t bytes = a.specular.size() * sizeof(glm::vec4);
  EXPECT_EQ(std::memcmp(a.specular.pixels.data(), b.specular.pixels.data(), bytes), 0);
  EXPECT_EQ(std::memcmp(a.specular.pixels.data(), c.specular.pixels.data(), bytes), 0);
  double sum = 0;
  for (const glm::vec4& p : a.specular.pixels) sum += p.x + p.y + p.z;
  EXPECT_GT(sum, 0.0);
}

// ROGER §3.4 (Fig.3.17) keeps 2.5–4.5 candidates per ray, about the polygons each ray
// intersects; the leaf test brings sphere-in-room (its default tessellation, one reflected
// ray per reflector pixel at 64²) to at most that, with every hit still the oracle's.
TEST(RayHierarchyScenesCandidates, SphereInRoomAtMostFourAndAHalfPerRay) {
  const Scene scene = load_scene("sphere-in-room", SceneOptions{});
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(scene.mesh, ex);
  const int w = 64, h = 64;
  const PrimaryPlanes g = primary_planes(scene, bvh, scene.cameras.front(), w, h);
  const SecondaryRays rays = secondary_rays(ex, g.position, g.normal, g.surface, g.object, scene.cameras.front().eye);
  const RayHierarchy hi = build_ray_hierarchy(ex, rays.rays, rays.active, w, h);
  HitStream hits;
  HierarchyTraverseStats stats;
  hierarchy_closest_hits(ex, scene.mesh.positions, scene.mesh.indices, hi, rays.rays, hits, {}, &stats);
  EXPECT_GT(stats.active_rays, 500u);
  EXPECT_LE(stats.candidates_per_ray(), 4.5);
  EXPECT_GE(stats.candidates, stats.hits);  // every hit ray keeps at least its hit triangle
  for (std::size_t i = 0; i < rays.active.size(); ++i) {
    if (!rays.active[i]) continue;
    const Hit o = closest_hit_oracle(scene.mesh.positions, scene.mesh.indices, rays.rays.get(i));
    ASSERT_EQ(hits.triangle[i], o.triangle) << "pixel " << i;
    if (o.hit()) {
      EXPECT_EQ(std::memcmp(&hits.t[i], &o.t, 4), 0) << "pixel " << i;
    }
  }
}

}  // namespace
}  // namespace speculum::trace
