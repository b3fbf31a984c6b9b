// Per-vertex refractor thickness: see refractor_thickness.h.
#include "trace/refractor_thickness.h"

#include <cstdint>

#include <glm/geometric.hpp>

#include "core/shading.h"
#include "trace/bvh.h"
#include "trace/traversal.h"

namespace speculum::trace {

std::vector<float> refractor_vertex_thickness(const Scene& scene, par::Executor& executor) {
  const TriangleMesh& m = scene.mesh;
  const std::vector<std::uint8_t> refractors = refractor_objects(scene);
  std::vector<std::uint32_t> indices;
  std::vector<std::uint8_t> vertex_of_refractor(m.positions.size(), 0);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t o = m.triangle_object[t];
    if (o >= refractors.size() || !refractors[o]) continue;
    for (int k = 0; k < 3; ++k) {
      indices.push_back(m.indices[3 * t + k]);
      vertex_of_refractor[m.indices[3 * t + k]] = 1;
    }
  }
  std::vector<float> thickness(m.positions.size(), 0.0f);
  if (indices.empty()) return thickness;
  const Bvh bvh = Bvh::build(m.positions, indices, executor);
  const float scale = glm::length(scene.bounds().extent());
  // Per vertex: the bounding-box centre of its refractor.
  std::vector<Bounds> boxes(scene.objects.size());
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (refractors[m.triangle_object[t]])
      for (int k = 0; k < 3; ++k) boxes[m.triangle_object[t]].grow(m.positions[m.indices[3 * t + k]]);
  std::vector<glm::vec3> centre(m.positions.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (refractors[m.triangle_object[t]])
      for (int k = 0; k < 3; ++k) centre[m.indices[3 * t + k]] = boxes[m.triangle_object[t]].center();
  RayStream rays;
  rays.resize(m.positions.size());
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    Ray r;
    // Nudged towards the refractor's centre so rays from corner vertices do not graze
    // the neighbouring faces' edges (convex refractors).
    r.origin = m.positions[v] + 1e-4f * (centre[v] - m.positions[v]);
    r.direction = vertex_of_refractor[v] && v < m.normals.size() ? -m.normals[v] : glm::vec3(0, 0, 1);
    r.tmin = 1e-5f * scale;  // skip the vertex's own triangles
    r.tmax = vertex_of_refractor[v] ? 3.0e38f : 0.0f;
    rays.set(v, r);
  }
  HitStream hits;
  closest_hit_stream(bvh, rays, hits, executor);
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    if (vertex_of_refractor[v] && hits.triangle[v] != kNoHit) thickness[v] = hits.t[v];
  return thickness;
}

}  // namespace speculum::trace
