// The technique table is the one place a technique's parameters are written: every default
// lies in its range, a recipe sees every parameter filled in, and any value outside a range
// (or fractional where whole, or unknown) is bad input — for every technique alike, through
// the table and through the CLI (exit 2, one line naming the parameter and its range).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "apps/techniques/technique_table.h"
#include "core/error.h"
#include "tests/apps/speculum_run.h"

namespace speculum::pipeline {
namespace {

std::string input_error(const Technique& t, const std::string& name, double value) {
  try {
    check_technique_params(t, {{name, value}});
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// Whole numbers in full (2^30 is 1073741824, not 1.07374e+09), others to 6 digits.
std::string text(double v) {
  std::ostringstream s;
  if (v == std::floor(v) && std::fabs(v) < 1e15) s << static_cast<long long>(v);
  else s << v;
  return s.str();
}

TEST(TechniqueParams, DefaultsLieInTheirRangesAndAreFilledIn) {
  for (const Technique& t : techniques()) {
    FrameSettings f;
    const FrameSettings filled = t.with_defaults(f);
    EXPECT_EQ(filled.params.size(), t.params.size()) << t.name;
    for (const TechniqueParam& p : t.params) {
      EXPECT_LE(p.min, p.fallback) << t.name << " " << p.name;
      EXPECT_LE(p.fallback, p.max) << t.name << " " << p.name;
      EXPECT_EQ(filled.param(p.name), p.fallback) << t.name << " " << p.name;
      EXPECT_EQ(input_error(t, p.name, p.min), "(accepted)") << t.name << " " << p.name;
      EXPECT_EQ(input_error(t, p.name, p.max), "(accepted)") << t.name << " " << p.name;
    }
    // A value given is kept.
    if (!t.params.empty()) {
      f.params[t.params[0].name] = t.params[0].max;
      EXPECT_EQ(t.with_defaults(f).param(t.params[0].name), t.params[0].max) << t.name;
    }
  }
}

TEST(TechniqueParams, OutOfRangeFractionalAndUnknownAreInputErrors) {
  for (const Technique& t : techniques()) {
    for (const TechniqueParam& p : t.params) {
      for (double bad : {p.min - 1, p.max + 1, std::nan("")}) {
        const std::string e = input_error(t, p.name, bad);
        EXPECT_NE(e.find("--param " + p.name + ":"), std::string::npos) << e;
        EXPECT_NE(e.find("[" + text(p.min) + ", " + text(p.max) + "]"), std::string::npos) << e;
      }
      if (p.integer && p.max > p.min)
        EXPECT_NE(input_error(t, p.name, p.min + 0.5), "(accepted)") << t.name << " " << p.name;
    }
    const std::string unknown = input_error(t, "no_such_param", 1);
    EXPECT_NE(unknown.find("unknown parameter 'no_such_param' for technique '" + t.name + "'"),
              std::string::npos) << unknown;
    FrameSettings f;
    f.params["no_such_param"] = 1;
    EXPECT_THROW(t.with_defaults(f), InputError) << t.name;
  }
}

// The CLI: for every technique with parameters, its first parameter just above its range
// exits 2 with one line on stderr naming the parameter and range, and writes no image.
TEST(TechniqueParams, CliRejectsOutOfRangeForEveryTechnique) {
  const auto dir = test::scratch_dir();
  for (const Technique& t : techniques()) {
    if (t.params.empty()) {
      const auto r = test::run_speculum("render -t " + t.name + " --param x=1 --width 8 --height 8 -o " +
                                            test::sh_quote((dir / "none.png").string()),
                                        dir);
      EXPECT_EQ(r.status, 2) << t.name << r.err;
      EXPECT_NE(r.err.find("it takes no parameters"), std::string::npos) << r.err;
      continue;
    }
    const TechniqueParam& p = t.params.front();
    const std::string out = (dir / (t.name + ".png")).string();
    const auto r = test::run_speculum("render -t " + t.name + " --param " + p.name + "=" + text(p.max + 1) +
                                          " --width 8 --height 8 -o " + test::sh_quote(out),
                                      dir);
    EXPECT_EQ(r.status, 2) << t.name << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("--param " + p.name), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("[" + text(p.min) + ", " + text(p.max) + "]"), std::string::npos) << r.err;
    EXPECT_FALSE(std::ifstream(out).good()) << out;
  }
}

}  // namespace
}  // namespace speculum::pipeline
