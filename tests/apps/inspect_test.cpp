// `speculum inspect`: manifest.json lists every executed node in execution order with its
// outputs, every listed file exists, the final image equals `render`'s, and index.html loads
// every image without console errors in headless Chromium.
#include <map>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>

#include "apps/cli/frame_options.h"
#include "apps/techniques/technique_table.h"
#include "core/image.h"
#include "core/image_metrics.h"
#include "core/scene_loader.h"
#include "tests/apps/headless_page.h"
#include "tests/apps/speculum_run.h"
#include "tests/test_dependency.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;
using test::sh_quote;
using test::run_shell;
using test::run_speculum;

constexpr const char* kScene = "sphere-in-room";
constexpr const char* kSmall = "--width 40 --height 30 --cube-size 16 --shadow-size 32";

nlohmann::json read_json(const fs::path& p) { return nlohmann::json::parse(test::slurp(p)); }

// The nodes render_frame runs for `technique` with inspect's defaults and kSmall, in order.
std::vector<std::string> expected_order(const std::string& technique) {
  pipeline::FrameOptions o;
  o.technique = technique;
  o.width = 40, o.height = 30, o.cube_map_size = 16, o.shadow_map_size = 32;
  const Scene scene = load_scene(kScene);
  const pipeline::FrameSettings f = pipeline::make_frame_settings(o, scene);
  par::Graph g;
  const pipeline::FrameOutputs out = pipeline::find_technique(technique).add_passes(g, &scene, f);
  g.request(out.radiance);
  g.request(out.display);
  g.compile();
  return g.order();
}

void expect_complete_manifest(const fs::path& dir, const std::string& technique) {
  const nlohmann::json m = read_json(dir / "manifest.json");
  EXPECT_EQ(m["technique"], technique);
  std::vector<std::string> names;
  for (const auto& n : m["nodes"]) names.push_back(n["name"]);
  EXPECT_EQ(names, expected_order(technique));
  std::set<std::string> files;
  for (const auto& f : m["files"]) files.insert(f.get<std::string>());
  for (const auto& f : files) EXPECT_TRUE(fs::is_regular_file(dir / f)) << f;
  EXPECT_TRUE(files.count("index.html") && files.count("manifest.json") && files.count("graph.dot"));
  bool display_drawn = false;
  for (const auto& n : m["nodes"]) {
    SCOPED_TRACE(n["name"].get<std::string>());
    EXPECT_GE(n["time_ms"].get<double>(), 0.0);
    EXPECT_FALSE(n["outputs"].empty());
    for (const auto& out : n["outputs"]) {
      EXPECT_FALSE(out["type"].get<std::string>().empty());
      if (out["drawable"].get<bool>()) {
        EXPECT_FALSE(out["images"].empty()) << out["resource"];
      }
      for (const auto& im : out["images"]) {
        EXPECT_TRUE(files.count(im["png"].get<std::string>())) << im["png"];
        EXPECT_TRUE(files.count(im["exr"].get<std::string>())) << im["exr"];
        const ImageRGBA png = read_image((dir / im["png"].get<std::string>()).string());
        EXPECT_GT(png.width, 0);
      }
      display_drawn = display_drawn || (out["resource"] == pipeline::kDisplay && !out["images"].empty());
    }
  }
  EXPECT_TRUE(display_drawn);
}

// The technique-specific outputs (apps/inspect/inspect_trace_images.h and the vertex
// projection's in inspect_images.cpp) a technique must draw: each is drawable, lists PNGs,
// and every PNG loads with the output's content.
const std::map<std::string, std::vector<std::string>> kTraceOutputs = {
    {"ray-hierarchy", {"secondary_rays", "ray_hierarchy", "hierarchy_traverse", "shadow_rays"}},
    // The cone angles, the cone hierarchy, and the kept / found hits and blended coverage.
    {"cone-tracing", {"pixel_cones", "cone_hierarchy", "cone_triangle_coverage"}},
    {"yu-lod", {"glossy_rays", "lod_trace"}},
    {"layered-distance-map", {"layered_distance_map"}},
    // The parameterization cube, the iteration-count image and the reflected layer.
    {"vertex-projection", {"reflector_param", "reflected_triangles", "vertex_projection_shade"}}};

void expect_trace_outputs_drawn(const fs::path& dir, const std::string& technique) {
  const auto wanted = kTraceOutputs.find(technique);
  if (wanted == kTraceOutputs.end()) return;
  const nlohmann::json m = read_json(dir / "manifest.json");
  std::set<std::string> drawn;
  for (const auto& n : m["nodes"])
    for (const auto& out : n["outputs"]) {
      if (!out["drawable"].get<bool>() || out["images"].empty()) continue;
      for (const auto& im : out["images"]) {
        const ImageRGBA png = read_image((dir / im["png"].get<std::string>()).string());
        EXPECT_GT(png.width, 0) << im["png"];
      }
      drawn.insert(out["resource"].get<std::string>());
    }
  for (const auto& r : wanted->second) EXPECT_TRUE(drawn.count(r)) << technique << ": " << r << " not drawn";
}

TEST(Inspect, ManifestListsEveryExecutedNodeOfEveryTechnique) {
  const fs::path root = test::scratch_dir();
  for (const auto& t : pipeline::techniques()) {
    SCOPED_TRACE(t.name);
    const fs::path dir = root / t.name;
    const auto r = run_speculum("-q inspect " + std::string(kScene) + " --technique " + t.name +
                                    " --spp 1 --no-svg " + kSmall + " -o " + sh_quote(dir.string()),
                                dir.parent_path());
    ASSERT_EQ(r.status, 0) << r.err;
    expect_complete_manifest(dir, t.name);
    expect_trace_outputs_drawn(dir, t.name);
  }
  fs::remove_all(root);
}

TEST(Inspect, FinalImageEqualsRender) {
  const fs::path dir = test::scratch_dir();
  const std::string size = "--width 48 --height 36";
  auto r = run_speculum("-q inspect " + std::string(kScene) + " --no-svg " + size + " -o " +
                            sh_quote((dir / "insp").string()),
                        dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // inspect tone-maps at exposure 1; render meters by default.
  r = run_speculum("-q render " + std::string(kScene) + " " + size + " --exposure 1 -o " +
                       sh_quote((dir / "render.png").string()),
                   dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json m = read_json(dir / "insp" / "manifest.json");
  std::string display_png;
  for (const auto& n : m["nodes"])
    for (const auto& out : n["outputs"])
      if (out["resource"] == pipeline::kDisplay) display_png = out["images"][0]["png"];
  ASSERT_FALSE(display_png.empty());
  const ImageError e = image_error(read_image((dir / "insp" / display_png).string()),
                                   read_image((dir / "render.png").string()));
  EXPECT_EQ(e.max8, 0.0);
  fs::remove_all(dir);
}

TEST(Inspect, BadInputExitsTwo) {
  const fs::path dir = test::scratch_dir();
  EXPECT_EQ(run_speculum("inspect no-such-scene -o " + sh_quote((dir / "o").string()), dir).status, 2);
  EXPECT_EQ(run_speculum("inspect --technique no-such -o " + sh_quote((dir / "o").string()), dir).status, 2);
  EXPECT_EQ(run_speculum("inspect --param nonsense -o " + sh_quote((dir / "o").string()), dir).status, 2);
  fs::remove_all(dir);
}


TEST(Inspect, EveryImageLoadsInHeadlessChromium) {
  SPECULUM_REQUIRE(run_shell("command -v chromium", fs::temp_directory_path()).status == 0,
                   "the Debian package chromium");
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "insp";
  const auto r = run_speculum("-q inspect " + std::string(kScene) + " " + kSmall + " -o " +
                                  sh_quote(out.string()),
                              dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json m = read_json(out / "manifest.json");
  int pictures = m["graph"]["svg"].get<std::string>().empty() ? 0 : 1;
  std::string first_png;
  for (const auto& n : m["nodes"])
    for (const auto& o : n["outputs"])
      for (const auto& im : o["images"]) {
        ++pictures;
        if (first_png.empty()) first_png = im["png"];
      }
  ASSERT_GT(pictures, 10);

  const test::PageStatus good = test::open_in_chromium(out / "index.html", dir, "inspect-status");
  EXPECT_EQ(good.state, "ok") << "failed: " << good.failed;
  EXPECT_EQ(good.images, pictures);
  EXPECT_EQ(good.loaded, pictures);
  EXPECT_EQ(good.console, "");

  // The check must notice a missing picture.
  fs::remove(out / first_png);
  const test::PageStatus broken = test::open_in_chromium(out / "index.html", dir, "inspect-status");
  EXPECT_EQ(broken.state, "error");
  EXPECT_EQ(broken.loaded, pictures - 1);
  EXPECT_NE(broken.failed.find(first_png), std::string::npos) << broken.failed;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum
