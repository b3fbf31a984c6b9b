// Tangent-space normal mapping as glTF 2.0 defines it, shared by the rasterizer's G-buffer
// and the ray tracers' hit decoding so that both perturb the shading normal the same way.
//
// The convention (glTF 2.0 spec §3.9.3 normalTexture, §3.7.2.1 TANGENT, §3.8.1 texture
// coordinates):
//  - a texel's rgb encodes the tangent-space normal n_t = 2·rgb − 1 with +X right (along +u),
//    +Y up, +Z out of the surface; "up" is towards the image's top row, and uv (0, 0) is the
//    image's upper-left corner, so +Y points along −dP/dv;
//  - normalTexture.scale multiplies n_t.x and n_t.y before normalization;
//  - the bitangent is B = cross(N, T.xyz) · T.w;
//  - N' = normalize(T n_t.x + B n_t.y + N n_t.z), with T made orthogonal to N first
//    (interpolated tangents drift off the tangent plane).
#pragma once

#include <cstdint>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/scene.h"

namespace speculum {

// The perturbed shading normal for unit normal n, tangent (xyz, w = bitangent sign), the
// normal texture's texel and normalTexture.scale. Returns n unchanged where the tangent is
// (nearly) parallel to n or the mapped normal has no length.
glm::vec3 perturb_normal(const glm::vec3& n, const glm::vec4& tangent, const glm::vec4& texel,
                         float scale);

// The shading normal of material m at (uv, uv1) — TEXCOORD_0 and _1 — with unit normal n and
// tangent `tangent`: m's normal texture sampled (bilinear, repeat, after its uv transform)
// and applied by perturb_normal. n itself when m has no (valid) normal texture.
glm::vec3 normal_mapped(const Scene& scene, const Material& m, const glm::vec3& n,
                        const glm::vec4& tangent, glm::vec2 uv, glm::vec2 uv1);

// The uv gradients of one triangle with edges e1 = P1 − P0, e2 = P2 − P0 and uv edges
// d1, d2: T ∝ dP/du and V ∝ dP/dv, both scaled by |det| of the uv edge matrix (so sums over
// the triangles around a vertex weight them by uv area). valid is false for a degenerate
// uv triangle or a non-finite result.
struct UvGradients {
  glm::vec3 t{0.0f}, v{0.0f};
  bool valid = false;
};
UvGradients triangle_uv_gradients(const glm::vec3& e1, const glm::vec3& e2, const glm::vec2& d1,
                                  const glm::vec2& d2);

// The glTF tangent for unit normal n from (summed) uv gradients: T = dP/du made orthogonal
// to n and unit (any perpendicular of n where that vanishes), w = +1 where cross(n, T) points
// up the image (along −dP/dv), −1 where the uv layout is mirrored.
glm::vec4 tangent_from_gradients(const glm::vec3& n, const UvGradients& g);

// The tangent at barycentrics (b1, b2) of triangle `triangle` with unit shading normal n:
// the interpolated vertex tangent (mesh.tangents, from TANGENT or derived at load time) when
// the mesh has them, otherwise derived from that triangle's own gradients of uv set
// `texcoord` (0 or 1). Both rasterizer and tracers take the normal map's tangent from here.
glm::vec4 surface_tangent(const TriangleMesh& mesh, std::uint32_t triangle, float b1, float b2,
                          const glm::vec3& n, int texcoord);

}  // namespace speculum
