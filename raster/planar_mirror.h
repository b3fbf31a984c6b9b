// Planar mirrors by geometry transformation (SURVEY §5): each planar mirror's reflection is
// the scene seen by the camera reflected about the mirror plane, clipped to the viewer's
// side of the plane, masked to the mirror's own samples and weighted by Fresnel; mirrors
// seen in a mirrored view recurse, to depth k. Exact up to rasterization.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/distance_map_reflect.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/mirrored_camera.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

struct PlanarMirror {
  std::uint32_t object = kNoId;
  Plane plane;
  Scene front;  // the scene clipped to plane.signed_distance > 0, this mirror left out
  Scene back;   // the same for the other side
  const Scene& clipped_for(const glm::vec3& eye) const {
    return plane.signed_distance(eye) >= 0.0f ? front : back;
  }
};

// Object `object`'s plane when every triangle's material is a mirror (is_mirror_lobe, not a
// refractor) and all its vertices lie within `tolerance` × (bounding-box diagonal) of one
// plane; the plane normal is the area-weighted mean of the triangle normals.
std::optional<Plane> planar_mirror_plane(const Scene& scene, std::uint32_t object,
                                         float tolerance = 1e-3f);

// The objects with a planar_mirror_plane, each with its clipped scenes.
std::vector<PlanarMirror> find_planar_mirrors(const Scene& scene, float tolerance = 1e-3f);

struct PlanarMirrorSettings {
  int depth = 3;  // mirror bounces rendered by geometry transformation
  int width = 0;  // target size in samples (the camera G-buffer's)
  int height = 0;
  // Mirrors that see each other multiply the views per level (up to (m-1)^depth), so the
  // whole recursion renders at most this many mirrored views (each a full frame); a mirror
  // whose view would exceed it keeps the environment lookup, as beyond `depth`. The views are
  // rendered depth-first in mirror order, so which ones fit does not depend on threads.
  int max_views = 256;
};

struct PlanarMirrorStats {
  std::uint64_t mirrored_views = 0;     // visibility + shading passes of mirrored cameras
  std::uint64_t mirror_samples = 0;     // samples that received a mirrored image
  std::uint64_t views_over_budget = 0;  // mirrored views not rendered (max_views reached)
  std::uint64_t depth_exhausted = 0;    // mirror samples of the deepest views: environment lookup
  std::uint64_t search_missed = 0;      // curved reflectors' distance-map searches that found nothing
};

// The specular layer of G-buffer `g` (seen from `camera` in `view_scene`, object ids of
// `scene`): planar-mirror samples get F(N·V) × the mirrored view's radiance (recursively,
// `depth` levels; beyond it the environment lookup); every other specular sample, in the
// camera's view and in every mirrored view, gets the distance-map search (SURVEY §4.2) in
// its own cube map in `curved` when it has one, else the environment lookup of envmap_reflect.
// `shadows` and `env` are the original scene's. planar_mirror_views then
// planar_mirror_compose with the same maps.
ImageRGBA planar_mirror_reflect(par::Executor& executor, const Scene& scene,
                                const std::vector<PlanarMirror>& mirrors, const GBuffer& g,
                                const Camera& camera, const std::vector<ShadowMap>& shadows,
                                const EnvironmentMap& env, const ReflectorMaps* curved,
                                const PlanarMirrorSettings& settings,
                                PlanarMirrorStats* stats = nullptr);

// planar_mirror_reflect in two halves, so that the curved reflectors' maps are shaded only
// where some view's searches read them. The views of the recursion, views[0] the camera's:
// each mirrored view's G-buffer and direct light, and every view's searches in `curved` (its
// distances are all they read).
struct PlanarMirrorView {
  GBuffer g;                 // mirrored views (the camera's is the caller's)
  ImageRGBA direct;          // mirrored views: direct light
  DistanceSearches searches; // with curved maps: this view's searches
  std::vector<std::pair<std::size_t, std::size_t>> mirrored;  // (mirror index, view index)
};
struct PlanarMirrorViews {
  std::deque<PlanarMirrorView> views;  // a deque: adding a view moves none of the others
  std::vector<CubeTileMask> tiles;  // per curved map: the tiles any view's searches read
  PlanarMirrorStats stats;
};
PlanarMirrorViews planar_mirror_views(par::Executor& executor, const Scene& scene,
                                      const std::vector<PlanarMirror>& mirrors, const GBuffer& g,
                                      const Camera& camera, const std::vector<ShadowMap>& shadows,
                                      const EnvironmentMap& env, const ReflectorMaps* curved,
                                      const PlanarMirrorSettings& settings);
// The specular layer of the camera's view from `views` (of the same `g` and `mirrors`), the
// searches read in `curved` (the same maps, or their colour shaded over views.tiles).
ImageRGBA planar_mirror_compose(par::Executor& executor, const PlanarMirrorViews& views, const GBuffer& g,
                                const std::vector<PlanarMirror>& mirrors, const EnvironmentMap& env,
                                const ReflectorMaps* curved);

using PlanarMirrors = std::vector<PlanarMirror>;

// Pass "planar_mirrors": the scene's planar mirrors and their clipped scenes.
struct PlanarMirrorsPass {
  static constexpr const char* description =
      "Planar mirror objects (coplanar within 1e-3 of their size) and the scene clipped to each "
      "side of each mirror plane (SURVEY §5).";
  const Scene* scene = nullptr;
  PlanarMirrors operator()(par::NodeContext& c) const;
};

// Pass "planar_mirror_views": the recursion's views, rendered, lit and searched.
struct PlanarMirrorViewsPass {
  static constexpr const char* description =
      "Per planar mirror the view of the camera reflected about its plane (scene clipped at the "
      "plane), recursively to depth k, each lit; every view's curved specular samples search "
      "their own distance map (SURVEY §5, §4.2).";
  const Scene* scene = nullptr;
  Camera camera;
  int depth = 3;
  void parameters(par::Params& p) const { p.set("depth", depth); }
  PlanarMirrorViews operator()(par::NodeContext& c, const PlanarMirrors& mirrors, const GBuffer& gbuffer,
                               const ShadowMaps& shadows, const EnvironmentMap& environment,
                               const ReflectorMaps& curved_reflectors) const;
};

// Pass "planar_mirror_reflect": the specular layer: each mirror's samples get F × its view's
// radiance, the other specular samples their searches' colour.
struct PlanarMirrorComposePass {
  static constexpr const char* description =
      "Each planar mirror's samples get F × its reflected view's radiance, recursively; other "
      "specular samples read their searches' hits in the shaded maps (SURVEY §5, §4.2).";
  ImageRGBA operator()(par::NodeContext& c, const PlanarMirrorViews& views, const GBuffer& gbuffer,
                       const PlanarMirrors& mirrors, const EnvironmentMap& environment,
                       const ReflectorMaps& curved_reflectors) const;
};

}  // namespace speculum::raster
