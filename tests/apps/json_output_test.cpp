// The JSON speculum prints and writes stays valid whatever the file names: paths with a quote,
// a backslash and a control character come back unchanged from nlohmann::json::parse.
// `compare --json`, `bench trace` and `bench raster --json` used to print such paths
// unescaped; `profile -o` and `inspect -o` write JSON files into such directories.
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/cli/json_output.h"
#include "apps/cli/result_table.h"
#include "core/image.h"
#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;
using test::run_speculum;
using test::sh_quote;

// A file name that every hand-made JSON writer gets wrong.
const std::string kAwkward = "q\"uote\\back";

nlohmann::json parse_or_fail(const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    ADD_FAILURE() << "invalid JSON (" << e.what() << "):\n" << text;
  }
  return j;
}

ImageRGBA flat_image(float value) {
  ImageRGBA img(8, 4);
  for (auto& p : img.pixels) p = {value, value, value, 1.0f};
  return img;
}

TEST(JsonOutput, CompareKeepsQuotedPathsIntact) {
  const fs::path dir = test::scratch_dir();
  const std::string a = (dir / (kAwkward + "_a.png")).string(), b = (dir / (kAwkward + "\tb.png")).string();
  write_image(a, flat_image(0.2f));
  write_image(b, flat_image(0.25f));
  const auto r = run_speculum("compare " + sh_quote(a) + " " + sh_quote(b) + " --json --metric flip", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = parse_or_fail(r.out);
  EXPECT_EQ(j.value("a", ""), a);
  EXPECT_EQ(j.value("b", ""), b);
  EXPECT_EQ(j.value("width", 0), 8);
  EXPECT_GT(j.value("mae8", 0.0), 0.0);
  EXPECT_TRUE(j["max8"].is_number_integer()) << r.out;
  EXPECT_TRUE(j.contains("flip")) << r.out;
  // The layout scripts match with `"key": value` is unchanged.
  EXPECT_NE(r.out.find("\"width\": 8, \"height\": 4"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(JsonOutput, BenchTraceAndRasterKeepQuotedPathsIntact) {
  const fs::path dir = test::scratch_dir();
  const std::string mesh = (dir / (kAwkward + ".ply")).string(), rays = (dir / (kAwkward + ".spry")).string();
  ASSERT_EQ(run_speculum("bench trace --make-mesh spheres:1 -o " + sh_quote(mesh), dir).status, 0);
  ASSERT_EQ(run_speculum("-q bench trace " + sh_quote(mesh) + " --emit-rays primary --width 8 --height 8 -o " +
                             sh_quote(rays), dir).status, 0);

  const auto trace = run_speculum("--threads 2 bench trace " + sh_quote(mesh) + " --rays " + sh_quote(rays) +
                                      " --repeat 1 --no-embree --json", dir);
  ASSERT_EQ(trace.status, 0) << trace.err;
  const nlohmann::json t = parse_or_fail(trace.out);
  EXPECT_EQ(t.value("mesh", ""), mesh);
  EXPECT_EQ(t.value("rays_file", ""), rays);
  EXPECT_EQ(t.value("rays", 0), 64);
  EXPECT_EQ(t.value("threads", 0), 2);
  EXPECT_TRUE(t["bvh"]["hash"].is_string()) << trace.out;
  EXPECT_EQ(t["bvh"]["hash"].get<std::string>().size(), 16u);

  const auto raster = run_speculum("bench raster " + sh_quote(mesh) + " --width 32 --height 24 --repeat 1 --json", dir);
  ASSERT_EQ(raster.status, 0) << raster.err;
  const nlohmann::json g = parse_or_fail(raster.out);
  EXPECT_EQ(g.value("scene", ""), mesh);
  EXPECT_EQ(g.value("width", 0), 32);
  ASSERT_TRUE(g["kernels_ms_median"].is_object()) << raster.out;
  EXPECT_FALSE(g["kernels_ms_median"].empty()) << raster.out;
  fs::remove_all(dir);
}

TEST(JsonOutput, ProfileAndInspectWriteValidJsonIntoQuotedDirectories) {
  const fs::path dir = test::scratch_dir();
  const std::string small = " --width 24 --height 16 --cube-size 8 --shadow-size 16";
  const fs::path prof = dir / (kAwkward + "_prof");
  const auto p = run_speculum("-q profile sphere-in-room --technique envmap --repeat 1 --warmup 0 --json -o " +
                                  sh_quote(prof.string()) + small, dir);
  ASSERT_EQ(p.status, 0) << p.err;
  const nlohmann::json counters = parse_or_fail(test::slurp(prof / "counters.json"));
  EXPECT_EQ(counters.value("technique", ""), "envmap");
  const nlohmann::json trace = parse_or_fail(test::slurp(prof / "trace.json"));
  EXPECT_FALSE(trace["traceEvents"].empty());
  // --json rows: one object per line.
  std::istringstream rows(p.out);
  int parsed = 0;
  for (std::string line; std::getline(rows, line);) parsed += parse_or_fail(line).contains("node");
  EXPECT_GT(parsed, 1) << p.out;

  const fs::path insp = dir / (kAwkward + "_insp");
  const auto i = run_speculum("-q inspect sphere-in-room --technique envmap --no-svg -o " + sh_quote(insp.string()) +
                                  small, dir);
  ASSERT_EQ(i.status, 0) << i.err;
  const nlohmann::json manifest = parse_or_fail(test::slurp(insp / "manifest.json"));
  EXPECT_EQ(manifest.value("technique", ""), "envmap");
  fs::remove_all(dir);
}

TEST(JsonOutput, ResultTableRowsParseBackToTheirCells) {
  const fs::path dir = test::scratch_dir();
  const fs::path file = dir / "rows.jsonl";
  std::FILE* out = std::fopen(file.c_str(), "w");
  ASSERT_NE(out, nullptr);
  {
    cli::ResultTable table(true, out);
    table.cell("scene", kAwkward + "\n\x01").cell("ms", 1.25, 1).cell("nan", std::nan(""))
        .cell("count", std::int64_t{-3}).cell("ok", true);
    table.end_row();
  }
  std::fclose(out);
  const std::string text = test::slurp(file);
  const nlohmann::json row = parse_or_fail(text);
  EXPECT_EQ(row.value("scene", ""), kAwkward + "\n\x01");
  EXPECT_DOUBLE_EQ(row.value("ms", 0.0), 1.25);  // full precision, not the text table's 1 digit
  EXPECT_TRUE(row["nan"].is_null());
  EXPECT_EQ(row.value("count", 0), -3);
  EXPECT_EQ(row.value("ok", false), true);
  // Columns keep their order.
  EXPECT_LT(text.find("\"scene\""), text.find("\"ms\""));
  EXPECT_LT(text.find("\"count\""), text.find("\"ok\""));
  fs::remove_all(dir);
}

TEST(JsonOutput, CountersAreIntegersWhenIntegral) {
  EXPECT_EQ(cli::counter_json(std::uint64_t{7}).dump(), "7");
  EXPECT_EQ(cli::counter_json(2.0).dump(), "2");
  EXPECT_EQ(cli::counter_json(-2.0f).dump(), "-2");
  EXPECT_EQ(cli::counter_json(2.5).dump(), "2.5");
  EXPECT_EQ(cli::counter_json(1e300).dump(), "1e+300");
  EXPECT_EQ(cli::counter_json(std::numeric_limits<double>::quiet_NaN()).dump(), "null");
  const std::map<std::string, double> counters{{"rays", 12.0}, {"ratio", 0.5}};
  EXPECT_EQ(cli::counters_json(counters).dump(), R"({"ratio":0.5,"rays":12})");
  EXPECT_EQ(cli::counters_text(counters), "ratio=0.5 rays=12");
}

TEST(JsonOutput, LinesKeepTheKeyColonSpaceLayoutAndReplaceInvalidUtf8) {
  cli::OrderedJson j{{"b", 1}, {"a", {1, 2}}, {"s", "x\"\\"}, {"o", {{"k", nullptr}}}};
  EXPECT_EQ(cli::json_line(j), R"({"b": 1, "a": [1, 2], "s": "x\"\\", "o": {"k": null}})");
  // A file name need not be UTF-8; the line stays valid JSON.
  const std::string line = cli::json_line(cli::OrderedJson{{"path", std::string("bad\xff.png")}});
  EXPECT_EQ(parse_or_fail(line).value("path", ""), "bad\xEF\xBF\xBD.png");
  EXPECT_DOUBLE_EQ(cli::rounded(1.23456, 3), 1.235);
  EXPECT_EQ(cli::json_line(cli::OrderedJson(cli::rounded(0.1 + 0.2, 3))), "0.3");
}

}  // namespace
}  // namespace speculum
