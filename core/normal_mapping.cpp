// Tangent-space normal mapping (see normal_mapping.h for the convention).
#include "core/normal_mapping.h"

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "core/mesh_normals.h"
#include "core/shading.h"

namespace speculum {

glm::vec3 perturb_normal(const glm::vec3& n, const glm::vec4& tangent, const glm::vec4& texel,
                         float scale) {
  glm::vec3 nt = glm::vec3(texel) * 2.0f - 1.0f;
  nt.x *= scale;
  nt.y *= scale;
  glm::vec3 t = glm::vec3(tangent);
  t = t - glm::dot(t, n) * n;  // Gram–Schmidt: interpolated tangents drift off the plane
  const float tl = glm::length(t);
  if (!(tl > 1e-8f)) return n;
  t /= tl;
  const glm::vec3 b = (tangent.w < 0.0f ? -1.0f : 1.0f) * glm::cross(n, t);
  const glm::vec3 mapped = t * nt.x + b * nt.y + n * nt.z;
  const float ml = glm::length(mapped);
  return ml > 1e-8f ? mapped / ml : n;
}

glm::vec3 normal_mapped(const Scene& scene, const Material& m, const glm::vec3& n,
                        const glm::vec4& tangent, glm::vec2 uv, glm::vec2 uv1) {
  const TextureRef& ref = m.normal_texture;
  if (!ref.valid() || static_cast<std::size_t>(ref.texture) >= scene.textures.size()) return n;
  const glm::vec2 base = ref.texcoord == 1 ? uv1 : uv;
  const glm::vec2 tuv = glm::vec2(ref.uv_transform * glm::vec3(base, 1.0f));
  return perturb_normal(n, tangent, sample_bilinear_repeat(scene.textures[ref.texture], tuv),
                        m.normal_scale);
}

UvGradients triangle_uv_gradients(const glm::vec3& e1, const glm::vec3& e2, const glm::vec2& d1,
                                  const glm::vec2& d2) {
  UvGradients g;
  const float det = d1.x * d2.y - d2.x * d1.y;
  if (!(std::fabs(det) >= 1e-20f)) return g;
  // Solve [e1 e2] = [T V] [d1 d2] for T = dP/du, V = dP/dv. Not dividing by det keeps the
  // uv-area weighting; multiplying by its sign keeps the directions.
  const float s = det > 0.0f ? 1.0f : -1.0f;
  g.t = (e1 * d2.y - e2 * d1.y) * s;
  g.v = (e2 * d1.x - e1 * d2.x) * s;
  g.valid = std::isfinite(g.t.x + g.t.y + g.t.z + g.v.x + g.v.y + g.v.z);
  return g;
}

glm::vec4 tangent_from_gradients(const glm::vec3& n, const UvGradients& g) {
  glm::vec3 t = g.t - n * glm::dot(n, g.t);
  const float len = glm::length(t);
  t = (len > 1e-20f && std::isfinite(len)) ? t / len : any_perpendicular(n);
  // The map's +Y is the image's up, −dP/dv (uv origin at the top-left): w = −1 where
  // cross(n, T) runs down the image instead.
  const float w = glm::dot(glm::cross(n, t), g.v) > 0.0f ? -1.0f : 1.0f;
  return glm::vec4(t, w);
}

glm::vec4 surface_tangent(const TriangleMesh& mesh, std::uint32_t triangle, float b1, float b2,
                          const glm::vec3& n, int texcoord) {
  const std::uint32_t i0 = mesh.indices[3 * std::size_t(triangle)];
  const std::uint32_t i1 = mesh.indices[3 * std::size_t(triangle) + 1];
  const std::uint32_t i2 = mesh.indices[3 * std::size_t(triangle) + 2];
  if (mesh.tangents.size() == mesh.positions.size()) {
    const float b0 = 1.0f - b1 - b2;
    return b0 * mesh.tangents[i0] + b1 * mesh.tangents[i1] + b2 * mesh.tangents[i2];
  }
  const auto& uvs = texcoord == 1 && mesh.uvs1.size() == mesh.positions.size() ? mesh.uvs1 : mesh.uvs;
  UvGradients g;
  if (uvs.size() == mesh.positions.size())
    g = triangle_uv_gradients(mesh.positions[i1] - mesh.positions[i0],
                              mesh.positions[i2] - mesh.positions[i0], uvs[i1] - uvs[i0],
                              uvs[i2] - uvs[i0]);
  return tangent_from_gradients(n, g);
}

}  // namespace speculum
