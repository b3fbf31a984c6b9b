// Tests of planar mirrors by geometry transformation (SURVEY §5): the mirrored camera sees
// exactly the reflected rays, clipping conserves area, the technique matches the reference
// tracer up to rasterization, two facing mirrors show k images weighted F^k, and the
// output is the same for 1 and 2 threads.
#include "raster/planar_mirror.h"

#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "apps/techniques/technique_table.h"
#include "apps/techniques/render_frame.h"
#include "core/camera_rays.h"
#include "core/optics.h"
#include "core/scene_loader.h"
#include "raster/shadow_map.h"
#include "raster_test_scenes.h"
#include "trace/reference_tracer.h"

namespace speculum::raster {
namespace {

using testing::add_triangles;

// An axis-aligned quad [lo, hi] in the plane perpendicular to `axis`, wound so its
// geometric normal points along +axis (sign > 0) or −axis.
void add_quad(Scene& s, int axis, float at, glm::vec2 lo, glm::vec2 hi, float sign,
              std::uint32_t material) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  auto p = [&](float a, float b) {
    glm::vec3 q(0.0f);
    q[axis] = at;
    q[u] = a;
    q[v] = b;
    return q;
  };
  std::vector<glm::vec3> pts = {p(lo.x, lo.y), p(hi.x, lo.y), p(hi.x, hi.y), p(lo.x, hi.y)};
  if (sign < 0) std::swap(pts[1], pts[3]);
  add_triangles(s, pts, {0, 1, 2, 0, 2, 3}, {}, material);
  auto& m = s.mesh;
  const glm::vec3 n = glm::normalize(glm::cross(pts[1] - pts[0], pts[2] - pts[0]));
  for (std::size_t i = m.normals.size() - 4; i < m.normals.size(); ++i) m.normals[i] = n;
}

Material emitter(glm::vec3 e) {
  Material m;
  m.base_color = glm::vec4(0, 0, 0, 1);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  m.emissive = e;
  return m;
}

Material mirror_material(float reflectance) {
  Material m;
  m.base_color = glm::vec4(glm::vec3(reflectance), 1.0f);
  m.metallic = 1.0f;
  m.roughness = 0.0f;
  return m;
}

double triangle_area(const TriangleMesh& m, std::size_t t) {
  const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
      c(m.positions[m.indices[3 * t + 2]]);
  return 0.5 * glm::length(glm::cross(b - a, c - a));
}

TEST(PlanarMirror, MirroredCameraSeesTheReflectedRaysLeftRightMirrored) {
  Camera cam;
  cam.eye = {0.3f, 1.2f, 4.0f};
  cam.target = {-0.5f, 0.8f, -1.0f};
  Plane plane{glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f)), -2.0f};
  const Camera m = mirrored_camera(cam, plane);
  const int w = 40, h = 30;
  for (int y = 0; y < h; y += 7)
    for (int x = 0; x < w; x += 5) {
      const Ray r = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
      const Ray q = primary_ray(m, w, h, (w - 1 - x) + 0.5f, y + 0.5f);
      const glm::vec3 expected = glm::normalize(plane.reflect_direction(r.direction));
      EXPECT_LT(glm::length(glm::normalize(q.direction) - expected), 1e-5f) << x << "," << y;
      EXPECT_LT(glm::length(q.origin - plane.reflect_point(r.origin)), 1e-5f);
    }
}

TEST(PlanarMirror, ClippingKeepsOneSideAndConservesArea) {
  Scene s = load_scene("sphere-in-room:size=3000");
  const Plane plane{glm::normalize(glm::vec3(1.0f, 0.3f, -0.2f)), 0.4f};
  const Scene front = clip_scene_to_half_space(s, plane, 1.0f);
  const Scene back = clip_scene_to_half_space(s, plane, -1.0f);
  double area = 0, split = 0;
  for (std::size_t t = 0; t < s.mesh.triangle_count(); ++t) area += triangle_area(s.mesh, t);
  for (const Scene* c : {&front, &back})
    for (std::size_t t = 0; t < c->mesh.triangle_count(); ++t) split += triangle_area(c->mesh, t);
  EXPECT_NEAR(split, area, 1e-4 * area);  // no slivers lost or duplicated
  for (std::size_t v : front.mesh.indices) EXPECT_GE(plane.signed_distance(front.mesh.positions[v]), -1e-5f);
  for (std::size_t v : back.mesh.indices) EXPECT_LE(plane.signed_distance(back.mesh.positions[v]), 1e-5f);
  // Objects keep contiguous ranges covering every kept triangle.
  std::size_t covered = 0;
  for (const Object& o : front.objects) covered += o.triangle_count;
  EXPECT_EQ(covered, front.mesh.triangle_count());
}

TEST(PlanarMirror, FindsTheCorridorMirrorsOnly) {
  const Scene s = load_scene("mirror-corridor:size=4000");
  const auto mirrors = find_planar_mirrors(s);
  ASSERT_EQ(mirrors.size(), 2u);
  for (const PlanarMirror& m : mirrors) {
    EXPECT_NEAR(std::abs(m.plane.normal.x), 1.0f, 1e-5f);
    EXPECT_NEAR(std::abs(m.plane.offset), 2.0f, 1e-5f);
  }
  // The mirror spheres of sphere-in-room are not planar.
  EXPECT_TRUE(find_planar_mirrors(load_scene("sphere-in-room:size=3000")).empty());
}

// Emissive quads in front of a mirror, no lights, black environment: the radiance is
// emission and mirrored emission only, so raster and reference differ only where a pixel
// centre lands on the other side of an edge.
Scene emissive_mirror_scene() {
  Scene s;
  s.name = "emissive mirror";
  s.materials = {mirror_material(0.8f), emitter({0.9f, 0.2f, 0.1f}), emitter({0.1f, 0.6f, 0.9f}),
                 emitter({0.4f, 0.4f, 0.4f})};
  add_quad(s, 2, -2.0f, {-2.0f, -1.5f}, {2.0f, 1.5f}, 1.0f, 0);   // mirror, facing +z
  add_quad(s, 1, -1.5f, {-2.0f, -2.0f}, {2.0f, 4.0f}, 1.0f, 3);   // floor (y = -1.5)
  add_quad(s, 2, 0.0f, {-1.2f, -1.0f}, {-0.2f, 0.2f}, 1.0f, 1);    // red panel
  add_quad(s, 0, 0.8f, {-1.0f, -1.5f}, {0.5f, 0.5f}, -1.0f, 2);    // blue panel facing -x
  s.environment.constant = glm::vec3(0.0f);
  s.cameras.push_back(Camera{});
  return s;
}

Camera emissive_camera() {
  Camera c;
  c.eye = {1.6f, 0.4f, 3.5f};
  c.target = {-0.2f, -0.2f, -2.0f};
  c.vfov_degrees = 50.0f;
  return c;
}

pipeline::FrameSettings small_settings(const Camera& c, int depth) {
  pipeline::FrameSettings f;
  f.width = 96;
  f.height = 72;
  f.camera = c;
  f.shadow_map_size = 64;
  f.environment_size = 8;
  f.params["depth"] = depth;
  return f;
}

TEST(PlanarMirror, MatchesTheReferenceTracerUpToRasterization) {
  const Scene s = emissive_mirror_scene();
  const auto f = small_settings(emissive_camera(), 2);
  par::Executor ex(2);
  const auto frame = pipeline::render_frame(s, pipeline::find_technique("planar-mirror"), f, ex);
  trace::ReferenceOptions o;
  o.width = f.width;
  o.height = f.height;
  o.spp = 1;
  o.max_depth = 2;
  o.environment_lighting = false;
  const ImageRGBA ref = trace::render_reference(s, f.camera, o, ex);
  // A differing pixel must sit on an edge of the reference image (a 4-neighbour differs).
  const auto differs = [](const glm::vec4& a, const glm::vec4& b) {
    return glm::length(glm::vec3(a) - glm::vec3(b)) > 1e-3f;
  };
  int diff = 0, off_edge = 0, lit = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const glm::vec4 r = ref.at(x, y);
      if (glm::length(glm::vec3(r)) > 0.0f) ++lit;
      if (!differs(frame.radiance.at(x, y), r)) continue;
      ++diff;
      bool edge = false;
      for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int nx = x + dx, ny = y + dy;
        if (nx >= 0 && ny >= 0 && nx < f.width && ny < f.height && differs(ref.at(nx, ny), r)) edge = true;
      }
      if (!edge) ++off_edge;
    }
  const int pixels = f.width * f.height;
  EXPECT_GT(lit, pixels / 3);  // the set-up really shows emitters
  // Threshold: at most 4% of pixels differ, and every differing pixel is an edge pixel.
  EXPECT_LT(diff, pixels * 4 / 100) << "differing pixels";
  EXPECT_EQ(off_edge, 0) << "differing pixels away from any edge (of " << diff << ")";
}

// Two parallel mirrors of reflectance 0.5 (x = ±2) face each other; the camera between
// them looks at mirror A (x = −2) head-on; an emissive bar just behind the camera is seen
// only through the mirrors: the image after j bounces has radiance 0.5^j E (virtual bars
// at x = −3, −9, −11, −17, separated on screen). Schlick's (1−cosθ)^5 < 1e-9 at these
// angles, so F = 0.5 to float precision. Threshold: pixel values equal 0.5^j within 1e-5.
TEST(PlanarMirror, TwoFacingMirrorsShowKImagesAttenuatedByFk) {
  Scene s;
  s.name = "facing mirrors";
  s.materials = {mirror_material(0.5f), emitter(glm::vec3(1.0f))};
  s.materials[1].double_sided = true;
  add_quad(s, 0, -2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, 1.0f, 0);  // mirror A facing +x
  add_quad(s, 0, 2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, -1.0f, 0);  // mirror B facing -x
  add_quad(s, 0, -1.0f, {0.15f, -0.3f}, {0.18f, 0.3f}, -1.0f, 1);    // bar behind the camera
  s.environment.constant = glm::vec3(0.0f);
  Camera c;
  c.eye = {-1.5f, 0.0f, 0.0f};
  c.target = {-2.0f, 0.0f, 0.0f};
  c.vfov_degrees = 14.5f;
  par::Executor ex(2);
  for (int k = 1; k <= 4; ++k) {
    auto f = small_settings(c, k);
    f.width = 64;
    f.height = 320;
    const auto frame = pipeline::render_frame(s, pipeline::find_technique("planar-mirror"), f, ex);
    std::vector<int> per_level(static_cast<std::size_t>(k) + 1, 0);
    int other = 0;
    for (const glm::vec4& p : frame.radiance.pixels) {
      if (glm::vec3(p) == glm::vec3(0.0f)) continue;
      int level = -1;
      for (int j = 1; j <= k; ++j)
        if (std::abs(p.x - std::pow(0.5f, float(j))) < 1e-5f && p.x == p.y && p.y == p.z) level = j;
      if (level < 0) ++other;
      else ++per_level[static_cast<std::size_t>(level)];
    }
    EXPECT_EQ(other, 0) << "k=" << k << ": pixels that are no 0.5^j image";
    for (int j = 1; j <= k; ++j)
      EXPECT_GT(per_level[static_cast<std::size_t>(j)], 0) << "k=" << k << " image " << j;
  }
}

TEST(PlanarMirror, SameBytesForOneAndTwoThreads) {
  const Scene s = load_scene("mirror-corridor:size=3000");
  auto f = small_settings(s.cameras.front(), 3);
  par::Executor one(1), two(2);
  const auto a = pipeline::render_frame(s, pipeline::find_technique("planar-mirror"), f, one);
  const auto b = pipeline::render_frame(s, pipeline::find_technique("planar-mirror"), f, two);
  ASSERT_EQ(a.radiance.size(), b.radiance.size());
  EXPECT_EQ(0, std::memcmp(a.radiance.pixels.data(), b.radiance.pixels.data(),
                           a.radiance.size() * sizeof(glm::vec4)));
}

// Four mirrors around the camera see each other, so the views multiply (up to 3 per view per
// level): the recursion renders at most max_views of them, counts the rest, and the budget
// is spent in a fixed order (the same bytes and counts on 1 and 2 threads); below the budget
// nothing changes.
TEST(PlanarMirror, MirrorsThatSeeEachOtherStopAtTheViewBudget) {
  Scene s;
  s.name = "mirror box";
  s.materials = {mirror_material(0.9f), emitter(glm::vec3(1.0f))};
  add_quad(s, 0, -2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, 1.0f, 0);   // facing +x
  add_quad(s, 0, 2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, -1.0f, 0);   // facing -x
  add_quad(s, 2, -2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, 1.0f, 0);   // facing +z
  add_quad(s, 2, 2.0f, {-20.0f, -20.0f}, {20.0f, 20.0f}, -1.0f, 0);   // facing -z
  add_quad(s, 1, -1.0f, {-0.3f, -0.3f}, {0.3f, 0.3f}, 1.0f, 1);      // a lamp on the floor
  s.environment.constant = glm::vec3(0.1f);
  Camera c;
  c.eye = {0.3f, 0.0f, 0.2f};
  c.target = {-2.0f, -0.2f, -2.0f};  // into a corner: two mirrors in view
  c.vfov_degrees = 60.0f;
  const auto mirrors = find_planar_mirrors(s);
  ASSERT_EQ(mirrors.size(), 4u);
  const auto run = [&](par::Executor& ex, int depth, int max_views, PlanarMirrorStats& stats) {
    const GBuffer g = resolve_gbuffer(ex, s, render_visibility(ex, s, c, 24, 16), c.eye);
    const EnvironmentMap env = build_environment(ex, s.environment, 8);
    PlanarMirrorSettings settings;
    settings.depth = depth;
    settings.width = 24;
    settings.height = 16;
    settings.max_views = max_views;
    return planar_mirror_reflect(ex, s, mirrors, g, c, {}, env, nullptr, settings, &stats);
  };
  par::Executor one(1), two(2);
  PlanarMirrorStats free_stats, budget_stats, budget_stats2;
  const ImageRGBA free = run(two, 3, 1 << 20, free_stats);
  EXPECT_GT(free_stats.mirrored_views, 8u);  // the views multiply
  EXPECT_EQ(free_stats.views_over_budget, 0u);
  // A budget the recursion does not reach changes nothing.
  PlanarMirrorStats same_stats;
  const ImageRGBA same = run(two, 3, static_cast<int>(free_stats.mirrored_views), same_stats);
  EXPECT_EQ(same_stats.views_over_budget, 0u);
  EXPECT_EQ(0, std::memcmp(free.pixels.data(), same.pixels.data(), free.size() * sizeof(glm::vec4)));
  // A budget it does reach: exactly that many views, the rest counted.
  const int budget = static_cast<int>(free_stats.mirrored_views / 2);
  const ImageRGBA a = run(one, 3, budget, budget_stats);
  const ImageRGBA b = run(two, 3, budget, budget_stats2);
  EXPECT_EQ(budget_stats.mirrored_views, static_cast<std::uint64_t>(budget));
  EXPECT_GT(budget_stats.views_over_budget, 0u);
  EXPECT_EQ(budget_stats2.mirrored_views, budget_stats.mirrored_views);
  EXPECT_EQ(budget_stats2.views_over_budget, budget_stats.views_over_budget);
  EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.size() * sizeof(glm::vec4)));
  // Depth 8: more views than depth 3 (fewer than 3^8: a view renders only what its parent's
  // mirror shows, and the images of the corner shrink to nothing), and a budget bounds them.
  PlanarMirrorStats deep_free, deep;
  run(two, 8, 1 << 20, deep_free);
  EXPECT_GT(deep_free.mirrored_views, free_stats.mirrored_views);
  EXPECT_EQ(deep_free.views_over_budget, 0u);
  const int deep_budget = static_cast<int>(deep_free.mirrored_views / 2);
  run(two, 8, deep_budget, deep);
  EXPECT_EQ(deep.mirrored_views, static_cast<std::uint64_t>(deep_budget));
  EXPECT_GT(deep.views_over_budget, 0u);
}

// A mirrored view keeps only the samples its parent's mirror shows (sample (x, y) of the
// parent shows (w − 1 − x, y)): the others are background, so nothing lights or searches
// them; the kept ones are the whole view's.
TEST(PlanarMirror, MirroredViewsKeepOnlyTheSamplesTheirParentShows) {
  par::Executor ex(2);
  const Scene s = load_scene("mirror-corridor");
  const int w = 96, h = 72;
  const EnvironmentMap env = build_environment(ex, s.environment);
  const ShadowMaps shadows = render_shadow_maps(ex, s, 64);
  const auto mirrors = find_planar_mirrors(s);
  PlanarMirrorSettings settings;
  settings.depth = 2;
  std::vector<Camera> cameras{s.cameras.front()};  // per view
  const GBuffer g = resolve_gbuffer(ex, s, render_visibility(ex, s, cameras[0], w, h), cameras[0].eye);
  const PlanarMirrorViews views = planar_mirror_views(ex, s, mirrors, g, cameras[0], shadows, env, nullptr, settings);
  ASSERT_GT(views.views.size(), 2u);
  cameras.resize(views.views.size());
  for (std::size_t v = 0; v < views.views.size(); ++v) {
    const GBuffer& parent = v == 0 ? g : views.views[v].g;
    for (const auto& [k, child] : views.views[v].mirrored) {
      ASSERT_GT(child, v);  // depth-first: a view's children come after it
      const PlanarMirror& mirror = mirrors[k];
      cameras[child] = mirrored_camera(cameras[v], mirror.plane);
      const Scene& clipped = mirror.clipped_for(cameras[v].eye);
      const GBuffer whole = resolve_gbuffer(ex, clipped, render_visibility(ex, clipped, cameras[child], w, h),
                                            cameras[child].eye);
      const PlanarMirrorView& view = views.views[child];
      std::size_t kept = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const std::size_t i = static_cast<std::size_t>(y * w + x), flipped = static_cast<std::size_t>(y * w + w - 1 - x);
          const bool shown = parent.object.pixels[flipped] == mirror.object;
          kept += view.g.covered(i);
          if (shown) {
            ASSERT_EQ(view.g.object.pixels[i], whole.object.pixels[i]) << "view " << child << " sample " << x << "," << y;
            if (whole.covered(i)) {
              EXPECT_EQ(view.g.position.pixels[i], whole.position.pixels[i]);
            }
          } else {
            EXPECT_FALSE(view.g.covered(i)) << "view " << child << " sample " << x << "," << y;
            EXPECT_EQ(view.direct.pixels[i], glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
          }
        }
      EXPECT_GT(kept, 0u) << "view " << child;
    }
  }
}

// The curved reflectors' maps shaded only where the searches of every view (the camera's and
// the mirrored ones) read them give the same specular layer, byte for byte, as complete maps,
// with fewer texels shaded.
TEST(PlanarMirror, CurvedMapsShadedWhereTheViewsSearchChangeNoSample) {
  par::Executor ex(2);
  for (const char* name : {"living-room", "mirror-corridor"}) {
    SCOPED_TRACE(name);
    const Scene s = load_scene(name);
    const Camera c = s.cameras.front();
    const GBuffer g = resolve_gbuffer(ex, s, render_visibility(ex, s, c, 128, 96), c.eye);
    const EnvironmentMap env = build_environment(ex, s.environment);
    const ShadowMaps shadows = render_shadow_maps(ex, s, 128);
    const auto mirrors = find_planar_mirrors(s);
    ASSERT_FALSE(mirrors.empty());
    PlanarMirrorSettings settings;
    settings.depth = 2;
    const ReflectorMaps whole =
        render_reflector_maps(ex, s, shadows, env, 64, &g, ReflectorSelection::not_planar_mirrors);
    ASSERT_FALSE(whole.cubes.empty());
    PlanarMirrorStats whole_stats;
    const ImageRGBA expected = planar_mirror_reflect(ex, s, mirrors, g, c, shadows, env, &whole, settings, &whole_stats);
    const ReflectorMaps distances = render_reflector_maps(ex, s, shadows, env, 64, &g, ReflectorSelection::not_planar_mirrors,
                                                          {}, nullptr, searched_distance_maps(false, false));
    const PlanarMirrorViews views = planar_mirror_views(ex, s, mirrors, g, c, shadows, env, &distances, settings);
    EXPECT_GT(views.stats.mirrored_views, 0u);
    EXPECT_EQ(views.stats.mirrored_views, whole_stats.mirrored_views);
    EXPECT_EQ(views.stats.mirror_samples, whole_stats.mirror_samples);
    const ReflectorMaps shaded = shade_reflector_maps(ex, s, shadows, env, distances, views.tiles);
    EXPECT_LT(rendered_texels(shaded), rendered_texels(whole));
    const ImageRGBA got = planar_mirror_compose(ex, views, g, mirrors, env, &shaded);
    EXPECT_EQ(0, std::memcmp(expected.pixels.data(), got.pixels.data(), expected.size() * sizeof(glm::vec4)));
  }
}

}  // namespace
}  // namespace speculum::raster
