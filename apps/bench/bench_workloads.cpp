// Yardstick workloads for `bench raster`: see bench_workloads.h.
#include "apps/bench/bench_workloads.h"

#include <cstdint>
#include <cstdio>
#include <fstream>

#include "core/error.h"
#include "core/procedural_geometry.h"
#include "core/sampling.h"
#include "core/scene_loader.h"

namespace speculum::pipeline {
namespace {

// Both workloads are framed by one named camera with the same clip planes.
Camera bench_camera(const glm::vec3& eye, const glm::vec3& target, float vfov_degrees) {
  Camera c;
  c.name = "bench";
  c.eye = eye;
  c.target = target;
  c.vfov_degrees = vfov_degrees;
  c.znear = 0.05f;
  c.zfar = 100.0f;
  return c;
}

Scene spheres_room() {
  procedural::SceneBuilder b("bench:spheres-room");
  const auto wall = b.add_material(procedural::diffuse("wall", {0.7f, 0.7f, 0.7f}));
  const auto ball = b.add_material(procedural::diffuse("ball", {0.8f, 0.3f, 0.2f}));
  b.add_object("room", wall, procedural::box({-6, 0, -6}, {6, 6, 6}, 40, true));
  for (int j = 0; j < 10; ++j)
    for (int i = 0; i < 10; ++i)
      b.add_object("sphere" + std::to_string(j * 10 + i), ball,
                   procedural::sphere({-4.5f + i, 0.45f + 0.3f * ((i + j) % 3), -4.5f + j}, 0.42f, 50));
  b.scene().cameras.push_back(bench_camera({0.0f, 4.5f, 7.5f}, {0.0f, 0.5f, -1.0f}, 60.0f));
  Scene s = b.take();
  finish_scene(s);
  return s;
}

Scene random_triangles() {
  procedural::SceneBuilder b("bench:random-triangles");
  const auto m = b.add_material(procedural::diffuse("grey", {0.6f, 0.6f, 0.6f}));
  procedural::MeshData mesh;
  const std::uint32_t count = 1000000;
  mesh.positions.reserve(3 * count);
  for (std::uint32_t t = 0; t < count; ++t) {
    // Centres uniform in [-1,1]^3, vertices within ±0.015 (a few pixels at 1080p).
    const glm::vec3 c(2.0f * random_float(t, 0, 0, 1) - 1.0f, 2.0f * random_float(t, 0, 1, 1) - 1.0f,
                      2.0f * random_float(t, 0, 2, 1) - 1.0f);
    for (std::uint32_t v = 0; v < 3; ++v) {
      const glm::vec3 o(random_float(t, v, 3, 1), random_float(t, v, 4, 1), random_float(t, v, 5, 1));
      mesh.positions.push_back(c + 0.03f * (o - 0.5f));
      mesh.indices.push_back(3 * t + v);
    }
  }
  b.add_object("triangles", m, std::move(mesh));
  b.scene().cameras.push_back(bench_camera({0.0f, 0.0f, 3.2f}, {0.0f, 0.0f, 0.0f}, 45.0f));
  Scene s = b.take();
  finish_scene(s);
  return s;
}

}  // namespace

bool is_bench_workload(const std::string& name) { return name.rfind("bench:", 0) == 0; }

Scene make_bench_workload(const std::string& name) {
  if (name == "bench:spheres-room") return spheres_room();
  if (name == "bench:random-triangles") return random_triangles();
  throw InputError(name, "unknown workload (bench:spheres-room, bench:random-triangles)");
}

void write_ply(const std::string& path, const Scene& scene) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError(path, "cannot open for writing");
  const auto& m = scene.mesh;
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face "
      << m.triangle_count() << "\nproperty list uchar uint vertex_indices\nend_header\n";
  out.write(reinterpret_cast<const char*>(m.positions.data()),
            static_cast<std::streamsize>(m.positions.size() * sizeof(glm::vec3)));
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint8_t three = 3;
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(&m.indices[3 * t]), 3 * sizeof(std::uint32_t));
  }
  if (!out) throw InputError(path, "write failed");
}

}  // namespace speculum::pipeline
