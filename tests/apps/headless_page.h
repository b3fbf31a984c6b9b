// Opens a page speculum wrote (the inspect report, the matrix atlas) in headless Chromium and
// reads what the page's own self-check script (apps/inspect/inspect_report.h
// page_check_script) wrote into its status element after the load event, plus Chromium's
// console lines (the pages log nothing, so any is an error).
#pragma once

#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include "tests/apps/speculum_run.h"

namespace speculum::test {

struct PageStatus {
  std::string state, failed;
  int images = -1, loaded = -1;
  std::string console;
};

inline std::string html_attribute(const std::string& tag, const std::string& name) {
  std::smatch m;
  if (std::regex_search(tag, m, std::regex(" " + name + "=\"([^\"]*)\""))) return m[1];
  return "";
}

// `status_id`: the id of the element the page's script fills ("inspect-status", ...).
inline PageStatus open_in_chromium(const std::filesystem::path& page, const std::filesystem::path& work,
                                   const std::string& status_id) {
  const std::filesystem::path profile = work / ("chromium-profile-" + std::to_string(std::rand()));
  const CommandResult r = run_shell(
      "timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-background-networking "
      "--disable-component-update --disable-sync --no-first-run --no-default-browser-check --user-data-dir=" +
          sh_quote(profile.string()) + " --enable-logging=stderr --v=0 --dump-dom " +
          sh_quote("file://" + std::filesystem::absolute(page).string()),
      work);
  std::filesystem::remove_all(profile);
  PageStatus s;
  std::smatch m;
  if (std::regex_search(r.out, m, std::regex("<p id=\"" + status_id + "\"[^>]*>"))) {
    const std::string tag = m[0];
    s.state = html_attribute(tag, "data-state");
    s.failed = html_attribute(tag, "data-failed");
    const std::string images = html_attribute(tag, "data-images"), loaded = html_attribute(tag, "data-loaded");
    if (!images.empty()) s.images = std::stoi(images);
    if (!loaded.empty()) s.loaded = std::stoi(loaded);
  }
  std::istringstream err(r.err);
  for (std::string line; std::getline(err, line);)
    if (line.find(":CONSOLE") != std::string::npos) s.console += line + "\n";
  return s;
}

}  // namespace speculum::test
