// The `refraction` node: see refraction.h.
#include "raster/refraction.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "raster/refraction_path.h"
#include "raster/specular_radiance.h"

namespace speculum::raster {

GBuffer render_refractor_back_faces(par::Executor& executor, const Scene& scene,
                                    const Camera& camera, int width, int height) {
  RasterOptions opt;
  opt.cull = CullMode::Front;  // keep the far side of each closed refractor
  const std::vector<std::uint8_t> refractors = refractor_objects(scene);
  opt.excluded_objects.resize(refractors.size());
  for (std::size_t o = 0; o < refractors.size(); ++o) opt.excluded_objects[o] = refractors[o] ? 0 : 1;
  const VisibilityBuffer vis = render_visibility(executor, scene, camera, width, height, opt);
  return resolve_gbuffer(executor, scene, vis, camera.eye);
}

namespace {

// Continuous pixel coordinates of world point p in `camera`'s image (primary_ray inverted);
// false behind the camera.
bool project(const Camera& camera, int width, int height, const glm::vec3& p, glm::vec2& pixel) {
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tan_half = std::tan(glm::radians(camera.vfov_degrees) * 0.5f);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const glm::vec3 d = p - camera.eye;
  const float z = glm::dot(d, forward);
  if (!(z > 0.0f)) return false;
  const float ndc_x = glm::dot(d, right) / (z * tan_half * aspect);
  const float ndc_y = glm::dot(d, up) / (z * tan_half);
  pixel = {(ndc_x + 1.0f) * 0.5f * static_cast<float>(width),
           (1.0f - ndc_y) * 0.5f * static_cast<float>(height)};
  return true;
}

// Per-vertex thickness interpolated at a visibility sample (the front triangle's d_N).
float interpolated_thickness(const TriangleMesh& m, const std::vector<float>& thickness,
                             const VisibilityBuffer& vis, std::size_t i) {
  const std::uint32_t t = vis.triangle.pixels[i];
  if (t == kNoId) return 0.0f;
  const glm::vec2 b = vis.bary.pixels[i];
  return (1.0f - b.x - b.y) * thickness[m.indices[3 * t]] + b.x * thickness[m.indices[3 * t + 1]] +
         b.y * thickness[m.indices[3 * t + 2]];
}

struct ChunkCounts {
  std::uint64_t refracted = 0, total_internal = 0, no_exit = 0, fallbacks = 0;
  void count(RefractionOutcome outcome) {
    switch (outcome) {
      case RefractionOutcome::Refracted: ++refracted; break;
      case RefractionOutcome::TotalInternal: ++total_internal; break;
      case RefractionOutcome::NoExit: ++no_exit; break;
      default: break;
    }
  }
};

// Radiance arriving at world point p from direction d, from the refractor's environment
// cube (localized search) or, without one, the environment map.
struct RefractorEnvironment {
  const RefractionInputs& in;
  const DistanceSearchOptions& search;
  glm::vec3 operator()(std::uint32_t object, const glm::vec3& p, const glm::vec3& d) const {
    const int k = in.maps && object < in.maps->map_of_object.size() ? in.maps->map_of_object[object] : -1;
    if (k < 0) return in.env ? in.env->radiance(d, 1e6f) : glm::vec3(0.0f);
    const CubeMap& cube = in.maps->cubes[static_cast<std::size_t>(k)];
    const DistanceSearchResult r = search_distance_map(cube, p, d, search);
    return glm::vec3(cube.colour_towards(r.direction));
  }
};

// The two-face exit of pixel i's refracted ray: P2 at the distance interpolated between the
// view-ray thickness (front to back face behind P1) and the normal thickness d_N. Returns
// whether the ray exits (distance > 0), with P2 and the exit normal N2.
bool two_face_exit(const RefractionInputs& in, const GBuffer& g, std::size_t i, float refractor_ior,
                   std::uint32_t object, const glm::vec3& p1, const glm::vec3& n1,
                   const RefractionPath& path, glm::vec3& p2, glm::vec3& n2, ChunkCounts& c) {
  const GBuffer& back = *in.back;
  const float d_normal = interpolated_thickness(*in.mesh, *in.vertex_thickness, *in.front_vis, i);
  const bool back_here = back.covered(i);
  const float d_view = back_here ? glm::length(back.position.pixels[i] - p1) : d_normal;
  const float d = two_face_distance(path.cos_i, path.cos_t, refractor_ior, d_view, d_normal);
  p2 = p1 + path.inside * d;
  // The exit normal is the back face's where P2 projects (Wyman); outside the
  // back-face buffer, the one behind P1.
  glm::vec2 px;
  bool found = false;
  if (project(in.camera, g.width, g.height, p2, px)) {
    const int x = static_cast<int>(std::floor(px.x)), y = static_cast<int>(std::floor(px.y));
    if (x >= 0 && y >= 0 && x < g.width && y < g.height) {
      const std::size_t j = static_cast<std::size_t>(y) * g.width + x;
      if (back.covered(j) && back.object.pixels[j] == object) {
        n2 = back.normal.pixels[j];
        found = true;
      }
    }
  }
  if (!found) {
    ++c.fallbacks;
    n2 = back_here ? back.normal.pixels[i] : -n1;
  }
  return d > 0.0f;
}

// The refractor's specular radiance at P1: transmission × (f_entry·L(R1) + (1 − f_entry)·
// base colour·L_through), L_through arriving through the exit (split again by f_exit unless
// the exit reflects totally) or, when the path has no exit, along T1 from P1.
template <class Environment>
glm::vec3 refractor_radiance(const Environment& environment, const SurfaceParams& s,
                             std::uint32_t object, const glm::vec3& p1, const RefractionPath& path,
                             bool exits) {
  glm::vec3 through;
  if (exits) {
    const glm::vec3 behind = environment(object, path.exit_point, path.exit_direction);
    through = path.total_internal
                  ? behind
                  : (1.0f - path.f_exit) * s.base_color * behind +
                        path.f_exit * environment(object, path.exit_point, path.internal);
  } else {
    through = environment(object, p1, path.inside);  // single interface
  }
  const glm::vec3 mirror = environment(object, p1, path.reflected);
  return s.transmission * (path.f_entry * mirror + (1.0f - path.f_entry) * s.base_color * through);
}

// Refractor sample i's path through its refractor: entered at P1, and left where the method
// finds the exit (two-face or impostor), or not.
struct SamplePath {
  glm::vec3 p1;
  RefractionPath path;
  bool exits = false;
  RefractionOutcome outcome = RefractionOutcome::Refracted;
};
SamplePath trace_sample_path(const RefractionInputs& in, const RefractionOptions& options, std::size_t i,
                             ChunkCounts& c) {
  const GBuffer& g = *in.front;
  const RefractionMethod method = options.method;
  const bool two_face = method == RefractionMethod::TwoFace && in.back && in.vertex_thickness &&
                        in.front_vis && in.mesh;
  const bool impostor = method == RefractionMethod::DistanceImpostor && in.impostors;
  const SurfaceParams& s = g.surface[i];
  const std::uint32_t object = g.object.pixels[i];
  SamplePath out;
  out.p1 = g.position.pixels[i];
  const glm::vec3 view = g.view_direction(i), v = -view;
  glm::vec3 n1 = g.normal.pixels[i];
  // Seen from inside (the camera in the refractor): swap the roles; single interface.
  const bool entering = glm::dot(n1, view) >= 0.0f;
  if (!entering) n1 = -n1;
  const float ior = entering ? s.ior : 1.0f / s.ior;
  out.path = enter_refractor(out.p1, v, n1, ior);
  if (entering && out.path.f_entry < 1.0f) {
    glm::vec3 p2, n2;
    if (two_face) {
      out.exits = two_face_exit(in, g, i, s.ior, object, out.p1, n1, out.path, p2, n2, c);
    } else if (impostor) {
      const CubeMap* cube = in.impostors->for_object(object);
      out.exits = cube && find_impostor_exit(*cube, out.p1, out.path.inside, options.exit_search, p2, n2);
    }
    if (out.exits) {
      leave_refractor(out.path, p2, n2, s.ior);
      if (out.path.total_internal) out.outcome = RefractionOutcome::TotalInternal;
    } else if (method != RefractionMethod::SingleInterface) {
      out.outcome = RefractionOutcome::NoExit;
    }
  }
  return out;
}

// RefractorEnvironment's colour reads marked instead of made: the same searches, each found
// direction's bilinear taps of level 0 (what CubeMap::colour_towards reads) marked in its map.
struct MarkedEnvironment {
  const RefractionInputs& in;
  const DistanceSearchOptions& search;
  std::vector<LookupTileMarker>& markers;
  glm::vec3 operator()(std::uint32_t object, const glm::vec3& p, const glm::vec3& d) const {
    const int k = in.maps && object < in.maps->map_of_object.size() ? in.maps->map_of_object[object] : -1;
    if (k < 0) return glm::vec3(0.0f);
    const DistanceSearchResult r = search_distance_map(in.maps->cubes[static_cast<std::size_t>(k)], p, d, search);
    markers[static_cast<std::size_t>(k)].mark(r.direction, kSharpLookupExponent);
    return glm::vec3(0.0f);
  }
};

}  // namespace

void mark_refraction_reads(par::Executor& executor, const RefractionInputs& in, const RefractionOptions& options,
                           std::vector<CubeTileMask>& tiles) {
  const GBuffer& g = *in.front;
  // Each chunk marks through markers of its own: a tile is only ever set, so the masks are
  // the same whatever thread marked what.
  executor.parallel_for("refraction_reads.mark", g.object.size(), 4096, [&](std::size_t begin, std::size_t end) {
    std::vector<LookupTileMarker> markers;
    for (std::size_t m = 0; m < tiles.size(); ++m) markers.emplace_back(tiles[m], in.maps->levels[m]);
    const MarkedEnvironment environment{in, options.environment_search, markers};
    ChunkCounts c;
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i) || !g.surface[i].is_refractor()) continue;
      const SamplePath sp = trace_sample_path(in, options, i, c);
      refractor_radiance(environment, g.surface[i], g.object.pixels[i], sp.p1, sp.path, sp.exits);
    }
  });
}

RefractionLayer refract_layer(par::Executor& executor, const RefractionInputs& in,
                              const RefractionOptions& options, const ImageRGBA& specular) {
  const GBuffer& g = *in.front;
  RefractionLayer out;
  out.specular = specular;
  out.outcome = Buffer2D<std::uint8_t>(g.width, g.height, 0);
  out.exit_point = Buffer2D<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
  out.exit_direction = Buffer2D<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
  const RefractorEnvironment environment{in, options.environment_search};

  constexpr std::size_t kChunk = 4096;
  const std::size_t chunks = (g.object.size() + kChunk - 1) / kChunk;
  std::vector<ChunkCounts> counts(chunks);
  executor.parallel_for("refraction.trace_paths", g.object.size(), kChunk,
                        [&](std::size_t begin, std::size_t end) {
    ChunkCounts& c = counts[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i) || !g.surface[i].is_refractor()) continue;
      SamplePath sp = trace_sample_path(in, options, i, c);
      const glm::vec3 radiance = refractor_radiance(environment, g.surface[i], g.object.pixels[i], sp.p1, sp.path, sp.exits);
      out.specular.pixels[i] = glm::vec4(radiance, 1.0f);
      out.outcome.pixels[i] = static_cast<std::uint8_t>(sp.outcome);
      out.exit_point.pixels[i] = sp.exits ? sp.path.exit_point : sp.p1;
      out.exit_direction.pixels[i] = sp.exits ? sp.path.exit_direction : sp.path.inside;
      c.count(sp.outcome);
    }
  });
  for (const ChunkCounts& c : counts) {
    out.refracted += c.refracted;
    out.total_internal += c.total_internal;
    out.no_exit += c.no_exit;
    out.exit_normal_fallbacks += c.fallbacks;
  }
  return out;
}

GBuffer RefractorBackFacesPass::operator()(par::NodeContext& c) const {
  return render_refractor_back_faces(c.executor(), *scene, camera, width, height);
}

namespace {

// The refraction passes' inputs from their nodes' (environment may be null: marking needs none).
RefractionInputs pass_inputs(const Scene& scene, const Camera& camera, const GBuffer& gbuffer,
                             const VisibilityBuffer& visibility, const ReflectorMaps& maps,
                             const EnvironmentMap* environment, const GBuffer* back, const VertexThickness* thickness,
                             const RefractorImpostors* impostors) {
  RefractionInputs in;
  in.front = &gbuffer;
  in.front_vis = &visibility;
  in.mesh = &scene.mesh;
  in.camera = camera;
  in.maps = &maps;
  in.env = environment;
  in.back = back;
  in.vertex_thickness = thickness;
  in.impostors = impostors;
  return in;
}

}  // namespace

std::vector<CubeTileMask> RefractionReadsPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                                          const VisibilityBuffer& visibility, const ReflectorMaps& maps,
                                                          const GBuffer* back, const VertexThickness* thickness,
                                                          const RefractorImpostors* impostors) const {
  std::vector<CubeTileMask> tiles = tile_masks_for_reads(maps);
  mark_refraction_reads(c.executor(), pass_inputs(*scene, camera, gbuffer, visibility, maps, nullptr, back, thickness, impostors),
                        options, tiles);
  return tiles;
}

ImageRGBA RefractionPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                    const VisibilityBuffer& visibility, const ReflectorMaps& maps,
                                    const EnvironmentMap& environment, const ImageRGBA& specular,
                                    const GBuffer* back, const VertexThickness* thickness,
                                    const RefractorImpostors* impostors) const {
  const RefractionInputs in =
      pass_inputs(*scene, camera, gbuffer, visibility, maps, &environment, back, thickness, impostors);
  RefractionLayer layer = refract_layer(c.executor(), in, options, specular);
  c.count("refracted", layer.refracted);
  c.count("total_internal", layer.total_internal);
  c.count("no_exit", layer.no_exit);
  c.count("exit_normal_fallbacks", layer.exit_normal_fallbacks);
  return std::move(layer.specular);
}

}  // namespace speculum::raster
