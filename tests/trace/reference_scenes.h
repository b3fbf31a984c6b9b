// Hand-built scenes for the reference tracer tests: materials and flat-shaded triangles,
// quads, boxes and UV spheres appended to a Scene's mesh (object 0).
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>

#include "core/sampling.h"
#include "core/scene.h"

namespace speculum::trace::testing {

inline std::uint32_t add_material(Scene& s, glm::vec3 color, float metallic, float roughness, glm::vec3 emissive = {},
                           float transmission = 0.0f, float ior = 1.5f) {
  Material m;
  m.base_color = glm::vec4(color, 1.0f);
  m.metallic = metallic;
  m.roughness = roughness;
  m.emissive = emissive;
  m.transmission = transmission;
  m.ior = ior;
  s.materials.push_back(m);
  return static_cast<std::uint32_t>(s.materials.size() - 1);
}

inline void add_tri(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, std::uint32_t mat) {
  auto& m = s.mesh;
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  m.positions.insert(m.positions.end(), {a, b, c});
  m.normals.insert(m.normals.end(), {n, n, n});
  m.uvs.insert(m.uvs.end(), 3, glm::vec2(0));
  m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
  m.triangle_material.push_back(mat);
  m.triangle_object.push_back(0);
}
inline void add_quad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t mat) {
  add_tri(s, a, b, c, mat);
  add_tri(s, a, c, d, mat);
}
// Axis-aligned box [lo, hi], faces outward.
inline void add_box(Scene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t mat) {
  const glm::vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  add_quad(s, p[0], p[3], p[2], p[1], mat);
  add_quad(s, p[4], p[5], p[6], p[7], mat);
  add_quad(s, p[0], p[1], p[5], p[4], mat);
  add_quad(s, p[3], p[7], p[6], p[2], mat);
  add_quad(s, p[0], p[4], p[7], p[3], mat);
  add_quad(s, p[1], p[2], p[6], p[5], mat);
}
inline void add_sphere(Scene& s, glm::vec3 c, float r, int rings, int segs, std::uint32_t mat) {
  auto& m = s.mesh;
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  for (int i = 0; i <= rings; ++i)
    for (int k = 0; k <= segs; ++k) {
      const float th = kPi * i / rings, ph = 2 * kPi * k / segs;
      const glm::vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      m.positions.push_back(c + r * n);
      m.normals.push_back(n);
      m.uvs.emplace_back(0.0f);
    }
  auto id = [&](int i, int k) { return base + static_cast<std::uint32_t>(i * (segs + 1) + k); };
  for (int i = 0; i < rings; ++i)
    for (int k = 0; k < segs; ++k) {
      m.indices.insert(m.indices.end(), {id(i, k), id(i, k + 1), id(i + 1, k)});
      m.indices.insert(m.indices.end(), {id(i, k + 1), id(i + 1, k + 1), id(i + 1, k)});
      m.triangle_material.insert(m.triangle_material.end(), 2, mat);
      m.triangle_object.insert(m.triangle_object.end(), 2, 0u);
    }
}

}  // namespace speculum::trace::testing
