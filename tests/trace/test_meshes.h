// Meshes and rays for the trace tests: random and degenerate soups, a closed UV sphere, and a
// tiny OFF reader for the assimp test models (the test must not depend on the core loader).
#pragma once

#include <cmath>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "core/camera_rays.h"
#include "core/sampling.h"

namespace speculum::trace::testing {

struct Soup {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  void add(glm::vec3 a, glm::vec3 b, glm::vec3 c) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    indices.insert(indices.end(), {base, base + 1, base + 2});
  }
};

inline float rnd(std::uint32_t i, std::uint32_t dim, std::uint32_t seed) { return random_float(i, 0, dim, seed); }
inline glm::vec3 rnd3(std::uint32_t i, std::uint32_t seed, float lo, float hi) {
  return glm::vec3(rnd(i, 0, seed), rnd(i, 1, seed), rnd(i, 2, seed)) * (hi - lo) + lo;
}

inline Soup random_soup(std::uint32_t n, std::uint32_t seed, float size = 0.2f) {
  Soup s;
  for (std::uint32_t i = 0; i < n; ++i) {
    const glm::vec3 c = rnd3(i, seed, -1.0f, 1.0f);
    s.add(c + rnd3(i, seed + 1, -size, size), c + rnd3(i, seed + 2, -size, size), c + rnd3(i, seed + 3, -size, size));
  }
  return s;
}

// Closed UV sphere with shared vertices (poles included), `rings` x `segments`.
inline Soup uv_sphere(int rings, int segments, glm::vec3 centre = glm::vec3(0), float radius = 1.0f) {
  Soup s;
  for (int r = 0; r <= rings; ++r)
    for (int k = 0; k < segments; ++k) {
      const float th = kPi * r / rings, ph = 2 * kPi * k / segments;
      s.positions.push_back(centre + radius * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  auto id = [&](int r, int k) { return static_cast<std::uint32_t>(r * segments + (k % segments)); };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      if (r > 0) s.indices.insert(s.indices.end(), {id(r, k), id(r + 1, k), id(r, k + 1)});
      if (r + 1 < rings) s.indices.insert(s.indices.end(), {id(r, k + 1), id(r + 1, k), id(r + 1, k + 1)});
    }
  return s;
}

// OFF (ASCII) with polygon faces fan-triangulated; empty soup when the file is missing.
inline Soup read_off(const std::string& path) {
  Soup s;
  std::ifstream in(path);
  std::string magic;
  if (!(in >> magic) || magic != "OFF") return s;
  std::size_t nv = 0, nf = 0, ne = 0;
  in >> nv >> nf >> ne;
  s.positions.resize(nv);
  for (auto& p : s.positions) in >> p.x >> p.y >> p.z;
  for (std::size_t f = 0; f < nf; ++f) {
    std::size_t k = 0;
    in >> k;
    std::vector<std::uint32_t> v(k);
    for (auto& x : v) in >> x;
    for (std::size_t i = 1; i + 1 < k; ++i) s.indices.insert(s.indices.end(), {v[0], v[i], v[i + 1]});
  }
  if (!in) return Soup{};
  return s;
}

// Random rays from a shell around the unit cube aimed at random points inside it.
inline Ray random_ray(std::uint32_t i, std::uint32_t seed) {
  Ray r;
  r.origin = rnd3(i, seed, -3.0f, 3.0f);
  r.direction = rnd3(i, seed + 7, -1.0f, 1.0f) - r.origin;
  return r;
}

}  // namespace speculum::trace::testing
