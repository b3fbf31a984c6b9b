// Runs the real speculum binary (or any shell command) for the apps tests: exit status,
// stdout and stderr, and a scratch directory per test.
#pragma once

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace speculum::test {

struct CommandResult {
  int status = -1;
  std::string out, err;
  long peak_rss_kb = -1;  // the largest resident set of the command's processes (wait4's ru_maxrss)
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A fresh directory named after the running test.
inline std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = std::filesystem::temp_directory_path() /
             ("speculum_h9_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" +
              info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Whether `s` contains `part` (the CLI tests check messages by their key phrases).
inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

inline std::string sh_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// `command` through /bin/sh, outputs captured in `dir`.
inline CommandResult run_shell(const std::string& command, const std::filesystem::path& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string cmd = command + " >" + sh_quote(out.string()) + " 2>" + sh_quote(err.string());
  // fork + wait4 rather than std::system: the child's rusage gives its peak memory (the
  // shell's, or the largest of the processes it waited for).
  CommandResult r;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int raw = -1;
  struct rusage usage {};
  if (pid > 0) {
    while (::wait4(pid, &raw, 0, &usage) < 0 && errno == EINTR) {
    }
    r.peak_rss_kb = usage.ru_maxrss;
  }
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// speculum with `args` (already shell-quoted where needed).
inline CommandResult run_speculum(const std::string& args, const std::filesystem::path& dir) {
  return run_shell(sh_quote(SPECULUM_BINARY) + " " + args, dir);
}

}  // namespace speculum::test
