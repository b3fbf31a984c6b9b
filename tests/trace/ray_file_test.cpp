// SPRY ray files and the benchmark ray sets of `bench trace`: round trip,
// malformed files rejected with InputError, ray-set geometry, and the bench CLI end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.h"
#include "core/optics.h"
#include "trace/ray_file.h"
#include "trace/ray_generation.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("speculum_trace_" + name)).string();
}

TEST(RayFile, RoundTripIsExact) {
  RayStream rays;
  rays.resize(1000);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    Ray r = testing::random_ray(static_cast<std::uint32_t>(i), 3);
    r.tmin = 0.001f * i;
    r.tmax = 100.0f + i;
    rays.set(i, r);
  }
  const std::string path = temp_path("roundtrip.spry");
  write_ray_file(path, rays);
  EXPECT_EQ(std::filesystem::file_size(path), 16u + 32u * rays.size());
  const RayStream back = read_ray_file(path);
  ASSERT_EQ(back.size(), rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Ray a = rays.get(i), b = back.get(i);
    EXPECT_EQ(0, std::memcmp(&a, &b, sizeof(Ray)));
  }
  std::filesystem::remove(path);
}

TEST(RayFile, MalformedFilesAreInputErrors) {
  const std::string path = temp_path("bad.spry");
  auto write = [&](const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
  };
  EXPECT_THROW(read_ray_file(temp_path("missing.spry")), InputError);
  write("SP");
  EXPECT_THROW(read_ray_file(path), InputError);  // truncated header
  std::string header("SPRY\x01\x00\x00\x00\x02\x00\x00\x00\x00\x00\x00\x00", 16);
  write(header + std::string(32, '\0'));          // says 2 rays, holds 1
  EXPECT_THROW(read_ray_file(path), InputError);
  header[0] = 'X';
  write(header + std::string(64, '\0'));
  EXPECT_THROW(read_ray_file(path), InputError);  // bad magic
  header[0] = 'S';
  header[4] = 2;
  write(header + std::string(64, '\0'));
  EXPECT_THROW(read_ray_file(path), InputError);  // unknown version
  header[4] = 1;
  header[15] = '\x7f';                             // absurd count
  write(header + std::string(64, '\0'));
  EXPECT_THROW(read_ray_file(path), InputError);
  std::filesystem::remove(path);
}

TEST(RayGeneration, SetsHaveTheirGeometry) {
  const testing::Soup s = testing::uv_sphere(32, 64, glm::vec3(0), 1.0f);
  par::Executor ex(2);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  Camera cam;
  cam.eye = {0, 0, 4};
  cam.target = {0, 0, 0};
  cam.vfov_degrees = 40;
  const RayStream primary = generate_rays(RaySetKind::Primary, bvh, cam, 32, 24, 1, ex);
  EXPECT_EQ(primary.size(), 32u * 24u);
  const RayStream cone = generate_rays(RaySetKind::ReflectCone30, bvh, cam, 32, 24, 1, ex);
  const RayStream hemi = generate_rays(RaySetKind::Hemisphere, bvh, cam, 32, 24, 1, ex);
  ASSERT_GT(cone.size(), 100u);
  EXPECT_EQ(cone.size(), hemi.size());  // one per primary hit
  const float cos30 = std::cos(glm::radians(30.0f)) - 1e-4f;
  // Secondary rays follow the primary hits in pixel order: recompute each hit's geometric
  // normal and check the cone and hemisphere about it.
  std::size_t k = 0;
  for (std::size_t i = 0; i < primary.size(); ++i) {
    const Ray p = primary.get(i);
    const Hit hit = closest_hit(bvh, p);
    if (!hit.hit()) continue;
    ASSERT_LT(k, cone.size());
    const glm::vec3 a = s.positions[s.indices[3 * hit.triangle]], b = s.positions[s.indices[3 * hit.triangle + 1]],
                    c3 = s.positions[s.indices[3 * hit.triangle + 2]];
    glm::vec3 n = glm::normalize(glm::cross(b - a, c3 - a));
    const glm::vec3 d = glm::normalize(p.direction);
    if (glm::dot(n, d) > 0) n = -n;
    const Ray c = cone.get(k), h = hemi.get(k);
    ++k;
    EXPECT_NEAR(glm::length(c.origin - (p.origin + hit.t * p.direction)), 0.0f, 1e-3f);
    EXPECT_GT(glm::dot(glm::normalize(c.direction), reflect(d, n)), cos30);
    EXPECT_GT(glm::dot(h.direction, n), -1e-5f);
  }
  EXPECT_EQ(k, cone.size());
  EXPECT_THROW(parse_ray_set_kind("sideways"), InputError);
  // The same rays for any thread count.
  par::Executor one(1);
  const RayStream again = generate_rays(RaySetKind::ReflectCone30, bvh, cam, 32, 24, 1, one);
  ASSERT_EQ(again.size(), cone.size());
  EXPECT_EQ(0, std::memcmp(again.dx.data(), cone.dx.data(), cone.size() * sizeof(float)));
}

TEST(BenchTraceCli, EmitsAndTracesAJsonRecord) {
  const std::string mesh = temp_path("spheres.ply"), rays = temp_path("cli.spry"), out = temp_path("cli.json");
  const std::string bin = SPECULUM_BINARY;
  ASSERT_EQ(0, std::system((bin + " bench trace --make-mesh spheres:2 -o " + mesh + " > /dev/null").c_str()));
  ASSERT_EQ(0, std::system((bin + " -q --threads 2 bench trace " + mesh +
                            " --emit-rays reflect-cone30 --width 64 --height 48 -o " + rays).c_str()));
  ASSERT_EQ(0, std::system((bin + " --threads 2 bench trace " + mesh + " --rays " + rays +
                            " --repeat 1 --no-embree --json > " + out).c_str()));
  std::ifstream in(out);
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* key : {"\"mrays_per_s\"", "\"build_ms\"", "\"rays\"", "\"threads\": 2", "\"hits\"",
                          "\"prim_sum\"", "\"t_sum\""})
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  // A bad ray file: one line on stderr, exit code 2, no crash.
  std::ofstream(rays, std::ios::binary) << "nonsense";
  EXPECT_EQ(2, WEXITSTATUS(std::system((bin + " bench trace " + mesh + " --rays " + rays + " 2> /dev/null").c_str())));
  for (const auto& p : {mesh, rays, out}) std::filesystem::remove(p);
}

}  // namespace
}  // namespace speculum::trace
