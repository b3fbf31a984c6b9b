// Every subcommand's --help (found by walking the help output from the top) names an
// example, and options with defaults show them.
#include <regex>
#include <set>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// Subcommand names listed in a help text's "Subcommands:" section.
std::vector<std::string> subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  bool inside = false;
  const std::regex entry("^  ([a-z][a-z0-9-]*)( .*)?$");
  for (std::string line; std::getline(in, line);) {
    std::string lower = line;
    for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (lower.rfind("subcommands:", 0) == 0) {
      inside = true;
      continue;
    }
    if (!inside) continue;
    if (!line.empty() && line[0] != ' ') break;  // the next section
    std::smatch m;
    if (std::regex_match(line, m, entry)) names.push_back(m[1]);
  }
  return names;
}

TEST(Help, EverySubcommandHasAnExample) {
  const fs::path dir = test::scratch_dir();
  std::vector<std::string> todo{""};
  std::set<std::string> seen;
  while (!todo.empty()) {
    const std::string path = todo.back();
    todo.pop_back();
    if (!seen.insert(path).second) continue;
    SCOPED_TRACE("speculum " + path + " --help");
    const auto r = test::run_speculum(path + " --help", dir);
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("Example"), std::string::npos) << r.out;
    for (const auto& sub : subcommands(r.out)) todo.push_back(path.empty() ? sub : path + " " + sub);
  }
  // The walk found the commands this issue names.
  for (const char* cmd : {"scenes", "info", "render", "techniques", "bench", "bench trace",
                          "bench raster", "experiment", "inspect", "profile", "compare"})
    EXPECT_TRUE(seen.count(cmd)) << cmd;
  fs::remove_all(dir);
}

TEST(Help, OptionsShowTheirDefaults) {
  const fs::path dir = test::scratch_dir();
  const auto inspect = test::run_speculum("inspect --help", dir);
  EXPECT_NE(inspect.out.find("=envmap"), std::string::npos) << inspect.out;
  EXPECT_NE(inspect.out.find("=inspect"), std::string::npos) << inspect.out;
  const auto profile = test::run_speculum("profile --help", dir);
  EXPECT_NE(profile.out.find("--repeat INT:INT in [1 - 10000]=5"), std::string::npos) << profile.out;
  const auto compare = test::run_speculum("compare --help", dir);
  EXPECT_NE(compare.out.find("=psnr"), std::string::npos) << compare.out;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace speculum
