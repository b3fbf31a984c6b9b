// ROGER ch.2: reflections on curved reflectors by non-linear vertex projection. Every scene
// vertex V is moved to its reflection point P on each star-shaped mirror reflector (the
// Fermat point of |EP| + |PV|, raster/fermat_projection.h), and the scene's triangles are
// rasterized between the projected vertices into the reflector's pixels with depth by path
// length, then shaded as the scene (direct light at V towards P) times the reflector's
// Fresnel at P (ROGER §2.2.3). The passes, in order:
//   tessellate           the reflected geometry split to a target edge length (§2.3.4)
//   reflector_param      per star-shaped reflector, a cube map around O of r(u) and n(u)
//   vertex_project       the secant search per (vertex, reflector), with counters
//   reflected_triangles  the projected triangles rasterized into each reflector's samples
//   vertex_projection_shade  the specular layer
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/environment.h"
#include "raster/fermat_projection.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

// The scene's triangles (every object, each split by mesh::split_long_edges when its faces
// share one material) with the original object and material ids.
struct ReflectedGeometry {
  TriangleMesh mesh;
  std::size_t splits = 0;
  std::size_t objects_kept_whole = 0;  // mixed materials or non-manifold: copied as they are
  bool vertex_budget_reached = false;
};

// max_edge: world units (≤ 0: no splitting); max_vertices bounds the result.
ReflectedGeometry tessellate_reflected(const Scene& scene, double max_edge, std::size_t max_vertices);

// A reflector's parameterization P(u) = O + r(u) u (ROGER §2.2.3), sampled by rasterizing
// the reflector alone from O into a cube map: r = |P − O| and the interpolated unit normal
// per texel (+inf: no surface that way). Looked up bilinearly; ∇ln r = u − n/(n·u) follows
// from n (raster/fermat_projection.h states the conventions).
struct ReflectorParam {
  std::uint32_t object = kNoId;
  glm::dvec3 centre{0.0};
  int orientation = 1;  // +1: O behind the surface (convex side out); −1: O on the mirror side
  // Mean curvature (core/mesh_processing) positive at every vertex with normals facing away
  // from O: a convex mirror, where every reflection is a path-length minimum.
  bool convex = false;
  bool closed = false;  // no boundary edges: seen from outside only
  int size = 0;
  double max_radius = 0.0;  // the largest finite r
  // Per face, per texel: the unit normal (xyz) and r (w; +inf: no surface that way), side by
  // side so that a lookup's four taps read two cache lines rather than four.
  std::array<Buffer2D<glm::vec4>, 6> texels;
  ReflectorSample operator()(const glm::dvec3& u) const;
};

struct ReflectorParams {
  std::vector<ReflectorParam> reflectors;
  std::size_t not_star_shaped = 0;  // mirror objects skipped (their pixels keep the fallback)
  std::vector<std::string> skipped;  // one line each: the object and its failing faces
};

// Mirror objects (MaterialKind::Mirror) star-shaped about the centre mesh::choose_star_centre
// picks get a parameterization of `size`² texels per face.
ReflectorParams build_reflector_params(par::Executor& executor, const Scene& scene, int size);

// Per reflector (outer index) and reflected vertex (inner): the projected vertex in the
// form the rasterizer takes (clip = (x_ndc ℓ, y_ndc ℓ, 0, ℓ) with ℓ = |EP| + |PV|: the depth
// test on 1/w keeps the shortest path, which at one pixel — one P — is the nearest |PV|).
struct ProjectedVertices {
  std::size_t vertices = 0;
  std::vector<std::vector<glm::vec4>> clip;
  std::vector<std::vector<std::uint8_t>> status;      // ProjectionStatus
  std::vector<std::vector<std::uint8_t>> extremum;    // PathExtremum
  std::vector<std::vector<std::uint8_t>> iterations;
};

struct ProjectionStats {
  std::uint64_t projections = 0, converged = 0, not_converged = 0, off_reflector = 0, hidden = 0;
  std::uint64_t minima = 0, maxima = 0, saddles = 0;  // of the converged ones
  std::uint64_t iterations = 0, backtracks = 0;
  std::array<std::uint64_t, 33> histogram{};  // converged projections by iteration count
};

ProjectedVertices project_vertices(par::Executor& executor, const ReflectedGeometry& geometry,
                                   const ReflectorParams& params, const Camera& camera, int width,
                                   int height, const FermatSettings& settings, ProjectionStats* stats = nullptr);

// Per sample of the G-buffer: the reflected triangle seen in it (index into the reflected
// geometry's triangles, kNoId: none), its perspective-correct barycentrics, and the largest
// iteration count of its three vertices (the iteration-count image; 0 where none).
struct ReflectedLayer {
  int width = 0, height = 0;
  IdBuffer triangle;
  Buffer2D<glm::vec2> bary;
  ImageF iterations;
};

struct ReflectedTriangleStats {
  std::uint64_t drawn = 0;            // triangles rasterized (summed over reflectors)
  std::uint64_t unprojected = 0;      // a vertex did not converge or left the reflector
  std::uint64_t hidden = 0;           // a vertex behind the reflector
  std::uint64_t middle_zone = 0;      // a saddle vertex or minima and maxima mixed (§2.3.3)
  std::uint64_t samples = 0;          // reflector samples that received a reflected triangle
};

ReflectedLayer rasterize_reflected(par::Executor& executor, const ReflectedGeometry& geometry,
                                   const ProjectedVertices& projected, const ReflectorParams& params,
                                   const GBuffer& gbuffer, ReflectedTriangleStats* stats = nullptr);

// The specular layer: mirror samples covered by a reflected triangle get
// F(n·v at P) × shade_surface(V, towards P); mirror samples of a projected reflector that no
// reflected triangle covers see past the scene, so they get F × the distant environment
// (`env`: not a cube map of the scene, whose geometry the projection already placed); every
// other sample keeps `fallback`.
ImageRGBA shade_reflected(par::Executor& executor, const Scene& scene, const ReflectedGeometry& geometry,
                          const ReflectedLayer& layer, const ReflectorParams& params, const GBuffer& gbuffer,
                          const ShadowMaps& shadows, const EnvironmentMap& env, const ImageRGBA& fallback);

// Pass "tessellate".
struct TessellatePass {
  static constexpr const char* description =
      "Splits the scene's edges longer than a fraction of its diagonal (OpenMesh, longest "
      "first), so linearly rasterized reflected triangles follow the curved reflection "
      "(ROGER §2.3.4).";
  const Scene* scene = nullptr;
  double edge = 0.0;  // fraction of the scene diagonal; 0: off
  std::size_t max_vertices = std::size_t(1) << 22;
  void parameters(par::Params& p) const { p.set("edge", edge); }
  ReflectedGeometry operator()(par::NodeContext& c) const;
};

// Pass "reflector_param".
struct ReflectorParamPass {
  static constexpr const char* description =
      "Per star-shaped mirror, a cube map around its centre O of the radius r(u) and normal: "
      "P(u) = O + r(u) u (ROGER §2.2.3); reflectors that are not star-shaped are counted and "
      "skipped.";
  const Scene* scene = nullptr;
  int size = 256;
  void parameters(par::Params& p) const { p.set("size", size); }
  ReflectorParams operator()(par::NodeContext& c) const;
};

// Pass "reflector_cube_maps" of this technique: the environment-map fallback's cube maps
// for the specular objects that have no parameterization (glossy ones, mirrors that are not
// star-shaped); a projected mirror never reads its own.
struct FallbackCubeMapsPass {
  static constexpr const char* description =
      "Per specular object without a parameterization (glossy, not star-shaped), a colour + "
      "distance cube map at its reference point for the environment-map fallback (SURVEY §3.1).";
  const Scene* scene = nullptr;
  int size = 256;
  MapSizing sizing;  // only the camera's fallback samples read these maps (envmap_reflect)
  void parameters(par::Params& p) const {
    p.set("size", size);
    p.set("footprint_size", sizing.from_footprint ? 1 : 0);
  }
  ReflectorMaps operator()(par::NodeContext& c, const ReflectorParams& params, const ShadowMaps& shadows,
                           const EnvironmentMap& environment, const GBuffer& gbuffer) const;
};

// Pass "vertex_project".
struct VertexProjectPass {
  static constexpr const char* description =
      "For every (scene vertex, reflector): the reflection point P by the 2-D secant iteration "
      "on the path length |EP| + |PV| (ROGER §2.2.3, corrected gradient), ≤ 32 iterations, "
      "stopped at a sub-pixel triangle; iteration histogram in the counters.";
  Camera camera;
  FermatSettings settings;
  void parameters(par::Params& p) const {
    p.set("max_iterations", settings.max_iterations).set("pixel_tolerance", settings.pixel_tolerance);
    p.set("residual", settings.residual);
  }
  ProjectedVertices operator()(par::NodeContext& c, const ReflectedGeometry& geometry,
                               const ReflectorParams& params, const GBuffer& gbuffer) const;
};

// Pass "reflected_triangles".
struct ReflectedTrianglesPass {
  static constexpr const char* description =
      "Rasterizes the scene's triangles between their projected vertices, depth by path "
      "length, kept in the reflector's visible samples (ROGER §2.2.3's stencil); triangles "
      "with a hidden, unconverged or middle-zone vertex are dropped and counted (§2.3.3).";
  ReflectedLayer operator()(par::NodeContext& c, const ReflectedGeometry& geometry,
                            const ProjectedVertices& projected, const ReflectorParams& params,
                            const GBuffer& gbuffer) const;
};

// Pass "vertex_projection_shade".
struct VertexProjectionShadePass {
  static constexpr const char* description =
      "Shades each reflected sample as the scene at V lit directly and seen from P, times "
      "the reflector's Fresnel at P (ROGER §2.2.3); uncovered reflector samples see the distant "
      "environment; other specular samples keep the environment-map layer.";
  const Scene* scene = nullptr;
  ImageRGBA operator()(par::NodeContext& c, const ReflectedLayer& layer, const ReflectedGeometry& geometry,
                       const ReflectorParams& params, const GBuffer& gbuffer, const ShadowMaps& shadows, const EnvironmentMap& environment,
                       const ImageRGBA& fallback) const;
};

}  // namespace speculum::raster
