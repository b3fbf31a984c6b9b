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
        EXPECT_NE(e.find(p.range_text()), std::string::npos) << e;
      }
      if (p.integer && p.max > p.min) {
        EXPECT_NE(input_error(t, p.name, p.min + 0.5), "(accepted)") << t.name << " " << p.name;
      }
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
    EXPECT_NE(r.err.find(p.range_text()), std::string::npos) << r.err;
    EXPECT_FALSE(std::ifstream(out).good()) << out;
  }
}

std::string parse_error(const Technique& t, const std::string& item) {
  try {
    parse_technique_param(t, item);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// The modes a parameter picks between are named: the value is the name's index, given by
// name or by number, and every enumerated parameter of the table has names.
TEST(TechniqueParams, NamedChoicesAreTheirIndexByNameOrNumber) {
  int named = 0;
  for (const Technique& t : techniques())
    for (const TechniqueParam& p : t.params) {
      if (p.choices.empty()) continue;
      ++named;
      EXPECT_TRUE(p.integer) << t.name << " " << p.name;
      EXPECT_EQ(p.min, 0.0) << t.name << " " << p.name;
      EXPECT_EQ(p.max, double(p.choices.size() - 1)) << t.name << " " << p.name;
      for (std::size_t k = 0; k < p.choices.size(); ++k) {
        EXPECT_EQ(parse_technique_param(t, p.name + "=" + p.choices[k]), std::make_pair(p.name, double(k)));
        EXPECT_EQ(parse_technique_param(t, p.name + "=" + std::to_string(k)), std::make_pair(p.name, double(k)));
        EXPECT_EQ(p.value_text(double(k)), p.choices[k]);
      }
      // The listing names the default and the modes.
      const std::string listed = t.describe_params("");
      EXPECT_NE(listed.find(p.name + "=" + p.value_text(p.fallback) + "  " + p.range_text()), std::string::npos)
          << listed;
    }
  // caustics filter and storage, refraction method, soff fill and concave, cone-tracing fill.
  EXPECT_EQ(named, 6);
  const Technique& caustics = find_technique("caustics");
  EXPECT_EQ(parse_technique_param(caustics, "filter=triangles"), std::make_pair(std::string("filter"), 1.0));
  EXPECT_EQ(find_technique("refraction").describe_params("").find("method=two-face  one of single|two-face|impostors"),
            0u);
  // Numbers still work for the others, and names only where a parameter has them.
  EXPECT_EQ(parse_technique_param(caustics, "photon_res=256"), std::make_pair(std::string("photon_res"), 256.0));
  EXPECT_NE(parse_error(caustics, "photon_res=splat").find("expected a number"), std::string::npos);
}

TEST(TechniqueParams, AnUnknownModeNameListsTheValidOnes) {
  const Technique& caustics = find_technique("caustics");
  const std::string e = parse_error(caustics, "filter=triangls");
  EXPECT_EQ(e, "--param filter: unknown value 'triangls' of 'filter' for technique 'caustics' (did you mean "
               "'triangles'?): one of splat|triangles");
  EXPECT_NE(parse_error(caustics, "filter=2").find("one of splat|triangles"), std::string::npos);
  EXPECT_NE(parse_error(caustics, "filter=0.5").find("one of splat|triangles"), std::string::npos);
  EXPECT_NE(parse_error(caustics, "filter=").find("one of splat|triangles"), std::string::npos);
  EXPECT_NE(parse_error(caustics, "filtr=splat").find("did you mean 'filter'"), std::string::npos);
  EXPECT_NE(parse_error(caustics, "=splat").find("expected name=value"), std::string::npos);
}

// Through the CLI: a mode by name renders the same bytes as by number; a bad name exits 2
// with one line listing the valid names (render and matrix alike), and the listings show them.
TEST(TechniqueParams, CliTakesModesByName) {
  const auto dir = test::scratch_dir();
  const std::string common = "render glass-sphere:size=1000 -t caustics --width 24 --height 16 --cube-size 16 "
                             "--shadow-size 64 -q --param photon_res=16 --param caustic_size=16 --param impostor_size=8 ";
  const auto out = [&](const char* name) { return " -o " + test::sh_quote((dir / name).string()); };
  const auto a = test::run_speculum(common + "--param filter=triangles" + out("a.png"), dir);
  const auto b = test::run_speculum(common + "--param filter=1" + out("b.png"), dir);
  const auto c = test::run_speculum(common + "--param filter=splat" + out("c.png"), dir);
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  ASSERT_EQ(c.status, 0) << c.err;
  EXPECT_EQ(test::slurp(dir / "a.png"), test::slurp(dir / "b.png"));
  EXPECT_NE(test::slurp(dir / "a.png"), test::slurp(dir / "c.png"));  // the name reached the recipe
  const auto bad = test::run_speculum(common + "--param filter=blur" + out("x.png"), dir);
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err, "speculum: --param filter: unknown value 'blur' of 'filter' for technique 'caustics': "
                     "one of splat|triangles\n");
  EXPECT_FALSE(std::ifstream((dir / "x.png").string()).good());
  const auto m = test::run_speculum("matrix --techniques refraction --scenes glass-sphere --param "
                                    "refraction:method=twoface" + out("m"),
                                    dir);
  EXPECT_EQ(m.status, 2);
  EXPECT_NE(m.err.find("did you mean 'two-face'?): one of single|two-face|impostors"), std::string::npos) << m.err;
  const auto listing = test::run_speculum("techniques", dir);
  EXPECT_NE(listing.out.find("--param filter=splat  one of splat|triangles"), std::string::npos) << listing.out;
  const auto help = test::run_speculum("render --help", dir);
  EXPECT_NE(help.out.find("method=two-face  one of single|two-face|impostors"), std::string::npos);
}

}  // namespace
}  // namespace speculum::pipeline
