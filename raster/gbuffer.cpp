// The `gbuffer` node: see gbuffer.h. Normal mapping follows glTF: tangent-space normal
// n_t = 2·texel − 1 with xy scaled by normal_scale, N' = normalize(T n_t.x + B n_t.y + N n_t.z),
// B = w · (N × T).
#include "raster/gbuffer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace speculum::raster {
namespace {

constexpr std::size_t kPixelChunk = 4096;

glm::vec3 apply_normal_map(const Scene& scene, const Material& m, const glm::vec3& n,
                           const glm::vec4& tangent, glm::vec2 uv, glm::vec2 uv1) {
  const TextureRef& ref = m.normal_texture;
  if (!ref.valid() || static_cast<std::size_t>(ref.texture) >= scene.textures.size()) return n;
  const glm::vec2 base = ref.texcoord == 1 ? uv1 : uv;
  const glm::vec2 tuv = glm::vec2(ref.uv_transform * glm::vec3(base, 1.0f));
  const glm::vec4 texel = sample_bilinear_repeat(scene.textures[ref.texture], tuv);
  glm::vec3 nt = glm::vec3(texel) * 2.0f - 1.0f;
  nt.x *= m.normal_scale;
  nt.y *= m.normal_scale;
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

template <class T>
void ensure_size(Buffer2D<T>& b, int width, int height) {
  if (b.width != width || b.height != height) b = Buffer2D<T>(width, height);
}

}  // namespace

GBuffer resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                        const glm::vec3& eye) {
  GBuffer g;
  resolve_gbuffer(executor, scene, vis, eye, g);
  return g;
}

void resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                     const glm::vec3& eye, GBuffer& g) {
  const int w = vis.width, h = vis.height;
  g.width = w;
  g.height = h;
  ensure_size(g.object, w, h);
  ensure_size(g.position, w, h);
  ensure_size(g.normal, w, h);
  g.eye = eye;
  ensure_size(g.uv, w, h);
  ensure_size(g.surface, w, h);
  ensure_size(g.reflector, w, h);
  const TriangleMesh& m = scene.mesh;
  const bool has_uv1 = !m.uvs1.empty();
  const bool has_tangents = !m.tangents.empty();
  // Untextured materials have the same parameters everywhere: evaluate them once.
  std::vector<SurfaceParams> constant_params;
  std::vector<std::uint8_t> textured;
  for (const Material& mat : scene.materials) {
    constant_params.push_back(surface_params(mat));
    textured.push_back(mat.base_color_texture.valid() || mat.metallic_roughness_texture.valid() ||
                       mat.emissive_texture.valid() || mat.transmission_texture.valid());
  }
  executor.parallel_for("gbuffer.resolve", vis.triangle.size(), kPixelChunk,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t t = vis.triangle.pixels[i];
      g.object.pixels[i] = vis.object.pixels[i];
      if (t == kNoId) {
        g.reflector.pixels[i] = kNoId;
        continue;
      }
      const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1],
                          i2 = m.indices[3 * t + 2];
      const glm::vec2 b = vis.bary.pixels[i];
      const float b0 = 1.0f - b.x - b.y;
      auto lerp3 = [&](const auto& a) { return b0 * a[i0] + b.x * a[i1] + b.y * a[i2]; };
      const glm::vec3 p = lerp3(m.positions);
      glm::vec3 n = lerp3(m.normals);
      const float nl = glm::length(n);
      const glm::vec3 face = glm::cross(m.positions[i1] - m.positions[i0],
                                        m.positions[i2] - m.positions[i0]);
      n = nl > 1e-12f ? n / nl : glm::normalize(face);
      const glm::vec2 uv = lerp3(m.uvs);
      const glm::vec2 uv1 = has_uv1 ? lerp3(m.uvs1) : glm::vec2(0.0f);
      const std::uint32_t mat = m.triangle_material[t];
      const Material& material = scene.materials[mat];
      if (has_tangents) n = apply_normal_map(scene, material, n, lerp3(m.tangents), uv, uv1);
      const glm::vec3 to_eye = eye - p;
      const float dl = glm::length(to_eye);
      const glm::vec3 v = dl > 0.0f ? to_eye / dl : glm::vec3(0, 0, 1);
      const SurfaceParams s =
          textured[mat] ? surface_params(scene, mat, uv, uv1) : constant_params[mat];
      // Opaque surfaces are shaded on the side the camera sees (double-sided or not, a
      // visible back face would otherwise shade black); refractors keep their orientation
      // so the reflection node knows whether the ray enters or leaves.
      if (!s.is_refractor() && glm::dot(n, v) < 0.0f) n = -n;
      g.position.pixels[i] = p;
      g.normal.pixels[i] = n;
      g.uv.pixels[i] = uv;
      g.surface.pixels[i] = s;
      g.reflector.pixels[i] = is_specular(s) ? vis.object.pixels[i] : kNoId;
    }
  });
}

ImageF specular_level_image(const GBuffer& g) {
  ImageF out(g.width, g.height, 0.0f);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!g.covered(i) || !is_specular(g.surface.pixels[i])) continue;
    const glm::vec3 f0 = specular_f0(g.surface.pixels[i]);
    out.pixels[i] = std::max({f0.x, f0.y, f0.z});
  }
  return out;
}

ImageF glossiness_image(const GBuffer& g) {
  ImageF out(g.width, g.height, 0.0f);
  for (std::size_t i = 0; i < out.size(); ++i)
    if (g.covered(i)) out.pixels[i] = g.surface.pixels[i].phong_exponent;
  return out;
}

}  // namespace speculum::raster
