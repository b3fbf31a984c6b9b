// `render --path NAME --frames A..B -o f_####.png`: every frame of a built-in scene's camera
// path, each the same bytes as rendering that frame alone; bad input (unknown path, empty
// range, a pattern without '#', frames past the path) exits 2 with one `speculum:` line.
#include <gtest/gtest.h>

#include <string>

#include "core/procedural_scenes.h"
#include "speculum_run.h"

namespace speculum {
namespace {

using test::run_speculum;
using test::scratch_dir;
using test::slurp;

TEST(RenderPath, FramesAreIndependentAndNumbered) {
  const auto dir = scratch_dir();
  const std::string common = "-q render bathroom:size=8000 --technique soff --width 64 --height 48 --path pan ";
  const auto all = run_speculum(common + "--frames 3..5 -o " + test::sh_quote((dir / "f_####.png").string()), dir);
  ASSERT_EQ(all.status, 0) << all.err;
  for (const char* f : {"f_0003.png", "f_0004.png", "f_0005.png"}) EXPECT_FALSE(slurp(dir / f).empty()) << f;
  EXPECT_TRUE(slurp(dir / "f_0002.png").empty());
  const auto one = run_speculum(common + "--frames 4..4 -o " + test::sh_quote((dir / "g#.png").string()), dir);
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_TRUE(slurp(dir / "g4.png") == slurp(dir / "f_0004.png")) << "a frame depends only on its index";
  EXPECT_FALSE(slurp(dir / "f_0003.png") == slurp(dir / "f_0005.png")) << "the camera moves along the path";
}

TEST(RenderPath, BadInputExitsTwoWithOneLine) {
  const auto dir = scratch_dir();
  const std::string common = "render bathroom:size=8000 --width 32 --height 24 ";
  for (const std::string& args : {common + "--path nope --frames 0..1 -o f#.png", common + "--path walk --frames 3..1 -o f#.png",
                                  common + "--path walk --frames 0..1 -o f.png", common + "--path walk --frames 0..60 -o f#.png",
                                  common + "--frames 0..1 -o f#.png", std::string("render sphere-in-room --path walk --frames 0..1 -o f#.png")}) {
    const auto r = run_speculum(args, dir);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(r.err.rfind("speculum: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << args << ": " << r.err;
  }
}

TEST(RenderPath, PathsInterpolateTheirKeys) {
  for (const char* scene : {"bathroom", "living-room"}) {
    const auto paths = builtin_camera_paths(scene);
    ASSERT_EQ(paths.size(), 2u) << scene;
    for (const CameraPath& p : paths) {
      EXPECT_EQ(p.at(0).eye, p.keys.front().eye);
      EXPECT_EQ(p.at(p.frames - 1).eye, p.keys.back().eye);
      EXPECT_EQ(p.at(0).target, p.keys.front().target);
    }
  }
  EXPECT_TRUE(builtin_camera_paths("sphere-in-room").empty());
}

}  // namespace
}  // namespace speculum
