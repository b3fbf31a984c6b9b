// `speculum experiment caustics` names its filters as the technique does (`--param filter=`):
// the rows say the name, `--filter` takes it, and a bad one is one line and exit 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

TEST(CausticsExperiment, FiltersAreNamedAsTheTechniqueNamesThem) {
  const auto dir = test::scratch_dir();
  const auto r = test::run_speculum(
      "-q experiment caustics --quick --scene glass-sphere --photon-res 16 --filter triangles --storage cube --json", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;  // one row: one filter, one storage
  EXPECT_NE(r.out.find("\"filter\": \"triangles\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"storage\": \"cube\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"mae8_caustic\""), std::string::npos) << r.out;
  const auto bad = test::run_speculum("-q experiment caustics --quick --filter blur", dir);
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err, "speculum: --filter: unknown value 'blur' of 'filter' for technique 'caustics': "
                     "one of splat|triangles\n");
}

}  // namespace
}  // namespace speculum
