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

struct Recursion {
  par::Executor& executor;
  const Scene& scene;
  const std::vector<PlanarMirror>& mirrors;
  const std::vector<ShadowMap>& shadows;
  const EnvironmentMap& env;
  const ReflectorMaps* curved;
  PlanarMirrorSettings settings;
  PlanarMirrorStats stats;
  DistanceReflectStats search;  // the curved reflectors' searches, in every view
  std::vector<std::uint8_t> is_mirror;  // per object id: 1 for the planar mirrors

  // Radiance of a mirrored view: the whole per-view pipeline (visibility → G-buffer →
  // direct light → specular layer) for `camera` in the clipped scene.
  ImageRGBA view_radiance(const Scene& view_scene, const Camera& camera, int level) {
    ++stats.mirrored_views;
    const VisibilityBuffer vis =
        render_visibility(executor, view_scene, camera, settings.width, settings.height);
    const GBuffer g = resolve_gbuffer(executor, view_scene, vis, camera.eye);
    ImageRGBA radiance = direct_light(executor, view_scene, g, camera, shadows, env);
    const ImageRGBA specular = reflect(g, camera, level);
    executor.parallel_for("planar_mirror.add_layers", radiance.size(), 4096,
                          [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i)
        radiance.pixels[i] = glm::vec4(glm::vec3(radiance.pixels[i]) + glm::vec3(specular.pixels[i]), 1.0f);
    });
    return radiance;
  }

  // The specular layer of a view at recursion `level` (0: the camera's own view).
  ImageRGBA reflect(const GBuffer& g, const Camera& camera, int level) {
    ImageRGBA specular = curved ? distance_map_reflect(executor, g, env, *curved, DistanceSearchOptions{}, &search)
                                : envmap_reflect(executor, g, env);
    if (level >= settings.depth) {
      // The mirrors seen here are not rendered again: they keep the environment lookup.
      for (const std::uint32_t object : g.object.pixels)
        stats.depth_exhausted += object < is_mirror.size() && is_mirror[object];
      return specular;
    }
    for (const PlanarMirror& mirror : mirrors) {
      // Skip mirrors this view does not see (no mirrored render for them).
      bool seen = false;
      for (std::size_t i = 0; i < g.object.size() && !seen; ++i) seen = g.object.pixels[i] == mirror.object;
      if (!seen) continue;
      if (stats.mirrored_views >= static_cast<std::uint64_t>(settings.max_views)) {
        ++stats.views_over_budget;  // a bound that is hit is counted, never silent
        continue;
      }
      const ImageRGBA mirrored = view_radiance(mirror.clipped_for(camera.eye),
                                               mirrored_camera(camera, mirror.plane), level + 1);
      const int w = g.width;
      std::uint64_t samples = 0;
      std::vector<std::uint64_t> per_row(static_cast<std::size_t>(g.height), 0);
      executor.parallel_for("planar_mirror.composite_mirror", static_cast<std::size_t>(g.height), 8,
                            [&](std::size_t begin, std::size_t end) {
        for (std::size_t y = begin; y < end; ++y)
          for (int x = 0; x < w; ++x) {
            const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
            if (g.object.pixels[i] != mirror.object) continue;
            // The mirrored camera sees the reflected rays left-right mirrored.
            const glm::vec3 l(mirrored.at(w - 1 - x, static_cast<int>(y)));
            const float cos_nv = std::abs(glm::dot(g.normal.pixels[i], g.view_direction(i)));
            specular.pixels[i] = glm::vec4(specular_reflectance(g.surface[i], cos_nv) * l, 1.0f);
            ++per_row[y];
          }
      });
      for (const std::uint64_t n : per_row) samples += n;
      stats.mirror_samples += samples;
    }
    return specular;
  }
};

}  // namespace

ImageRGBA planar_mirror_reflect(par::Executor& executor, const Scene& scene,
                                const std::vector<PlanarMirror>& mirrors, const GBuffer& g,
                                const Camera& camera, const std::vector<ShadowMap>& shadows,
                                const EnvironmentMap& env, const ReflectorMaps* curved,
                                const PlanarMirrorSettings& settings, PlanarMirrorStats* stats) {
  PlanarMirrorSettings s = settings;
  s.width = g.width;
  s.height = g.height;
  Recursion r{executor, scene, mirrors, shadows, env, curved, s, {}, {}, std::vector<std::uint8_t>(scene.objects.size(), 0)};
  for (const PlanarMirror& mirror : mirrors)
    if (mirror.object < r.is_mirror.size()) r.is_mirror[mirror.object] = 1;
  ImageRGBA specular = r.reflect(g, camera, 0);
  r.stats.search_missed = r.search.missed;
  if (stats) *stats = r.stats;
  return specular;
}

PlanarMirrors PlanarMirrorsPass::operator()(par::NodeContext& c) const {
  PlanarMirrors mirrors = find_planar_mirrors(*scene);
  c.count("mirrors", mirrors.size());
  return mirrors;
}

ImageRGBA PlanarMirrorReflectPass::operator()(par::NodeContext& c, const PlanarMirrors& mirrors,
                                             const GBuffer& gbuffer, const ShadowMaps& shadows,
                                             const EnvironmentMap& environment,
                                             const ReflectorMaps* curved_reflectors) const {
  PlanarMirrorSettings settings;
  settings.depth = depth;
  PlanarMirrorStats stats;
  ImageRGBA specular = planar_mirror_reflect(c.executor(), *scene, mirrors, gbuffer, camera, shadows,
                                             environment, curved_reflectors, settings, &stats);
  c.count("mirrored_views", stats.mirrored_views);
  c.count("mirror_samples", stats.mirror_samples);
  c.count("views_over_budget", stats.views_over_budget);
  c.count("fallback_depth_exhausted", stats.depth_exhausted);
  c.count("fallback_search_missed", stats.search_missed);
  return specular;
}

}  // namespace speculum::raster
