// Hand-made scenes and a brute-force ray–triangle oracle for the raster tests (kept
// independent of core's procedural scenes so the rasterizer is tested on its own).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/camera_rays.h"
#include "core/scene.h"

namespace speculum::raster::testing {

// Appends a triangle soup object with per-vertex normals/uvs to `scene`.
inline void add_triangles(Scene& scene, const std::vector<glm::vec3>& positions,
                          const std::vector<std::uint32_t>& indices,
                          const std::vector<glm::vec2>& uvs = {}, std::uint32_t material = 0) {
  TriangleMesh& m = scene.mesh;
  const auto base = static_cast<std::uint32_t>(m.positions.size());
  const auto first_triangle = static_cast<std::uint32_t>(m.triangle_count());
  const auto object = static_cast<std::uint32_t>(scene.objects.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    m.positions.push_back(positions[i]);
    m.normals.push_back(glm::vec3(0, 0, 1));
    m.uvs.push_back(uvs.empty() ? glm::vec2(0.0f) : uvs[i]);
  }
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    const glm::vec3 a = positions[indices[i]], b = positions[indices[i + 1]],
                    c = positions[indices[i + 2]];
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    for (int k = 0; k < 3; ++k) {
      m.indices.push_back(base + indices[i + k]);
      if (len > 0.0f) m.normals[base + indices[i + k]] = n / len;
    }
    m.triangle_material.push_back(material);
    m.triangle_object.push_back(object);
  }
  if (scene.materials.empty()) scene.materials.push_back(Material{});
  scene.objects.push_back({"object" + std::to_string(object), first_triangle,
                           static_cast<std::uint32_t>(indices.size() / 3), material});
}

// A closed torus (major radius R, minor r) around `centre` in the XY plane, CCW outward.
inline void add_torus(Scene& scene, const glm::vec3& centre, float R, float r, int nu, int nv) {
  std::vector<glm::vec3> p;
  std::vector<std::uint32_t> idx;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float u = 2.0f * 3.14159265f * i / nu, v = 2.0f * 3.14159265f * j / nv;
      p.push_back(centre + glm::vec3((R + r * std::cos(v)) * std::cos(u),
                                     (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)));
    }
  auto at = [&](int i, int j) { return std::uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      idx.insert(idx.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      idx.insert(idx.end(), {at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  add_triangles(scene, p, idx);
}

struct OracleHit {
  std::uint32_t triangle = 0xffffffffu;
  double t = std::numeric_limits<double>::infinity();
  double b1 = 0, b2 = 0;
  double min_edge_distance = 0;  // smallest barycentric of the hit: ~0 means on an edge
};

// Closest hit over all triangles (Möller–Trumbore in double), view depth >= znear.
inline OracleHit oracle_closest_hit(const Scene& scene, const Ray& ray, const glm::dvec3& forward,
                                    double znear) {
  OracleHit best;
  const TriangleMesh& m = scene.mesh;
  const glm::dvec3 o(ray.origin), d(ray.direction);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::dvec3 a(m.positions[m.indices[3 * t]]), b(m.positions[m.indices[3 * t + 1]]),
        c(m.positions[m.indices[3 * t + 2]]);
    const glm::dvec3 e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
    const double det = glm::dot(e1, pv);
    if (det == 0.0) continue;
    const glm::dvec3 tv = o - a;
    const double u = glm::dot(tv, pv) / det;
    const glm::dvec3 qv = glm::cross(tv, e1);
    const double v = glm::dot(d, qv) / det;
    const double dist = glm::dot(e2, qv) / det;
    if (u < 0 || v < 0 || u + v > 1 || dist <= 0) continue;
    if (dist * glm::dot(d, forward) < znear) continue;
    if (dist < best.t) {
      best.triangle = static_cast<std::uint32_t>(t);
      best.t = dist;
      best.b1 = u;
      best.b2 = v;
      best.min_edge_distance = std::min({u, v, 1 - u - v});
    }
  }
  return best;
}

}  // namespace speculum::raster::testing
