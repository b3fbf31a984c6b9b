// Every error the user can cause is one line on stderr starting "speculum: ", exit status 2,
// naming what the user gave (the option, the file as typed — never a temporary file): the
// option parser's errors too, misspelt names get "did you mean", and a write that fails says
// why (never "Success"), leaving no file behind. Help still prints and exits 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// The result of `args`, checked to be one "speculum: ..." line and status 2.
std::string one_line_error(const std::string& args, const fs::path& dir) {
  const test::CommandResult r = test::run_speculum(args, dir);
  EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << "\n" << r.err;
  EXPECT_EQ(r.err.rfind("speculum: ", 0), 0u) << args << "\n" << r.err;
  EXPECT_EQ(r.err.find("Success"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << r.err;
  return r.err;
}

TEST(CliErrors, OptionParserErrorsAreOneLine) {
  const fs::path dir = test::scratch_dir();
  EXPECT_TRUE(test::contains(one_line_error("render --width abc -q", dir), "--width"));
  EXPECT_TRUE(test::contains(one_line_error("render --width 0 -q", dir), "--width"));
  EXPECT_TRUE(test::contains(one_line_error("render --no-such-option -q", dir), "--no-such-option"));
  EXPECT_TRUE(test::contains(one_line_error("render --spp -q", dir), "--spp"));
  one_line_error("", dir);  // no subcommand
}

TEST(CliErrors, HelpStillPrintsAndExitsZero) {
  const fs::path dir = test::scratch_dir();
  for (const char* args : {"--help", "render --help", "techniques --help"}) {
    const test::CommandResult r = test::run_speculum(args, dir);
    EXPECT_EQ(r.status, 0) << args;
    EXPECT_TRUE(test::contains(r.out, "Usage")) << args << r.out;
    EXPECT_TRUE(r.err.empty()) << args << r.err;
  }
}

TEST(CliErrors, MisspeltNamesGetASuggestion) {
  const fs::path dir = test::scratch_dir();
  EXPECT_TRUE(test::contains(one_line_error("rendr sphere-in-room", dir), "did you mean 'render'?"));
  EXPECT_TRUE(test::contains(one_line_error("render sphere-in-rom -q -o x.png", dir), "did you mean 'sphere-in-room'?"));
  EXPECT_TRUE(test::contains(one_line_error("render -t envmapp -q -o x.png", dir), "did you mean 'envmap'?"));
  EXPECT_TRUE(test::contains(one_line_error("render -t distance-map --param linear_step=4 -q -o x.png", dir),
                       "did you mean 'linear_steps'?"));
  EXPECT_TRUE(test::contains(one_line_error("render --aov albdo -q -o x.exr", dir), "did you mean 'albedo'?"));
  // Unrelated words get no suggestion.
  EXPECT_FALSE(test::contains(one_line_error("render -t zzzzzzzz -q -o x.png", dir), "did you mean"));
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(CliErrors, BadParamValuesNameTheParameterTechniqueAndRange) {
  const fs::path dir = test::scratch_dir();
  for (const char* value : {"1e9", "-3", "2.5", "nan", "inf", "0"}) {
    const std::string e = one_line_error(std::string("render -t distance-map --width 16 --height 16 -q --param "
                                                     "linear_steps=") + value + " -o x.png",
                                         dir);
    EXPECT_TRUE(test::contains(e, "linear_steps")) << e;
    if (std::string(value) != "nan" && std::string(value) != "inf") {
      EXPECT_TRUE(test::contains(e, "'distance-map'")) << e;
      EXPECT_TRUE(test::contains(e, "integer in [1, ")) << e;
    }
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(CliErrors, AbsurdSizesAreRejectedUpFrontNamingTheLimit) {
  const fs::path dir = test::scratch_dir();
  EXPECT_TRUE(test::contains(one_line_error("render --width 100000 -q -o x.png", dir), "--width"));
  EXPECT_TRUE(test::contains(one_line_error("render --cube-size 100000 -q -o x.png", dir), "--cube-size"));
  EXPECT_TRUE(test::contains(one_line_error("render --shadow-size 100000 -q -o x.png", dir), "--shadow-size"));
  EXPECT_TRUE(test::contains(one_line_error("render --spp 1000000 -q -o x.png", dir), "--spp"));
  const std::string samples = one_line_error("render --width 16384 --height 16384 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(samples, "samples")) << samples;
  // Each technique's own limit (Technique::max_samples), named in the message.
  EXPECT_TRUE(test::contains(samples, "envmap takes at most 8388608 (2^23)")) << samples;
  const std::string rays = one_line_error("render -t ray-hierarchy --width 4096 --height 2048 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(rays, "ray-hierarchy takes at most 4194304 (2^22)")) << rays;
  const std::string paths = one_line_error("render -t reference --width 16384 --height 16384 -q -o x.png", dir);
  EXPECT_TRUE(test::contains(paths, "reference takes at most 67108864 (2^26)")) << paths;
  EXPECT_TRUE(test::contains(one_line_error("render sphere-in-room:size=1e13 -q -o x.png", dir), "size"));
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(CliErrors, WriteFailuresSayWhyAndNameTheUsersPath) {
  const fs::path dir = test::scratch_dir();
  const std::string small = "render --width 8 --height 8 -q -o ";
  // A directory that does not exist.
  const std::string missing = (dir / "no-such-dir" / "out.png").string();
  std::string e = one_line_error(small + test::sh_quote(missing), dir);
  EXPECT_TRUE(test::contains(e, missing)) << e;
  EXPECT_TRUE(test::contains(e, "does not exist")) << e;
  // A "directory" that is a file.
  std::ofstream(dir / "file.txt") << "x";
  const std::string under_file = (dir / "file.txt" / "out.exr").string();
  e = one_line_error(small + test::sh_quote(under_file), dir);
  EXPECT_TRUE(test::contains(e, under_file)) << e;
  EXPECT_TRUE(test::contains(e, "not a directory")) << e;
  // The output path is a directory.
  fs::create_directories(dir / "taken.png");
  e = one_line_error(small + test::sh_quote((dir / "taken.png").string()), dir);
  EXPECT_TRUE(test::contains(e, "is a directory")) << e;
  // A file system that refuses writes (/proc, even for root).
  e = one_line_error(small + "/proc/speculum-out.png", dir);
  EXPECT_TRUE(test::contains(e, "/proc/speculum-out.png")) << e;
  // Nothing left behind: the scratch directory holds only what the test made.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_TRUE(entry.path().filename() == "file.txt" || entry.path().filename() == "taken.png" ||
                entry.path().extension() == ".txt")
        << entry.path();
}

}  // namespace
}  // namespace speculum
