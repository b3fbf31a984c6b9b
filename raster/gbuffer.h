// The `gbuffer` node: resolves a visibility buffer into per-sample surface attributes —
// world position, shading normal (normal maps applied), uv, material parameters and
// reflector id (SOFF §3.1's G-buffer).
#pragma once

#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "core/shading.h"
#include "core/surface_plane.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/gbuffer_triangles.h"
#include "raster/visibility.h"

namespace speculum::raster {

struct GBuffer {
  int width = 0;
  int height = 0;
  IdBuffer object;                  // kNoId: background (nothing else is valid there)
  Buffer2D<glm::vec3> position;     // world space
  Buffer2D<glm::vec3> normal;       // unit shading normal, facing the camera side for
                                    // opaque surfaces; geometric orientation for refractors
  glm::vec3 eye{0.0f};              // the camera position (view directions derive from it)
  Buffer2D<glm::vec2> uv;
  SurfacePlane surface;             // diffuse colour, metallic, roughness, glossiness (Phong
                                    // exponent), ior, transmission, emissive: surface[i]; an
                                    // untextured material's samples share one entry
  IdBuffer reflector;               // object id of non-diffuse surfaces, kNoId otherwise

  bool covered(std::size_t i) const { return object.pixels[i] != kNoId; }
  // Unit direction from covered sample i towards the eye.
  glm::vec3 view_direction(std::size_t i) const {
    const glm::vec3 d = eye - position.pixels[i];
    const float l = glm::length(d);
    return l > 0.0f ? d / l : glm::vec3(0.0f, 0.0f, 1.0f);
  }
};

GBuffer resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                        const glm::vec3& eye);
// The same into `out`, reusing its memory when the size is unchanged. Every sample is
// rewritten: background samples get kNoId ids and the planes' default values.
void resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                     const glm::vec3& eye, GBuffer& out);
// The same reading the scene-static per-triangle records (built once per static scene, see
// gbuffer_triangles.h) instead of gathering through the mesh's index and vertex arrays: the
// same bytes, fewer cache and TLB misses. `triangles` null: the mesh arrays (as above).
// Throws InputError if they come from another mesh.
void resolve_gbuffer(par::Executor& executor, const Scene& scene, const GBufferTriangles* triangles,
                     const VisibilityBuffer& vis, const glm::vec3& eye, GBuffer& out);

// World position of covered visibility sample i (barycentric interpolation only): what
// distance-only passes (shadow and distance maps) need, without resolving materials.
inline glm::vec3 visible_position(const TriangleMesh& m, const VisibilityBuffer& vis,
                                  std::size_t i) {
  const std::uint32_t t = vis.triangle.pixels[i];
  const glm::vec2 b = vis.bary.pixels[i];
  return (1.0f - b.x - b.y) * m.positions[m.indices[3 * t]] +
         b.x * m.positions[m.indices[3 * t + 1]] + b.y * m.positions[m.indices[3 * t + 2]];
}

// |visible_position(m, vis, i) − from| for the covered samples i in [begin, end), written to
// out[i − begin] (uncovered samples' entries are left as they were): eight samples at a time
// in lanes, with the scalar expression's operations per lane (the same bits).
void visible_distances(const TriangleMesh& m, const VisibilityBuffer& vis, const glm::vec3& from, std::size_t begin,
                       std::size_t end, float* out);

// The scalar views of the G-buffer for inspection: specular level (max of F0 for
// non-diffuse surfaces, 0 otherwise) and glossiness (Phong exponent).
ImageF specular_level_image(const GBuffer& g);
ImageF glossiness_image(const GBuffer& g);

// The material-kind test used by every reflection node: the surface reflects its
// surroundings (mirror or glossy lobe) or refracts.
inline bool is_specular(const SurfaceParams& s) {
  return s.is_refractor() || s.roughness < kGlossyRoughness;
}

// Pass "gbuffer": the visibility buffer resolved into surface attributes.
struct GBufferPass {
  static constexpr const char* description =
      "Resolves the visibility buffer into world position, shading normal, uv and material "
      "parameters per sample: the G-buffer every reflection pass reads (SOFF §3.1).";
  const Scene* scene = nullptr;
  glm::vec3 eye{0.0f};
  GBuffer operator()(par::NodeContext& c, const VisibilityBuffer& visibility) const;
};

}  // namespace speculum::raster
