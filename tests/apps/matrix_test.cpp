// `speculum matrix`: results.json holds one record per cell with its errors against the
// cached references; a rerun does not retrace them and gives the same records (times aside);
// bad input is one line, exit 2, nothing written.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <expat.h>
#include <gtest/gtest.h>

#include "tests/test_dependency.h"
#include <nlohmann/json.hpp>

#include "headless_page.h"
#include "speculum_run.h"

namespace speculum::test {
namespace {

namespace fs = std::filesystem;

const std::string kSmall =
    "--threads 2 matrix --techniques envmap,planar-mirror --scenes mirror-corridor,bowl --width 40 --height 30 "
    "--repeat 1 --spp-reference 4";

std::size_t line_count(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

// The record without its wall times (every key ending in "ms").
nlohmann::json without_times(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& k = it.key();
      if (k.size() >= 2 && k.compare(k.size() - 2, 2, "ms") == 0) continue;
      out[k] = without_times(it.value());
    }
    return out;
  }
  if (j.is_array())
    for (auto& e : j) e = without_times(e);
  return j;
}

TEST(Matrix, RecordsEveryCellAndReusesTheReferences) {
  const auto dir = scratch_dir();
  const std::string out = (dir / "m").string();
  const CommandResult first = run_speculum(kSmall + " -o " + sh_quote(out), dir);
  ASSERT_EQ(first.status, 0) << first.err;
  EXPECT_NE(first.err.find("tracing the reference of bowl"), std::string::npos) << first.err;
  EXPECT_EQ(line_count(first.out), 2u + 4u) << first.out;  // header, rule, one row per cell
  const nlohmann::json a = nlohmann::json::parse(slurp(dir / "m" / "results.json"));
  ASSERT_EQ(a["cells"].size(), 4u);
  for (const auto& c : a["cells"]) {
    SCOPED_TRACE(c["id"].get<std::string>());
    EXPECT_TRUE(fs::exists(dir / "m" / c["image"].get<std::string>()));
    EXPECT_TRUE(fs::exists(dir / "m" / c["reference"]["image"].get<std::string>()));
    for (const char* metric : {"mae8", "rmse", "psnr", "flip"}) EXPECT_TRUE(c["frame"].contains(metric));
    // A feed-forward frame with shadow maps is never the 4-spp path-traced one.
    EXPECT_GT(c["frame"]["mae8"].get<double>(), 0.0);
    EXPECT_LT(c["frame"]["psnr"].get<double>(), 100.0);
    EXPECT_GT(c["ms"].get<double>(), 0.0);
    EXPECT_GE(c["nodes"].size(), 3u);
    EXPECT_EQ(c["options"]["width"], 40);
  }
  // The specular error isolates the technique's own approximation: the planar mirror is
  // exact but for edges on the corridor's flat mirrors (the glossy torus between them is
  // searched in its distance map), envmap (no parallax) is far off.
  auto cell = [&](const std::string& id) {
    for (const auto& c : a["cells"])
      if (c["id"] == id) return c;
    return nlohmann::json();
  };
  const auto mirror = cell("planar-mirror@mirror-corridor"), envmap = cell("envmap@mirror-corridor");
  ASSERT_TRUE(mirror.contains("specular"));
  EXPECT_GT(mirror["specular"]["pixels"].get<int>(), 100);
  EXPECT_EQ(mirror["specular"]["pixels"], envmap["specular"]["pixels"]);  // one G-buffer, one mask
  EXPECT_LT(mirror["specular"]["mae8"].get<double>(), 1.0);
  EXPECT_GT(envmap["specular"]["mae8"].get<double>(), 5.0 * mirror["specular"]["mae8"].get<double>());
  EXPECT_EQ(mirror["specular_reference"]["bounces"], 3);  // planar-mirror's depth
  EXPECT_EQ(envmap["specular_reference"]["bounces"], 1);
  EXPECT_EQ(a["cells"][0]["technique"], "envmap");
  EXPECT_EQ(a["cells"][0]["scene"], "mirror-corridor");

  // Rerun: references come from the cache, every record is the same but for its times.
  const CommandResult second = run_speculum(kSmall + " -o " + sh_quote(out) + " --json", dir);
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_EQ(second.err.find("tracing the reference"), std::string::npos) << second.err;
  EXPECT_EQ(line_count(second.out), 4u);
  EXPECT_EQ(nlohmann::json::parse(second.out.substr(0, second.out.find('\n')))["id"], "envmap@mirror-corridor");
  const nlohmann::json b = nlohmann::json::parse(slurp(dir / "m" / "results.json"));
  EXPECT_EQ(without_times(a), without_times(b));

  // Another reference spp is another cache key: traced again.
  const CommandResult third =
      run_speculum("--threads 2 matrix --techniques envmap --scenes bowl --width 40 --height 30 --repeat 1 "
                   "--spp-reference 1 -o " + sh_quote(out), dir);
  ASSERT_EQ(third.status, 0) << third.err;
  EXPECT_NE(third.err.find("tracing the reference of bowl"), std::string::npos) << third.err;
  fs::remove_all(dir);
}

// The reference follows --bounces (0 or absent: its default depth, 8).
TEST(Matrix, ReferenceHonoursBounces) {
  const auto dir = scratch_dir();
  const std::string base = "-q render mirror-corridor -t reference --width 40 --height 30 -o ";
  const std::pair<std::string, std::string> runs[] = {{"", "r.png"}, {"--bounces 8 ", "r8.png"}, {"--bounces 1 ", "r1.png"}};
  for (const auto& [b, name] : runs) {
    const CommandResult r = run_speculum(base + sh_quote((dir / name).string()) + " " + b, dir);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_EQ(slurp(dir / "r.png"), slurp(dir / "r8.png"));
  EXPECT_NE(slurp(dir / "r.png"), slurp(dir / "r1.png"));  // facing mirrors: later bounces show
  fs::remove_all(dir);
}

// The specular reference's glossy lobes converge: 1024 samples differ from 256 less than 256
// from 16.
TEST(Matrix, SpecularReferenceGlossyLobeConverges) {
  const auto dir = scratch_dir();
  for (int n : {16, 256, 1024}) {
    const CommandResult r = run_speculum("-q render glossy-plane -t specular-reference --width 40 --height 30 "
                                         "--param glossy_samples=" + std::to_string(n) + " -o " +
                                             sh_quote((dir / ("g" + std::to_string(n) + ".png")).string()),
                                         dir);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  auto mae8 = [&](const std::string& a, const std::string& b) {
    const CommandResult r = run_speculum("compare --json " + sh_quote((dir / a).string()) + " " + sh_quote((dir / b).string()), dir);
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(r.out)["mae8"].get<double>();
  };
  const double coarse = mae8("g16.png", "g256.png"), fine = mae8("g256.png", "g1024.png");
  EXPECT_GT(coarse, 0.0);
  EXPECT_LT(fine, 0.5 * coarse);
  fs::remove_all(dir);
}

// What a JUnit report holds, as an XML parser reads it.
struct JUnit {
  bool well_formed = false;
  int suites = 0, cases = 0, failures = 0;
  std::string suite_tests, suite_failures;
  std::vector<std::string> failed;  // classname@name of the failing cases
  std::string current;
};

JUnit parse_junit(const std::string& xml) {
  JUnit j;
  XML_Parser p = XML_ParserCreate(nullptr);
  XML_SetUserData(p, &j);
  XML_SetStartElementHandler(p, [](void* data, const XML_Char* name, const XML_Char** attrs) {
    auto& j = *static_cast<JUnit*>(data);
    auto attr = [&](const std::string& key) {
      for (int i = 0; attrs[i]; i += 2)
        if (key == attrs[i]) return std::string(attrs[i + 1]);
      return std::string();
    };
    const std::string element = name;
    if (element == "testsuite") {
      ++j.suites;
      j.suite_tests = attr("tests");
      j.suite_failures = attr("failures");
    } else if (element == "testcase") {
      ++j.cases;
      j.current = attr("classname") + "@" + attr("name");
    } else if (element == "failure") {
      ++j.failures;
      j.failed.push_back(j.current);
    }
  });
  j.well_formed = XML_Parse(p, xml.data(), static_cast<int>(xml.size()), 1) == XML_STATUS_OK;
  XML_ParserFree(p);
  return j;
}

// Goldens written by --update-golden pass; a changed parameter fails exactly the cells it
// changes, and the JUnit XML says so.
TEST(Matrix, GoldenImagesAndJUnit) {
  const auto dir = scratch_dir();
  const std::string out = sh_quote((dir / "m").string()), golden = sh_quote((dir / "golden").string());
  const std::string run = "-q --threads 2 matrix --techniques distance-map,planar-mirror --scenes mirror-corridor,bowl "
                          "--width 40 --height 30 --repeat 1 --spp-reference 2 --glossy-samples 4 -o " + out;
  const CommandResult update = run_speculum(run + " --update-golden " + golden, dir);
  ASSERT_EQ(update.status, 0) << update.err;
  EXPECT_TRUE(fs::exists(dir / "golden" / "planar-mirror@bowl.png"));

  const std::string junit = (dir / "report.xml").string();
  const CommandResult pass = run_speculum(run + " --golden " + golden + " --max-mae8 0 --junit " + sh_quote(junit), dir);
  EXPECT_EQ(pass.status, 0) << pass.err;
  JUnit j = parse_junit(slurp(junit));
  EXPECT_TRUE(j.well_formed);
  EXPECT_EQ(j.suites, 1);
  EXPECT_EQ(j.cases, 4);
  EXPECT_EQ(j.failures, 0);
  EXPECT_EQ(j.suite_tests, "4");
  EXPECT_EQ(j.suite_failures, "0");

  // One mirror bounce instead of three: only the planar mirrors facing each other change.
  const CommandResult fail =
      run_speculum(run + " --param planar-mirror:depth=1 --golden " + golden + " --max-mae8 0 --junit " + sh_quote(junit), dir);
  EXPECT_EQ(fail.status, 1) << fail.err;
  j = parse_junit(slurp(junit));
  EXPECT_TRUE(j.well_formed);
  EXPECT_EQ(j.cases, 4);
  EXPECT_EQ(j.failures, 1);
  EXPECT_EQ(j.suite_failures, "1");
  EXPECT_EQ(j.failed, std::vector<std::string>{"planar-mirror@mirror-corridor"});
  EXPECT_NE(fail.err.find("planar-mirror@mirror-corridor: mae8"), std::string::npos) << fail.err;

  // Per-cell bounds: the changed cell's own entry lets it pass, a technique entry covers
  // every scene of it, and the cells a file does not name stay at --max-mae8.
  const fs::path loose = dir / "loose.json", strict = dir / "strict.json", misspelt = dir / "misspelt.json";
  { std::ofstream(loose) << R"({"planar-mirror@mirror-corridor": 255})"; }
  { std::ofstream(strict) << R"({"planar-mirror": 0, "distance-map@bowl": 255})"; }
  { std::ofstream(misspelt) << R"({"planar-mirror@mirror-coridor": 255})"; }
  const std::string changed = run + " --param planar-mirror:depth=1 --golden " + golden + " --max-mae8 0 --junit " + sh_quote(junit);
  const CommandResult loosened = run_speculum(changed + " --bounds " + sh_quote(loose.string()), dir);
  EXPECT_EQ(loosened.status, 0) << loosened.err;
  EXPECT_EQ(parse_junit(slurp(junit)).failures, 0);
  const CommandResult by_technique = run_speculum(changed + " --bounds " + sh_quote(strict.string()), dir);
  EXPECT_EQ(by_technique.status, 1) << by_technique.err;
  EXPECT_EQ(parse_junit(slurp(junit)).failed, std::vector<std::string>{"planar-mirror@mirror-corridor"});
  // A key that names no cell is bad input, before any cell runs.
  const CommandResult typo = run_speculum(changed + " --bounds " + sh_quote(misspelt.string()), dir);
  EXPECT_EQ(typo.status, 2) << typo.err;
  EXPECT_EQ(line_count(typo.err), 1u) << typo.err;
  EXPECT_NE(typo.err.find("did you mean 'mirror-corridor'"), std::string::npos) << typo.err;

  // A golden directory that does not exist is bad input.
  const CommandResult bad = run_speculum(run + " --golden " + sh_quote((dir / "none").string()), dir);
  EXPECT_EQ(bad.status, 2) << bad.err;
  fs::remove_all(dir);
}

// A glossy lobe searched along several sub-lobe directions blurs what it finds the way the
// lobe does, instead of drawing its edges as a mirror would: against the exact specular
// reference, the glossy floors of glossy-plane and living-room get closer than with the one
// search along R (lobe_directions=1, the search as SURVEY §4.2 states it).
TEST(Matrix, GlossyLobeSearchesLowerTheSpecularError) {
  const auto dir = scratch_dir();
  // Both runs share one output folder: the second reuses the first's cached references.
  const std::string out = (dir / "m").string();
  const auto specular_mae8 = [&](int directions) {
    const CommandResult r = run_speculum(
        "-q --threads 2 matrix --techniques distance-map --scenes glossy-plane,living-room --width 96 --height 72 "
        "--repeat 1 --spp-reference 4 --glossy-samples 64 --json --param distance-map:lobe_directions=" +
            std::to_string(directions) + " -o " + sh_quote(out),
        dir);
    EXPECT_EQ(r.status, 0) << r.err;
    std::map<std::string, double> e;
    const auto results = nlohmann::json::parse(slurp(fs::path(out) / "results.json"));
    for (const auto& c : results["cells"])
      e[c["scene"].get<std::string>()] = c["specular"]["mae8"].get<double>();
    return e;
  };
  const auto one = specular_mae8(1), eight = specular_mae8(8);
  for (const char* scene : {"glossy-plane", "living-room"}) {
    SCOPED_TRACE(scene);
    ASSERT_TRUE(one.count(scene) && eight.count(scene));
    EXPECT_LT(eight.at(scene), one.at(scene) - 0.3);
  }
  fs::remove_all(dir);
}

// --inspect writes each cell's inspect page beside it (the same passes the cell ran) and
// the atlas links to it.
TEST(Matrix, InspectPagesAreLinkedFromTheAtlas) {
  const auto dir = scratch_dir();
  const CommandResult r = run_speculum("-q --threads 2 matrix --techniques planar-mirror --scenes mirror-corridor "
                                       "--width 40 --height 30 --repeat 1 --spp-reference 2 --glossy-samples 4 "
                                       "--inspect -o " + sh_quote((dir / "m").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto record = nlohmann::json::parse(slurp(dir / "m" / "cells" / "planar-mirror@mirror-corridor.json"));
  ASSERT_TRUE(record.contains("inspect"));
  const std::string page = record["inspect"];
  EXPECT_EQ(page, "cells/planar-mirror@mirror-corridor.inspect/index.html");
  ASSERT_TRUE(fs::exists(dir / "m" / page));
  EXPECT_NE(slurp(dir / "m" / "index.html").find("href=\"" + page + "\""), std::string::npos);
  const auto manifest = nlohmann::json::parse(slurp(dir / "m" / "cells" / "planar-mirror@mirror-corridor.inspect" / "manifest.json"));
  std::vector<std::string> cell_nodes, page_nodes;
  for (const auto& n : record["nodes"]) cell_nodes.push_back(n["name"]);
  for (const auto& n : manifest["nodes"]) page_nodes.push_back(n["name"]);
  EXPECT_EQ(page_nodes, cell_nodes);
  fs::remove_all(dir);
}

// Every file under `dir` (relative path → bytes), results.json left out.
std::map<std::string, std::string> images(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".png") out[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return out;
}

// The plan's jobs run by GNU parallel (references, then cells), then merged: the same
// results.json (times aside) and the same image bytes as one `speculum matrix` process.
TEST(Matrix, PlanRunByGnuParallelEqualsOneProcess) {
  const auto dir = scratch_dir();
  SPECULUM_REQUIRE(run_shell("command -v parallel", dir).status == 0, "the Debian package parallel");
  const std::string selection = "matrix --techniques envmap,ray-hierarchy --scenes sphere-in-room,glass-sphere "
                                "--width 40 --height 30 --repeat 1 --spp-reference 2 --glossy-samples 4 --param "
                                "ray-hierarchy:block=16";
  const std::string one = sh_quote((dir / "one").string()), jobs = sh_quote((dir / "jobs").string());
  const CommandResult single = run_speculum("-q --threads 1 " + selection + " -o " + one, dir);
  ASSERT_EQ(single.status, 0) << single.err;

  const CommandResult plan = run_speculum(selection + " --plan -o " + jobs, dir);
  ASSERT_EQ(plan.status, 0) << plan.err;
  EXPECT_EQ(line_count(plan.out), 2u + 4u) << plan.out;  // two reference jobs, four cells
  EXPECT_NE(plan.out.find("matrix --reference 'glass-sphere'"), std::string::npos) << plan.out;
  EXPECT_NE(plan.out.find("matrix --cell 'ray-hierarchy@sphere-in-room'"), std::string::npos) << plan.out;
  EXPECT_TRUE(plan.out.find("matrix --cell") > plan.out.rfind("matrix --reference"));
  EXPECT_FALSE(fs::exists(dir / "jobs"));  // --plan only prints

  for (const std::string phase : {"references", "cells"}) {
    const CommandResult r = run_shell(sh_quote(SPECULUM_BINARY) + " " + selection + " --plan " + phase + " -o " + jobs +
                                          " | parallel --will-cite -j2 --halt now,fail=1", dir);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  // Remove a cell: the merge names it, exit 2, and writes no results.json.
  const fs::path record = dir / "jobs" / "cells" / "envmap@glass-sphere.json";
  const std::string kept = slurp(record);
  fs::remove(record);
  const CommandResult missing = run_speculum(selection + " --merge " + jobs, dir);
  EXPECT_EQ(missing.status, 2) << missing.err;
  EXPECT_NE(missing.err.find("1 of 4 cells missing: envmap@glass-sphere"), std::string::npos) << missing.err;
  EXPECT_EQ(line_count(missing.err), 1u) << missing.err;
  EXPECT_FALSE(fs::exists(dir / "jobs" / "results.json"));
  { std::ofstream(record, std::ios::binary) << kept; }

  const CommandResult merged = run_speculum(selection + " --merge " + jobs, dir);
  ASSERT_EQ(merged.status, 0) << merged.err;
  EXPECT_EQ(line_count(merged.out), 2u + 4u);
  const auto a = nlohmann::json::parse(slurp(dir / "one" / "results.json"));
  const auto b = nlohmann::json::parse(slurp(dir / "jobs" / "results.json"));
  EXPECT_EQ(without_times(a), without_times(b));
  EXPECT_EQ(a["cells"].size(), 4u);
  const auto ia = images(dir / "one"), ib = images(dir / "jobs");
  EXPECT_EQ(ia.size(), 4u * 3u + 2u + 2u * 2u);  // cells and their two heat maps; frame references;
                                                // specular references and masks (1 bounce)
  EXPECT_TRUE(ia == ib);
  fs::remove_all(dir);
}


// index.html loads in headless Chromium with every image (each cell's image and two heat
// maps, one gnuplot chart per scene) and no console error; a missing image is noticed.
TEST(Matrix, AtlasLoadsInHeadlessChromium) {
  const auto dir = scratch_dir();
  SPECULUM_REQUIRE(run_shell("{ command -v chromium && command -v gnuplot; }", dir).status == 0,
                   "the Debian packages chromium and gnuplot-nox");
  const CommandResult r = run_speculum(kSmall + " -q -o " + sh_quote((dir / "m").string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const int expected = 4 * 3 + 2;
  const PageStatus good = open_in_chromium(dir / "m" / "index.html", dir, "atlas-status");
  EXPECT_EQ(good.state, "ok") << good.failed;
  EXPECT_EQ(good.images, expected);
  EXPECT_EQ(good.loaded, expected);
  EXPECT_EQ(good.console, "");
  const std::string html = slurp(dir / "m" / "index.html");
  EXPECT_NE(html.find("charts/mirror-corridor.svg"), std::string::npos);
  EXPECT_NE(slurp(dir / "m" / "charts" / "bowl.svg").find("<svg"), std::string::npos);

  fs::remove(dir / "m" / "charts" / "bowl.svg");
  const PageStatus broken = open_in_chromium(dir / "m" / "index.html", dir, "atlas-status");
  EXPECT_EQ(broken.state, "error");
  EXPECT_EQ(broken.loaded, expected - 1);
  EXPECT_NE(broken.failed.find("charts/bowl.svg"), std::string::npos) << broken.failed;
  fs::remove_all(dir);
}

TEST(Matrix, BadInputIsOneLineExitTwoAndWritesNothing) {
  const auto dir = scratch_dir();
  const std::string out = (dir / "m").string();
  struct Case {
    std::string args, expect;
  };
  const Case cases[] = {
      {"matrix --techniques envmp -o " + sh_quote(out), "did you mean 'envmap'"},
      {"matrix --scenes bowl,sphere-in-rom -o " + sh_quote(out), "did you mean 'sphere-in-room'"},
      {"matrix --techniques , -o " + sh_quote(out), "empty selection"},
      {"matrix --techniques reference -o " + sh_quote(out), "unknown technique 'reference'"},
      {"matrix --techniques envmap --param envmap:foo=1 -o " + sh_quote(out), "foo"},
      {"matrix --techniques envmap --scenes bowl --cell envmap@glass-sphere -o " + sh_quote(out), "unknown cell"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CommandResult r = run_speculum(c.args, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(line_count(r.err), 1u) << r.err;
    EXPECT_EQ(r.err.rfind("speculum: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  // DIR is a file: left as it was.
  const fs::path file = dir / "file";
  { std::ofstream(file) << "keep"; }
  const CommandResult r = run_speculum("matrix --techniques envmap --scenes bowl -o " + sh_quote(file.string()), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(line_count(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("is not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(file), "keep");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum::test
