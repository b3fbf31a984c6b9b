// Planar mirrors by geometry transformation: see planar_mirror.h.
#include "raster/planar_mirror.h"

#include <cmath>
#include <optional>

#include "core/shading.h"
#include "raster/direct_light.h"
#include "raster/distance_map_reflect.h"
#include "raster/envmap_reflect.h"
#include "raster/visibility.h"

namespace speculum::raster {

std::optional<Plane> planar_mirror_plane(const Scene& scene, std::uint32_t o, float tolerance) {
  const TriangleMesh& m = scene.mesh;
  const Object& obj = scene.objects[o];
  if (obj.triangle_count == 0) return std::nullopt;
  // Every triangle must be a mirror (not only the first): a mixed object is not a mirror.
  glm::vec3 area_normal(0.0f);
  Bounds box;
  for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t) {
    const std::uint32_t mat = m.triangle_material[t];
    const SurfaceParams s = surface_params(scene.materials[mat < scene.materials.size() ? mat : 0]);
    if (s.is_refractor() || !s.is_mirror_lobe()) return std::nullopt;
    const glm::vec3 a = m.positions[m.indices[3 * t]], b = m.positions[m.indices[3 * t + 1]],
                    c = m.positions[m.indices[3 * t + 2]];
    area_normal += glm::cross(b - a, c - a);
    box.grow(a);
    box.grow(b);
    box.grow(c);
  }
  const float len = glm::length(area_normal);
  if (!(len > 0.0f)) return std::nullopt;
  Plane plane;
  plane.normal = area_normal / len;
  double offset = 0.0;
  std::size_t n = 0;
  for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
    for (int k = 0; k < 3; ++k, ++n) offset += glm::dot(plane.normal, m.positions[m.indices[3 * t + k]]);
  plane.offset = static_cast<float>(offset / static_cast<double>(n));
  const float limit = tolerance * glm::length(box.extent());
  for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
    for (int k = 0; k < 3; ++k)
      if (std::abs(plane.signed_distance(m.positions[m.indices[3 * t + k]])) > limit) return std::nullopt;
  return plane;
}

std::vector<PlanarMirror> find_planar_mirrors(const Scene& scene, float tolerance) {
  std::vector<PlanarMirror> mirrors;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const std::optional<Plane> plane = planar_mirror_plane(scene, o, tolerance);
    if (!plane) continue;
    PlanarMirror mirror;
    mirror.object = o;
    mirror.plane = *plane;
    mirror.front = clip_scene_to_half_space(scene, mirror.plane, 1.0f, o);
    mirror.back = clip_scene_to_half_space(scene, mirror.plane, -1.0f, o);
    mirrors.push_back(std::move(mirror));
  }
  return mirrors;
}

namespace {

// The samples of a mirrored view that `g`'s samples of mirror `object` show: the mirrored
// camera sees the reflected rays left-right mirrored, so sample (x, y) of `g` shows sample
// (w − 1 − x, y) of the view (the same size).
std::vector<std::uint8_t> samples_shown_by(const GBuffer& g, std::uint32_t object) {
  const std::size_t w = static_cast<std::size_t>(g.width);
  std::vector<std::uint8_t> shown(g.object.pixels.size(), 0);
  for (std::size_t row = 0; row < shown.size(); row += w)
    for (std::size_t x = 0; x < w; ++x) shown[row + w - 1 - x] = g.object.pixels[row + x] == object;
  return shown;
}

// Only the samples a view's parent shows are composited, so the others are made background:
// no pass lights, searches or recurses from them (their values were never read).
void keep_samples(GBuffer& g, const std::vector<std::uint8_t>& keep) {
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (!keep[i]) g.object.pixels[i] = g.reflector.pixels[i] = kNoId;
}

// Phase one of the recursion: every view rendered, lit and searched, depth-first in mirror
// order (which views fit max_views does not depend on threads).
struct ViewRecursion {
  par::Executor& executor;
  const Scene& scene;
  const std::vector<PlanarMirror>& mirrors;
  const std::vector<ShadowMap>& shadows;
  const EnvironmentMap& env;
  const ReflectorMaps* curved;
  PlanarMirrorSettings settings;
  PlanarMirrorViews& out;
  std::vector<std::uint8_t> is_mirror;  // per object id: 1 for the planar mirrors

  // Adds view `v`'s searches and, below `settings.depth`, the mirrored views of the mirrors
  // it sees. `g` is the view's G-buffer (views[v].g, or the camera's for view 0).
  void add(std::size_t v, const GBuffer& g, const Camera& camera, int level) {
    if (curved) {
      // Every view's reads marked in the one set of masks the maps are shaded on.
      out.views[v].searches = distance_map_search(executor, g, *curved, DistanceSearchOptions{}, nullptr, &out.tiles);
      out.stats.search_missed += out.views[v].searches.stats.missed;
    }
    if (level >= settings.depth) {
      // The mirrors seen here are not rendered again: they keep the environment lookup.
      for (const std::uint32_t object : g.object.pixels)
        out.stats.depth_exhausted += object < is_mirror.size() && is_mirror[object];
      return;
    }
    for (std::size_t k = 0; k < mirrors.size(); ++k) {
      const PlanarMirror& mirror = mirrors[k];
      // Skip mirrors this view does not see (no mirrored render for them).
      std::uint64_t samples = 0;
      for (const std::uint32_t object : g.object.pixels) samples += object == mirror.object;
      if (samples == 0) continue;
      if (out.stats.mirrored_views >= static_cast<std::uint64_t>(settings.max_views)) {
        ++out.stats.views_over_budget;  // a bound that is hit is counted, never silent
        continue;
      }
      ++out.stats.mirrored_views;
      out.stats.mirror_samples += samples;
      // The mirrored view: visibility → G-buffer → direct light, in the scene clipped at
      // the mirror's plane.
      const Scene& view_scene = mirror.clipped_for(camera.eye);
      const Camera mirrored = mirrored_camera(camera, mirror.plane);
      const std::size_t child = out.views.size();
      out.views[v].mirrored.push_back({k, child});
      out.views.emplace_back();
      PlanarMirrorView& view = out.views[child];
      const VisibilityBuffer vis = render_visibility(executor, view_scene, mirrored, settings.width, settings.height);
      view.g = resolve_gbuffer(executor, view_scene, vis, mirrored.eye);
      const std::vector<std::uint8_t> shown = samples_shown_by(g, mirror.object);
      keep_samples(view.g, shown);
      view.direct = direct_light(executor, view_scene, view.g, mirrored, shadows, env, &shown);
      add(child, out.views[child].g, mirrored, level + 1);
    }
  }
};

// Phase two: view `v`'s specular layer from the shaded maps, each mirror's samples replaced by
// F × its mirrored view's radiance (direct light + specular layer).
ImageRGBA compose(par::Executor& executor, const PlanarMirrorViews& views, std::size_t v, const GBuffer& g,
                  const std::vector<PlanarMirror>& mirrors, const EnvironmentMap& env, const ReflectorMaps* curved) {
  ImageRGBA specular = curved ? distance_map_lookup(executor, g, env, *curved, views.views[v].searches, DistanceSearchOptions{})
                              : envmap_reflect(executor, g, env);
  for (const auto& [k, child] : views.views[v].mirrored) {
    const PlanarMirrorView& view = views.views[child];
    ImageRGBA mirrored = compose(executor, views, child, view.g, mirrors, env, curved);
    executor.parallel_for("planar_mirror.add_layers", mirrored.size(), 4096, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        mirrored.pixels[i] = glm::vec4(glm::vec3(view.direct.pixels[i]) + glm::vec3(mirrored.pixels[i]), 1.0f);
    });
    const std::uint32_t object = mirrors[k].object;
    const int w = g.width;
    executor.parallel_for("planar_mirror.composite_mirror", static_cast<std::size_t>(g.height), 8,
                          [&](std::size_t begin, std::size_t end) {
      for (std::size_t y = begin; y < end; ++y)
        for (int x = 0; x < w; ++x) {
          const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
          if (g.object.pixels[i] != object) continue;
          // The mirrored camera sees the reflected rays left-right mirrored.
          const glm::vec3 l(mirrored.at(w - 1 - x, static_cast<int>(y)));
          const float cos_nv = std::abs(glm::dot(g.normal.pixels[i], g.view_direction(i)));
          specular.pixels[i] = glm::vec4(specular_reflectance(g.surface[i], cos_nv) * l, 1.0f);
        }
    });
  }
  return specular;
}

}  // namespace

PlanarMirrorViews planar_mirror_views(par::Executor& executor, const Scene& scene,
                                      const std::vector<PlanarMirror>& mirrors, const GBuffer& g,
                                      const Camera& camera, const std::vector<ShadowMap>& shadows,
                                      const EnvironmentMap& env, const ReflectorMaps* curved,
                                      const PlanarMirrorSettings& settings) {
  PlanarMirrorViews out;
  out.views.emplace_back();
  if (curved)
    for (std::size_t m = 0; m < curved->cubes.size(); ++m)
      out.tiles.push_back(tile_mask_for_reads(curved->cubes[m].size, curved->levels[m]));
  PlanarMirrorSettings s = settings;
  s.width = g.width;
  s.height = g.height;
  ViewRecursion r{executor, scene, mirrors, shadows, env, curved, s, out, std::vector<std::uint8_t>(scene.objects.size(), 0)};
  for (const PlanarMirror& mirror : mirrors)
    if (mirror.object < r.is_mirror.size()) r.is_mirror[mirror.object] = 1;
  r.add(0, g, camera, 0);
  return out;
}

ImageRGBA planar_mirror_compose(par::Executor& executor, const PlanarMirrorViews& views, const GBuffer& g,
                                const std::vector<PlanarMirror>& mirrors, const EnvironmentMap& env,
                                const ReflectorMaps* curved) {
  return compose(executor, views, 0, g, mirrors, env, curved);
}

ImageRGBA planar_mirror_reflect(par::Executor& executor, const Scene& scene,
                                const std::vector<PlanarMirror>& mirrors, const GBuffer& g,
                                const Camera& camera, const std::vector<ShadowMap>& shadows,
                                const EnvironmentMap& env, const ReflectorMaps* curved,
                                const PlanarMirrorSettings& settings, PlanarMirrorStats* stats) {
  const PlanarMirrorViews views = planar_mirror_views(executor, scene, mirrors, g, camera, shadows, env, curved, settings);
  if (stats) *stats = views.stats;
  return planar_mirror_compose(executor, views, g, mirrors, env, curved);
}

PlanarMirrors PlanarMirrorsPass::operator()(par::NodeContext& c) const {
  PlanarMirrors mirrors = find_planar_mirrors(*scene);
  c.count("mirrors", mirrors.size());
  return mirrors;
}

PlanarMirrorViews PlanarMirrorViewsPass::operator()(par::NodeContext& c, const PlanarMirrors& mirrors,
                                                    const GBuffer& gbuffer, const ShadowMaps& shadows,
                                                    const EnvironmentMap& environment,
                                                    const ReflectorMaps& curved_reflectors) const {
  PlanarMirrorSettings settings;
  settings.depth = depth;
  PlanarMirrorViews views = planar_mirror_views(c.executor(), *scene, mirrors, gbuffer, camera, shadows, environment,
                                                &curved_reflectors, settings);
  c.count("mirrored_views", views.stats.mirrored_views);
  c.count("mirror_samples", views.stats.mirror_samples);
  c.count("views_over_budget", views.stats.views_over_budget);
  c.count("fallback_depth_exhausted", views.stats.depth_exhausted);
  c.count("fallback_search_missed", views.stats.search_missed);
  return views;
}

ImageRGBA PlanarMirrorComposePass::operator()(par::NodeContext& c, const PlanarMirrorViews& views,
                                              const GBuffer& gbuffer, const PlanarMirrors& mirrors,
                                              const EnvironmentMap& environment,
                                              const ReflectorMaps& curved_reflectors) const {
  return planar_mirror_compose(c.executor(), views, gbuffer, mirrors, environment, &curved_reflectors);
}

}  // namespace speculum::raster
