// The CLI's determinism promise at the level users see it: the same render gives the same
// bytes for every --threads and --lanes. ray-hierarchy runs the stream primitives
// (hierarchical compaction, radix sort, segmented min) and envmap the tile rasterizer, so
// both families of width-generic kernels are exercised at W = 1, 4, 8 and 16.
#include <gtest/gtest.h>

#include <string>

#include "speculum_run.h"

namespace speculum {
namespace {

using test::run_speculum;
using test::scratch_dir;
using test::slurp;

void expect_same_bytes_for_every_width_and_thread_count(const std::string& technique) {
  const auto dir = scratch_dir();
  std::string first;
  for (int threads : {1, 2})
    for (int lanes : {1, 4, 8, 16}) {
      const auto out = dir / (technique + "_t" + std::to_string(threads) + "_w" + std::to_string(lanes) + ".png");
      const auto r = run_speculum("-q --threads " + std::to_string(threads) + " --lanes " + std::to_string(lanes) +
                                      " render sphere-in-room --technique " + technique +
                                      " --width 96 --height 64 --cube-size 32 --shadow-size 64 -o " +
                                      test::sh_quote(out.string()),
                                  dir);
      ASSERT_EQ(r.status, 0) << r.err;
      const std::string bytes = slurp(out);
      ASSERT_FALSE(bytes.empty());
      if (first.empty()) first = bytes;
      EXPECT_TRUE(bytes == first) << technique << " differs at --threads " << threads << " --lanes " << lanes;
    }
}

TEST(LanesThreadsDeterminism, RayHierarchySameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("ray-hierarchy");
}

TEST(LanesThreadsDeterminism, ConeTracingSameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("cone-tracing");
}

TEST(LanesThreadsDeterminism, SpecularReferenceSameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("specular-reference");
}

TEST(LanesThreadsDeterminism, EnvmapSameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("envmap");
}

TEST(LanesThreadsDeterminism, VertexProjectionSameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("vertex-projection");
}

TEST(LanesThreadsDeterminism, SoffSameBytesForEveryWidthAndThreadCount) {
  expect_same_bytes_for_every_width_and_thread_count("soff");
}

}  // namespace
}  // namespace speculum
