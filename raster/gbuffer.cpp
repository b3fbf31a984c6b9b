// The `gbuffer` node: see gbuffer.h. Normal mapping follows glTF: tangent-space normal
// n_t = 2·texel − 1 with xy scaled by normal_scale, N' = normalize(T n_t.x + B n_t.y + N n_t.z),
// B = w · (N × T).
#include "raster/gbuffer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
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

struct SampleContext {
  const Scene& scene;
  const TriangleMesh& m;
  const VisibilityBuffer& vis;
  const glm::vec3& eye;
  const std::vector<SurfaceParams>& constant_params;
  const std::vector<std::uint8_t>& textured;
  const std::vector<std::uint8_t>& normal_mapped;
};

// Resolves visibility sample i into g (only the ids on background).
inline void resolve_sample(const SampleContext& c, std::size_t i, GBuffer& g) {
  const std::uint32_t t = c.vis.triangle.pixels[i];
  const std::uint32_t object = c.vis.object.pixels[i];
  g.object.pixels[i] = object;
  if (t == kNoId) {
    g.reflector.pixels[i] = kNoId;
    return;
  }
  const TriangleMesh& m = c.m;
  const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
  const glm::vec2 b = c.vis.bary.pixels[i];
  const float b0 = 1.0f - b.x - b.y;
  auto lerp3 = [&](const auto& a) { return b0 * a[i0] + b.x * a[i1] + b.y * a[i2]; };
  const glm::vec3 p = lerp3(m.positions);
  glm::vec3 n = lerp3(m.normals);
  const float nl = glm::length(n);
  if (nl > 1e-12f) {
    n = n / nl;
  } else {  // degenerate interpolated normal: fall back to the face normal
    n = glm::normalize(
        glm::cross(m.positions[i1] - m.positions[i0], m.positions[i2] - m.positions[i0]));
  }
  const glm::vec2 uv = lerp3(m.uvs);
  const std::uint32_t mat = m.triangle_material[t];
  const bool textured = c.textured[mat] != 0, normal_mapped = c.normal_mapped[mat] != 0;
  const glm::vec2 uv1 =
      (textured || normal_mapped) && !m.uvs1.empty() ? lerp3(m.uvs1) : glm::vec2(0.0f);
  if (normal_mapped)
    n = apply_normal_map(c.scene, c.scene.materials[mat], n, lerp3(m.tangents), uv, uv1);
  SurfaceParams& sp = g.surface.pixels[i];
  sp = textured ? surface_params(c.scene, mat, uv, uv1) : c.constant_params[mat];
  // Opaque surfaces are shaded on the side the camera sees (double-sided or not, a visible
  // back face would otherwise shade black); refractors keep their orientation so the
  // reflection node knows whether the ray enters or leaves. Only the sign of N·V matters,
  // so V is not normalized.
  if (!sp.is_refractor() && glm::dot(n, c.eye - p) < 0.0f) n = -n;
  g.position.pixels[i] = p;
  g.normal.pixels[i] = n;
  g.uv.pixels[i] = uv;
  g.reflector.pixels[i] = is_specular(sp) ? object : kNoId;
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
  // Untextured materials have the same parameters everywhere: evaluate them once.
  std::vector<SurfaceParams> constant_params;
  std::vector<std::uint8_t> textured, normal_mapped;
  for (const Material& mat : scene.materials) {
    constant_params.push_back(surface_params(mat));
    textured.push_back(mat.base_color_texture.valid() || mat.metallic_roughness_texture.valid() ||
                       mat.emissive_texture.valid() || mat.transmission_texture.valid());
    normal_mapped.push_back(!m.tangents.empty() && mat.normal_texture.valid());
  }
  const SampleContext ctx{scene, m, vis, eye, constant_params, textured, normal_mapped};
  executor.parallel_for("gbuffer.resolve", vis.triangle.size(), kPixelChunk,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) resolve_sample(ctx, i, g);
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
