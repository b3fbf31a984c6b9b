// Vertex normals and tangents computed from geometry when an input lacks them:
// area-weighted face normals, and per-triangle uv-gradient tangents (MikkTSpace-like).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace speculum {

// Unit normal per vertex: the sum of the (unnormalised, hence area-weighted) face normals
// of the triangles using it. A vertex no non-degenerate triangle touches gets +Z.
std::vector<glm::vec3> area_weighted_normals(std::span<const glm::vec3> positions,
                                             std::span<const std::uint32_t> indices);

// Unit tangent per vertex (w = bitangent handedness +-1) from the uv gradients of the
// triangles around it, Gram-Schmidt orthogonalised against the vertex normal, in glTF's
// convention: cross(n, t) * w points up the image, along -dP/dv (core/normal_mapping.h).
// Where the uvs are degenerate an arbitrary tangent perpendicular to the normal is used.
std::vector<glm::vec4> uv_tangents(std::span<const glm::vec3> positions,
                                   std::span<const glm::vec3> normals,
                                   std::span<const glm::vec2> uvs,
                                   std::span<const std::uint32_t> indices);

// A unit vector perpendicular to unit `n` (stable for every direction).
glm::vec3 any_perpendicular(const glm::vec3& n);

}  // namespace speculum
