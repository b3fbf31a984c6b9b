// Closest-hit surface decoding: see hit_surface.h.
#include "trace/hit_surface.h"

#include <glm/geometric.hpp>

#include "core/normal_mapping.h"

namespace speculum::trace {

HitSurface hit_surface(const Scene& scene, const Hit& h, const glm::vec3& ray_direction) {
  HitSurface out;
  const TriangleMesh& m = scene.mesh;
  const std::uint32_t t = h.triangle;
  const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
  const float w0 = 1.0f - h.u - h.v;
  const glm::vec3 dir = glm::normalize(ray_direction);
  out.p = m.positions[i0] * w0 + m.positions[i1] * h.u + m.positions[i2] * h.v;
  glm::vec3 ng = glm::cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]);
  const float len = glm::length(ng);
  ng = len > 0.0f ? ng / len : -dir;
  glm::vec3 n = ng;
  if (m.normals.size() == m.positions.size()) {
    const glm::vec3 s = m.normals[i0] * w0 + m.normals[i1] * h.u + m.normals[i2] * h.v;
    if (glm::length(s) > 0.0f) n = glm::normalize(s);
  }
  glm::vec2 uv(0.0f), uv1(0.0f);
  if (m.uvs.size() == m.positions.size()) uv = m.uvs[i0] * w0 + m.uvs[i1] * h.u + m.uvs[i2] * h.v;
  if (m.uvs1.size() == m.positions.size()) uv1 = m.uvs1[i0] * w0 + m.uvs1[i1] * h.u + m.uvs1[i2] * h.v;
  const std::uint32_t mat = t < m.triangle_material.size() ? m.triangle_material[t] : 0u;
  out.s = surface_params(scene, mat, uv, uv1);
  // The normal map perturbs the interpolated normal in the surface's own frame; the side
  // it is turned to is decided by the unperturbed normal (as in the G-buffer), so a map
  // tilting it past the incident side's horizon is not mirrored into the surface.
  glm::vec3 shading = n;
  if (mat < scene.materials.size() && scene.materials[mat].normal_texture.valid()) {
    const Material& material = scene.materials[mat];
    shading = normal_mapped(scene, material, n,
                            surface_tangent(m, t, h.u, h.v, n, material.normal_texture.texcoord), uv, uv1);
  }
  out.entering = glm::dot(ng, dir) < 0.0f;
  if (!out.entering) ng = -ng;
  if (glm::dot(n, ng) < 0.0f) shading = -shading;
  out.ng = ng;
  out.n = shading;
  return out;
}

}  // namespace speculum::trace
