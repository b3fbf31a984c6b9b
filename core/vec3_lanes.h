// Vec3Lanes<W>: W glm::vec3 held as three lanes of floats (x, y, z), with glm's vec3
// operations in glm's own order — dot is (x·x' + y·y') + z·z', cross is glm::cross's
// component formulas, a vector divided by a scalar divides each component — so a kernel
// written with them gives every lane the bits of the scalar glm code it mirrors (the build
// forbids contraction: parallel/lanes.h). The helpers here and in core/brdf_lanes.h are
// always inlined: left to itself GCC kept several as calls that pass the lanes through
// memory (a fifth of the direct light's samples were in them and their call overhead).
#pragma once

#include <glm/vec3.hpp>

#include "parallel/lanes.h"

namespace speculum {

template <int W>
struct Vec3Lanes {
  using L = par::Lanes<W>;
  using f32 = typename L::f32;
  using mask = typename L::mask;
  f32 x, y, z;

  Vec3Lanes() = default;
  Vec3Lanes(f32 x_, f32 y_, f32 z_) : x(x_), y(y_), z(z_) {}
  explicit Vec3Lanes(const glm::vec3& v) : x(v.x), y(v.y), z(v.z) {}

  // v[0, count) into lanes; lanes past count repeat v[0] (valid inputs whose results the
  // caller drops).
  static Vec3Lanes load(const glm::vec3* v, int count) {
    alignas(64) float c[3][W];
    for (int j = 0; j < W; ++j) {
      const glm::vec3& e = v[j < count ? j : 0];
      c[0][j] = e.x, c[1][j] = e.y, c[2][j] = e.z;
    }
    return {L::load(c[0]), L::load(c[1]), L::load(c[2])};
  }
  void store(glm::vec3* v, int count) const {
    alignas(64) float c[3][W];
    L::store(x, c[0]), L::store(y, c[1]), L::store(z, c[2]);
    for (int j = 0; j < count; ++j) v[j] = glm::vec3(c[0][j], c[1][j], c[2][j]);
  }

  friend Vec3Lanes operator+(const Vec3Lanes& a, const Vec3Lanes& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3Lanes operator-(const Vec3Lanes& a, const Vec3Lanes& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3Lanes operator*(const Vec3Lanes& a, const Vec3Lanes& b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
  friend Vec3Lanes operator*(const Vec3Lanes& a, const f32& s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3Lanes operator*(const f32& s, const Vec3Lanes& a) { return {s * a.x, s * a.y, s * a.z}; }
  friend Vec3Lanes operator/(const Vec3Lanes& a, const f32& s) { return {a.x / s, a.y / s, a.z / s}; }
  friend Vec3Lanes operator-(const Vec3Lanes& a) { return {-a.x, -a.y, -a.z}; }
};

template <int W>
[[gnu::always_inline]] inline typename Vec3Lanes<W>::f32 dot(const Vec3Lanes<W>& a, const Vec3Lanes<W>& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}

template <int W>
[[gnu::always_inline]] inline Vec3Lanes<W> cross(const Vec3Lanes<W>& a, const Vec3Lanes<W>& b) {
  return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}

// m ? a : b per lane.
template <int W>
[[gnu::always_inline]] inline Vec3Lanes<W> select(const typename Vec3Lanes<W>::mask& m, const Vec3Lanes<W>& a, const Vec3Lanes<W>& b) {
  using L = par::Lanes<W>;
  return {L::select(m, a.x, b.x), L::select(m, a.y, b.y), L::select(m, a.z, b.z)};
}

}  // namespace speculum
