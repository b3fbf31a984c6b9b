// BVH on real meshes: Debian's assimp-testmodels loaded through the
// project's loaders (OFF, PLY ASCII/binary, STL ASCII/binary, glTF binary); both layouts,
// closest hit and any hit, and 8-ray packets return the all-pairs oracle's (t, triangle)
// for random and adversarial rays; and real meshes are watertight: rays aimed exactly at
// their shared (manifold) edges and vertices, across the surface, never miss.
#include <gtest/gtest.h>

#include "tests/test_dependency.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "core/scene_loader.h"
#include "trace/bvh.h"
#include "trace/packet_traversal.h"
#include "trace/traversal.h"
#include "tests/trace/oracle_checks.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

const std::string kModels = "/usr/share/assimp/models/";

using testing::bits;

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  glm::vec3 lo{3e38f}, hi{-3e38f};
  std::size_t triangles() const { return indices.size() / 3; }
  glm::vec3 vertex(std::size_t t, int k) const { return positions[indices[3 * t + k]]; }
};

// Loads through the project's loader; empty when assimp-testmodels is not installed.
Mesh load(const std::string& rel) {
  Mesh m;
  if (!std::filesystem::exists(kModels + rel)) return m;
  const Scene scene = load_scene(kModels + rel);
  m.positions = scene.mesh.positions;
  m.indices = scene.mesh.indices;
  for (const glm::vec3& p : m.positions) {
    m.lo = glm::min(m.lo, p);
    m.hi = glm::max(m.hi, p);
  }
  return m;
}

// Random rays from a shell around the bounds aimed at random points inside them, and
// adversarial ones: aimed exactly at vertices and edge points (from outside and from the
// centre), axis-aligned through vertices (zero direction components, origins on box
// planes), starting on the surface (tmin 0 and small), and clipped exactly at the
// oracle's hit distance (tmax = t and the float below).
std::vector<Ray> rays_for(const Mesh& m, int budget) {
  std::vector<Ray> rays;
  const glm::vec3 c = 0.5f * (m.lo + m.hi);
  const float diag = std::max(glm::length(m.hi - m.lo), 1e-3f);
  const auto R = [](std::uint32_t i, std::uint32_t d, std::uint32_t seed) { return testing::rnd(i, d, seed); };
  auto inside = [&](std::uint32_t i, std::uint32_t seed) {
    return m.lo + (m.hi - m.lo) * glm::vec3(R(i, 0, seed), R(i, 1, seed), R(i, 2, seed));
  };
  const int per_kind = std::max(8, budget / 6);
  for (int i = 0; i < per_kind; ++i) {  // random
    Ray r;
    r.origin = c + diag * (glm::vec3(R(i, 0, 3), R(i, 1, 3), R(i, 2, 3)) * 3.0f - 1.5f);
    r.direction = inside(i, 4) - r.origin;
    rays.push_back(r);
  }
  const std::size_t stride = std::max<std::size_t>(1, m.triangles() / static_cast<std::size_t>(per_kind / 4 + 1));
  for (std::size_t t = 0; t < m.triangles(); t += stride) {  // at features
    const int e = static_cast<int>(t % 3);
    const glm::vec3 a = m.vertex(t, e), b = m.vertex(t, (e + 1) % 3);
    for (const glm::vec3& target : {a, 0.5f * (a + b)}) {
      Ray out;
      out.origin = c + glm::normalize(target - c + glm::vec3(1e-3f, 2e-3f, 0.0f)) * diag;
      out.direction = target - out.origin;
      rays.push_back(out);
      Ray in;
      in.origin = c;
      in.direction = target - c;
      if (glm::length(in.direction) > 0.0f) rays.push_back(in);
    }
  }
  for (std::size_t t = 0; t < m.triangles(); t += stride * 2) {  // axis-aligned through vertices
    const glm::vec3 v = m.vertex(t, static_cast<int>(t % 3));
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {1.0f, -1.0f}) {
        Ray r;
        r.origin = v;
        r.origin[axis] -= sign * diag;
        r.direction = glm::vec3(sign > 0 ? 0.0f : -0.0f);
        r.direction[axis] = sign;
        rays.push_back(r);
      }
  }
  for (std::size_t t = 0, k = 0; t < m.triangles(); t += stride, ++k) {  // from the surface
    const auto i = static_cast<std::uint32_t>(k);
    float u = R(i, 0, 9), v = R(i, 1, 9);
    if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
    Ray r;
    r.origin = m.vertex(t, 0) * (1.0f - u - v) + m.vertex(t, 1) * u + m.vertex(t, 2) * v;
    r.direction = inside(i, 10) - r.origin + glm::vec3(1e-4f);
    rays.push_back(r);
    r.tmin = 1e-4f * diag;
    rays.push_back(r);
  }
  for (int i = 0; i < per_kind; ++i) {  // clipped at the oracle's t
    Ray r;
    r.origin = c + diag * (glm::vec3(R(i, 0, 13), R(i, 1, 13), R(i, 2, 13)) * 3.0f - 1.5f);
    r.direction = inside(i, 14) - r.origin;
    const Hit o = closest_hit_oracle(m.positions, m.indices, r);
    if (!o.hit()) continue;
    r.tmax = o.t;
    rays.push_back(r);
    r.tmax = std::nextafter(o.t, 0.0f);
    rays.push_back(r);
    r.tmin = o.t;  // tmin exactly at the hit, tmax open
    r.tmax = 3.0e38f;
    rays.push_back(r);
  }
  return rays;
}

// Every query agrees with the oracle, single rays (tests/trace/oracle_checks.h) and packets;
// returns the number of oracle hits.
int expect_matches_oracle(const Mesh& m, const Bvh& bvh, const std::vector<Ray>& rays) {
  TraversalCounters c;
  const int hits = testing::expect_single_rays_match_oracle(m.positions, m.indices, bvh, rays, c);
  // Packets of consecutive rays (the coherent groups, e.g. the clipped triples and rays
  // aimed at one triangle's features, take the packet path; the others fall back).
  for (std::size_t i = 0; i < rays.size(); i += kPacketSize) {
    const int n = static_cast<int>(std::min<std::size_t>(kPacketSize, rays.size() - i));
    Hit h[kPacketSize];
    closest_hit_packet(bvh, &rays[i], n, h, &c);
    for (int k = 0; k < n; ++k) {
      const Hit o = closest_hit_oracle(m.positions, m.indices, rays[i + k]);
      EXPECT_EQ(o.triangle, h[k].triangle) << "packet, ray " << i + k;
      if (o.hit()) {
        EXPECT_EQ(bits(o.t), bits(h[k].t)) << "packet, ray " << i + k;
      }
    }
  }
  EXPECT_EQ(c.stack_overflows, 0u);
  return hits;
}

// Coherent primary-like packets (a narrow fan from outside towards the centre), so the
// packet path itself is exercised on the real mesh; returns how many packets took it.
int expect_packets_match_oracle(const Mesh& m, const Bvh& bvh, int packets) {
  const glm::vec3 c = 0.5f * (m.lo + m.hi);
  const float diag = std::max(glm::length(m.hi - m.lo), 1e-3f);
  int taken = 0;
  for (int p = 0; p < packets; ++p) {
    const auto i = static_cast<std::uint32_t>(p);
    const glm::vec3 eye = c + diag * glm::normalize(glm::vec3(testing::rnd(i, 0, 21), testing::rnd(i, 1, 21),
                                                              testing::rnd(i, 2, 21)) - 0.5f + glm::vec3(1e-3f));
    const glm::vec3 aim = m.lo + (m.hi - m.lo) * glm::vec3(testing::rnd(i, 0, 22), testing::rnd(i, 1, 22),
                                                          testing::rnd(i, 2, 22));
    Ray rays[kPacketSize];
    for (int k = 0; k < kPacketSize; ++k) {
      rays[k].origin = eye;
      rays[k].direction = glm::normalize(aim - eye) + 0.004f * glm::vec3(k % 4, k / 4, 0.5f * (k % 3));
    }
    Hit h[kPacketSize];
    taken += closest_hit_packet(bvh, rays, kPacketSize, h);
    for (int k = 0; k < kPacketSize; ++k) {
      const Hit o = closest_hit_oracle(m.positions, m.indices, rays[k]);
      EXPECT_EQ(o.triangle, h[k].triangle) << "packet " << p << " ray " << k;
      if (o.hit()) {
        EXPECT_EQ(bits(o.t), bits(h[k].t)) << "packet " << p << " ray " << k;
      }
    }
  }
  return taken;
}

class RealMesh : public ::testing::TestWithParam<std::tuple<const char*, int>> {};

TEST_P(RealMesh, BothLayoutsAnyHitAndPacketsMatchOracle) {
  const auto [rel, min_triangles] = GetParam();
  const Mesh m = load(rel);
  SPECULUM_REQUIRE(!m.indices.empty(), std::string("the Debian package assimp-testmodels (") + rel + ")");
  ASSERT_GE(static_cast<int>(m.triangles()), min_triangles) << rel;
  // Rays scaled so the all-pairs oracle stays cheap on the big models.
  const int budget = static_cast<int>(std::clamp<std::size_t>(8'000'000 / m.triangles(), 60, 1200));
  const std::vector<Ray> rays = rays_for(m, budget);
  BvhBuildOptions one_per_leaf;
  one_per_leaf.max_leaf_size = 1;
  par::Executor ex(2);
  for (const BvhBuildOptions& opt : {BvhBuildOptions{}, one_per_leaf}) {
    const Bvh bvh = Bvh::build(m.positions, m.indices, ex, opt);
    EXPECT_GT(expect_matches_oracle(m, bvh, rays), static_cast<int>(rays.size() / 5)) << rel;
    EXPECT_GT(expect_packets_match_oracle(m, bvh, std::max(4, budget / 40)), 0) << rel;
  }
}

INSTANTIATE_TEST_SUITE_P(
    AssimpTestModels, RealMesh,
    ::testing::Values(std::make_tuple("OFF/Cube.off", 12), std::make_tuple("PLY/cube.ply", 12),
                      std::make_tuple("PLY/cube_binary.ply", 12), std::make_tuple("STL/Spider_ascii.stl", 1000),
                      std::make_tuple("STL/Spider_binary.stl", 1000), std::make_tuple("STL/sphereWithHole.stl", 200),
                      std::make_tuple("STL/3DSMaxExport.STL", 1000), std::make_tuple("STL/Wuson.stl", 3000),
                      std::make_tuple("glTF2/BoxTextured-glTF-Binary/BoxTextured.glb", 12),
                      std::make_tuple("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", 100000)),
    [](const ::testing::TestParamInfo<RealMesh::ParamType>& info) {
      std::string name = std::get<0>(info.param);
      name = name.substr(name.rfind('/') + 1);
      for (char& ch : name)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return name;
    });

// Vertices welded by exact position (watertightness is about equal floats at a shared
// edge). A manifold edge is used by exactly two triangles with opposite orientation; the
// mesh is closed when every edge is.
struct Welded {
  std::vector<glm::vec3> p;
  std::vector<std::uint32_t> idx;
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> directed;  // edge -> triangles
  std::size_t non_manifold_edges = 0;
  bool manifold(std::uint32_t a, std::uint32_t b) const {
    const auto f = directed.find({a, b}), r = directed.find({b, a});
    return f != directed.end() && r != directed.end() && f->second.size() == 1 && r->second.size() == 1;
  }
};

Welded weld(const Mesh& m) {
  Welded w;
  std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, std::uint32_t> id;
  for (std::uint32_t v : m.indices) {
    const glm::vec3 q = m.positions[v];
    const auto key = std::make_tuple(bits(q.x), bits(q.y), bits(q.z));
    auto [it, fresh] = id.emplace(key, static_cast<std::uint32_t>(w.p.size()));
    if (fresh) w.p.push_back(q);
    w.idx.push_back(it->second);
  }
  for (std::uint32_t t = 0; t < w.idx.size() / 3; ++t)
    for (int e = 0; e < 3; ++e) w.directed[{w.idx[3 * t + e], w.idx[3 * t + (e + 1) % 3]}].push_back(t);
  for (const auto& [edge, tris] : w.directed) w.non_manifold_edges += !w.manifold(edge.first, edge.second);
  return w;
}

glm::dvec3 face_normal(const Welded& w, std::uint32_t t) {
  const glm::dvec3 a = w.p[w.idx[3 * t]], b = w.p[w.idx[3 * t + 1]], c = w.p[w.idx[3 * t + 2]];
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double l = glm::length(n);
  return l > 0 ? n / l : glm::dvec3(0);
}

// Smallest altitude of triangle t: a ray aimed at one of its features passes within float
// rounding of it, so slivers thinner than `fat` are left out.
double min_altitude(const Welded& w, std::uint32_t t) {
  const glm::dvec3 v[3] = {w.p[w.idx[3 * t]], w.p[w.idx[3 * t + 1]], w.p[w.idx[3 * t + 2]]};
  const double twice_area = glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
  double longest = 0;
  for (int k = 0; k < 3; ++k) longest = std::max(longest, glm::length(v[(k + 1) % 3] - v[k]));
  return longest > 0 ? twice_area / longest : 0.0;
}

// Rays across the surface at a manifold edge point or vertex X, along a direction n such
// that X + εn and X - εn lie on opposite sides of the local surface (the triangles around
// X, which alone fill a small ball about X): a ray from X + dn through X must cross that
// local surface unless it hits something before, so it can never miss. (For a closed mesh
// this is the parity argument; the local one also covers the manifold parts of open ones.)
int count_misses(const Welded& w, const Mesh& m, const Bvh& bvh, int& rays_cast) {
  const float diag = glm::length(m.hi - m.lo);
  const double scale = std::max({static_cast<double>(diag), glm::length(glm::dvec3(m.lo)), glm::length(glm::dvec3(m.hi))});
  const double fat = 1e-5 * scale;
  int misses = 0;
  auto cast = [&](const glm::vec3& x, const glm::dvec3& n) {
    for (float d : {0.01f * diag, diag}) {
      Ray r;
      r.origin = x + glm::vec3(n) * d;
      r.direction = -glm::vec3(n);
      ++rays_cast;
      const bool wide = closest_hit(bvh, r).hit(), threaded = closest_hit_threaded(bvh, r).hit();
      const bool any = any_hit(bvh, r), oracle = any_hit_oracle(m.positions, m.indices, r);
      if (!wide || !threaded || !any || !oracle)
        ADD_FAILURE() << "miss at (" << x.x << ", " << x.y << ", " << x.z << ") from d = " << d << ": wide " << wide
                      << " threaded " << threaded << " any " << any << " oracle " << oracle;
      misses += !wide + !threaded + !any + !oracle;
    }
  };
  // Manifold edges (each once): the bisector of the two face normals separates the sides
  // for convex and reflex edges alike; aimed at the midpoint and a quarter point.
  for (const auto& [edge, tris] : w.directed) {
    if (edge.first > edge.second || !w.manifold(edge.first, edge.second)) continue;
    const std::uint32_t t1 = tris[0], t2 = w.directed.at({edge.second, edge.first})[0];
    const glm::dvec3 s = face_normal(w, t1) + face_normal(w, t2);
    if (min_altitude(w, t1) < fat || min_altitude(w, t2) < fat || glm::length(s) < 1e-2) continue;  // sliver / folded
    const glm::vec3 a = w.p[edge.first], b = w.p[edge.second];
    for (const glm::vec3& x : {0.5f * (a + b), 0.25f * a + 0.75f * b}) cast(x, glm::normalize(s));
  }
  // Vertices whose one-ring is manifold and locally convex or locally concave.
  std::vector<std::vector<std::uint32_t>> ring(w.p.size());
  for (std::uint32_t t = 0; t < w.idx.size() / 3; ++t)
    for (int k = 0; k < 3; ++k) ring[w.idx[3 * t + k]].push_back(t);
  for (std::uint32_t v = 0; v < w.p.size(); ++v) {
    glm::dvec3 s(0);
    bool ok = !ring[v].empty(), convex = true, concave = true;
    for (std::uint32_t t : ring[v]) {
      for (int k = 0; k < 3; ++k) ok = ok && w.manifold(w.idx[3 * t + k], w.idx[3 * t + (k + 1) % 3]);
      ok = ok && min_altitude(w, t) >= fat;
      const glm::dvec3 n = face_normal(w, t);
      s += n;
      for (std::uint32_t u : ring[v])
        for (int k = 0; k < 3; ++k) {
          const double side = glm::dot(n, glm::dvec3(w.p[w.idx[3 * u + k]]) - glm::dvec3(w.p[v]));
          convex = convex && side <= 1e-9 * scale;
          concave = concave && side >= -1e-9 * scale;
        }
    }
    if (!ok || (!convex && !concave) || glm::length(s) < 1e-2) continue;
    // The mean normal must lie strictly inside every face's outer half-space: then -s is
    // inside the (locally convex) solid cone, or +s inside the (locally concave) empty one.
    // A sharp spike can fail this (its mean normal points out through a face).
    const glm::dvec3 sn = glm::normalize(s);
    bool inside_all = true;
    for (std::uint32_t t : ring[v]) inside_all = inside_all && glm::dot(sn, face_normal(w, t)) > 1e-2;
    if (!inside_all) continue;
    cast(w.p[v], sn);
  }
  return misses;
}

// Cube.off is closed; Wuson and Spider are closed but for a few holes and non-manifold
// spots (left out: only manifold edges and vertices are aimed at).
TEST(RealMeshWatertight, RaysAtSharedEdgesAndVerticesNeverMiss) {
  int meshes = 0;
  for (const char* rel : {"OFF/Cube.off", "OFF/Wuson.off", "STL/Spider_binary.stl", "STL/3DSMaxExport.STL"}) {
    const Mesh m = load(rel);
    if (m.indices.empty()) continue;
    const Welded w = weld(m);
    if (std::string(rel) == "OFF/Cube.off") {
      EXPECT_EQ(w.non_manifold_edges, 0u) << "Cube.off is closed";
    }
    EXPECT_LT(w.non_manifold_edges, w.directed.size() / 10) << rel << ": mostly manifold";
    ++meshes;
    par::Executor ex(2);
    BvhBuildOptions one_per_leaf;
    one_per_leaf.max_leaf_size = 1;
    for (const BvhBuildOptions& opt : {BvhBuildOptions{}, one_per_leaf}) {
      const Bvh bvh = Bvh::build(m.positions, m.indices, ex, opt);
      int cast = 0;
      EXPECT_EQ(count_misses(w, m, bvh, cast), 0) << rel << ", of " << cast << " rays";
      EXPECT_GT(cast, static_cast<int>(m.triangles())) << rel;  // most features were aimed at
    }
  }
  SPECULUM_REQUIRE(meshes > 0, "the Debian package assimp-testmodels");
}

}  // namespace
}  // namespace speculum::trace
