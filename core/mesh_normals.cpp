// Normals and tangents from geometry (see mesh_normals.h).
#include "core/mesh_normals.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/normal_mapping.h"

namespace speculum {

glm::vec3 any_perpendicular(const glm::vec3& n) {
  // Pick the axis least aligned with n so the cross product is well conditioned.
  const glm::vec3 a = std::fabs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(n, a));
}

std::vector<glm::vec3> area_weighted_normals(std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices) {
  std::vector<glm::vec3> sum(positions.size(), glm::vec3(0.0f));
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const std::uint32_t a = indices[i], b = indices[i + 1], c = indices[i + 2];
    if (a >= positions.size() || b >= positions.size() || c >= positions.size()) continue;
    // |cross| is twice the triangle area: summing unnormalised crosses weights by area.
    const glm::vec3 n = glm::cross(positions[b] - positions[a], positions[c] - positions[a]);
    if (!std::isfinite(n.x + n.y + n.z)) continue;
    sum[a] += n;
    sum[b] += n;
    sum[c] += n;
  }
  for (auto& n : sum) {
    const float len = glm::length(n);
    n = (len > 0.0f && std::isfinite(len)) ? n / len : glm::vec3(0, 0, 1);
  }
  return sum;
}

std::vector<glm::vec4> uv_tangents(std::span<const glm::vec3> positions,
                                   std::span<const glm::vec3> normals,
                                   std::span<const glm::vec2> uvs,
                                   std::span<const std::uint32_t> indices) {
  const std::size_t nv = positions.size();
  std::vector<UvGradients> sum(nv);
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const std::uint32_t v[3] = {indices[i], indices[i + 1], indices[i + 2]};
    if (v[0] >= nv || v[1] >= nv || v[2] >= nv) continue;
    const UvGradients g = triangle_uv_gradients(positions[v[1]] - positions[v[0]],
                                                positions[v[2]] - positions[v[0]],
                                                uvs[v[1]] - uvs[v[0]], uvs[v[2]] - uvs[v[0]]);
    if (!g.valid) continue;
    for (std::uint32_t k : v) {
      sum[k].t += g.t;
      sum[k].v += g.v;
    }
  }
  std::vector<glm::vec4> out(nv);
  for (std::size_t k = 0; k < nv; ++k) out[k] = tangent_from_gradients(normals[k], sum[k]);
  return out;
}

}  // namespace speculum
