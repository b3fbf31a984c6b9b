// `speculum bench trace` checksums (the Embree comparison's correctness side): hits,
// prim_sum (sum of hit triangle indices in file order) and t_sum (double, summed in file
// order) printed by the CLI equal the all-pairs oracle's over the same rays and mesh, for
// both kernels (packet, single) and 1 or 2 threads.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "trace/packet_traversal.h"
#include "trace/ray_file.h"
#include "trace/traversal.h"
#include "tests/apps/speculum_run.h"
#include "tests/trace/test_meshes.h"

namespace speculum::trace {
namespace {

// ASCII PLY, faces in the soup's order (the CLI's triangle index is the file's face index).
void write_ply(const std::string& path, const testing::Soup& s) {
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\nelement vertex " << s.positions.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << s.indices.size() / 3
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  char buf[128];
  for (const glm::vec3& p : s.positions) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g\n", p.x, p.y, p.z);  // round-trips floats exactly
    out << buf;
  }
  for (std::size_t t = 0; t < s.indices.size(); t += 3)
    out << "3 " << s.indices[t] << ' ' << s.indices[t + 1] << ' ' << s.indices[t + 2] << '\n';
}

// The CLI's stdout for `args`, which must succeed (tests/apps/speculum_run.h runs it).
std::string run(const std::string& args, const std::filesystem::path& dir) {
  const test::CommandResult r = test::run_speculum(args, dir);
  EXPECT_EQ(r.status, 0) << args << ": " << r.err;
  return r.out;
}

// The raw text of a top-level JSON number field (the first occurrence: the Embree block,
// when present, comes later).
std::string field(const std::string& json, const std::string& key) {
  const std::string k = "\"" + key + "\": ";
  const std::size_t at = json.find(k);
  if (at == std::string::npos) return "<missing " + key + ">";
  const std::size_t b = at + k.size();
  return json.substr(b, json.find_first_of(",}", b) - b);
}

struct Expected {
  std::uint64_t hits = 0, prim_sum = 0;
  double t_sum = 0.0;
};

Expected oracle_checksum(const testing::Soup& s, const RayStream& rays) {
  Expected e;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit h = closest_hit_oracle(s.positions, s.indices, rays.get(i));
    if (!h.hit()) continue;
    ++e.hits;
    e.prim_sum += h.triangle;
    e.t_sum += h.t;
  }
  return e;
}

TEST(BenchTraceCli, ChecksumsEqualTheOracleForBothKernelsAndThreadCounts) {
  // Two closed spheres, a floor and a random soup: overlapping boxes, many triangle indices.
  testing::Soup s = testing::uv_sphere(12, 24, glm::vec3(-0.6f, 0.0f, 0.0f), 0.5f);
  const testing::Soup s2 = testing::uv_sphere(10, 20, glm::vec3(0.7f, 0.1f, -0.3f), 0.6f);
  auto append = [&s](const testing::Soup& o) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(), o.positions.begin(), o.positions.end());
    for (std::uint32_t i : o.indices) s.indices.push_back(base + i);
  };
  append(s2);
  testing::Soup floor;
  floor.add({-3, -1, -3}, {-3, -1, 3}, {3, -1, 3});
  floor.add({-3, -1, -3}, {3, -1, 3}, {3, -1, -3});
  append(floor);
  append(testing::random_soup(400, 91, 0.08f));
  const std::filesystem::path dir = test::scratch_dir();
  const std::string mesh = (dir / "mesh.ply").string(), primary = (dir / "primary.spry").string(),
                    random = (dir / "random.spry").string();
  write_ply(mesh, s);
  run("-q --threads 2 bench trace " + mesh +
          " --emit-rays primary --width 128 --height 96 --fov 20 --eye 0.3,0.8,3.5 --target 0,-0.2,0 -o " + primary,
      dir);
  // Incoherent rays with varied [tnear, tfar], so a kernel ignoring the file's interval
  // differs from the oracle.
  RayStream rr;
  rr.resize(2000);
  for (std::uint32_t i = 0; i < rr.size(); ++i) {
    Ray r = testing::random_ray(i, 44);
    r.tmin = (i % 3 == 0) ? 0.5f * testing::rnd(i, 30, 44) : 0.0f;
    r.tmax = (i % 4 == 0) ? 0.5f + 1.5f * testing::rnd(i, 31, 44) : 3.0e38f;
    rr.set(i, r);
  }
  write_ray_file(random, rr);

  for (const std::string& file : {primary, random}) {
    const RayStream rays = read_ray_file(file);
    const Expected e = oracle_checksum(s, rays);
    ASSERT_GT(e.hits, rays.size() / 10) << file;  // not vacuous: many hits ...
    ASSERT_LT(e.hits, rays.size()) << file;       // ... and some misses
    char t_sum[64];
    std::snprintf(t_sum, sizeof t_sum, "%.6f", e.t_sum);  // the CLI's precision
    for (const char* kernel : {"packet", "single"})
      for (int threads : {1, 2}) {
        const std::string json = run("--threads " + std::to_string(threads) + " bench trace " + mesh + " --rays " +
                                     file + " --repeat 1 --no-embree --json --kernel " + kernel,
                                     dir);
        SCOPED_TRACE(file + " --kernel " + kernel + " --threads " + std::to_string(threads) + ": " + json);
        EXPECT_EQ(field(json, "rays"), std::to_string(rays.size()));
        EXPECT_EQ(field(json, "triangles"), std::to_string(s.indices.size() / 3));
        EXPECT_EQ(field(json, "hits"), std::to_string(e.hits));
        EXPECT_EQ(field(json, "prim_sum"), std::to_string(e.prim_sum));
        EXPECT_EQ(std::stod(field(json, "t_sum")), std::stod(t_sum));  // same number; JSON drops trailing zeros
        EXPECT_EQ(field(json, "stack_overflows"), "0");
      }
  }
  // The packet comparison is not vacuous: most of the primary file's packets are coherent
  // enough (narrow field of view) to take the packet path.
  par::Executor ex(1);
  const Bvh bvh = Bvh::build(s.positions, s.indices, ex);
  const RayStream rays = read_ray_file(primary);
  int packet_path = 0;
  for (std::size_t i = 0; i + kPacketSize <= rays.size(); i += kPacketSize) {
    Ray r[kPacketSize];
    Hit h[kPacketSize];
    for (int k = 0; k < kPacketSize; ++k) r[k] = rays.get(i + k);
    packet_path += closest_hit_packet(bvh, r, kPacketSize, h);
  }
  EXPECT_GT(packet_path, static_cast<int>(rays.size() / kPacketSize / 2));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum::trace
