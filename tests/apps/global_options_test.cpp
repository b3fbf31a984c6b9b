// --threads, --lanes and --quiet are declared once, on the top-level command, and are
// accepted before or after any subcommand, nested ones included, with the same effect.
#include <nlohmann/json.hpp>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;
using test::run_speculum;
using test::sh_quote;

TEST(GlobalOptions, AcceptedBeforeOrAfterTheSubcommand) {
  const fs::path dir = test::scratch_dir();
  const auto before = run_speculum("--threads 1 techniques", dir);
  const auto after = run_speculum("techniques --threads 1", dir);
  ASSERT_EQ(before.status, 0) << before.err;
  ASSERT_EQ(after.status, 0) << after.err;
  EXPECT_FALSE(after.out.empty());
  EXPECT_EQ(before.out, after.out);

  const auto list_before = run_speculum("--quiet scenes list", dir);
  const auto list_after = run_speculum("scenes list --quiet", dir);
  ASSERT_EQ(list_after.status, 0) << list_after.err;
  EXPECT_FALSE(list_after.out.empty());
  EXPECT_EQ(list_before.out, list_after.out);

  const auto mixed = run_speculum("--lanes 4 scenes --threads 2 list -q", dir);
  EXPECT_EQ(mixed.status, 0) << mixed.err;
  EXPECT_EQ(mixed.out, list_after.out);
  fs::remove_all(dir);
}

TEST(GlobalOptions, ReachNestedSubcommands) {
  const fs::path dir = test::scratch_dir();
  const std::string mesh = (dir / "m.ply").string(), rays = (dir / "r.spry").string();
  const auto make = run_speculum("bench trace --make-mesh spheres:2 -o " + sh_quote(mesh) + " --threads 2", dir);
  ASSERT_EQ(make.status, 0) << make.err;
  EXPECT_TRUE(fs::exists(mesh));
  const std::string made = test::slurp(mesh);
  const auto make_before = run_speculum("--threads 2 bench trace --make-mesh spheres:2 -o " + sh_quote(mesh), dir);
  ASSERT_EQ(make_before.status, 0) << make_before.err;
  EXPECT_EQ(make.out, make_before.out);
  EXPECT_EQ(test::slurp(mesh), made);

  // --quiet after a nested subcommand silences it: without it, --emit-rays reports on stderr.
  const std::string emit = "bench trace " + sh_quote(mesh) + " --emit-rays primary --width 8 --height 8 -o " +
                           sh_quote(rays);
  const auto loud = run_speculum(emit, dir);
  const auto quiet = run_speculum(emit + " --quiet", dir);
  ASSERT_EQ(loud.status, 0) << loud.err;
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  EXPECT_NE(loud.err.find("rays"), std::string::npos) << loud.err;
  EXPECT_EQ(quiet.err, "");

  // --threads and --lanes after `bench raster` reach the executor it reports on.
  const auto raster = run_speculum("bench raster " + sh_quote(mesh) +
                                       " --width 16 --height 16 --repeat 1 --json --threads 1 --lanes 4", dir);
  ASSERT_EQ(raster.status, 0) << raster.err;
  const auto j = nlohmann::json::parse(raster.out);
  EXPECT_EQ(j.value("threads", 0), 1);
  EXPECT_EQ(j.value("lanes", 0), 4);

  const auto experiment = run_speculum(
      "experiment ray-hierarchy --scenes sphere-in-room --min-width 8 --max-width 8 --runs 1 --json -q --threads 1",
      dir);
  ASSERT_EQ(experiment.status, 0) << experiment.err;
  EXPECT_EQ(experiment.err, "");
  EXPECT_EQ(nlohmann::json::parse(experiment.out).value("scene", ""), "sphere-in-room") << experiment.out;
  fs::remove_all(dir);
}

TEST(GlobalOptions, BadValuesAfterTheSubcommandAreInputErrors) {
  const fs::path dir = test::scratch_dir();
  for (const char* args : {"techniques --threads -1", "--threads -1 techniques", "scenes list --lanes 3",
                           "bench trace --make-mesh spheres:1 -o x.ply --threads 5000"}) {
    SCOPED_TRACE(args);
    const auto r = run_speculum(args, dir);
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(std::string(args).find("lanes") != std::string::npos ? "--lanes" : "--threads"),
              std::string::npos)
        << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "x.ply"));
  fs::remove_all(dir);
}

TEST(GlobalOptions, HelpListsThemOnce) {
  const fs::path dir = test::scratch_dir();
  const auto r = run_speculum("--help", dir);
  ASSERT_EQ(r.status, 0);
  for (const char* option : {"--threads", "--lanes", "--quiet"}) {
    const std::size_t at = r.out.find(option);
    EXPECT_NE(at, std::string::npos) << option << " in " << r.out;
    EXPECT_EQ(r.out.find(option, at + 1), std::string::npos) << option << " listed twice in " << r.out;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum
