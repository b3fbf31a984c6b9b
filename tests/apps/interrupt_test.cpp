// Ctrl-C during a render: the run stops at the next chunk boundary, the process exits 130
// with one "speculum: interrupted ..." line, and neither the output nor a temporary file is
// left in the output's directory.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "tests/apps/speculum_run.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// Whether process `pid` catches SIGINT yet (the SigCgt mask of /proc/PID/status): true once
// speculum's main has installed its handler.
bool catches_sigint(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("SigCgt:", 0) == 0) return (std::stoull(line.substr(7), nullptr, 16) >> (SIGINT - 1)) & 1;
  return false;
}

TEST(Interrupt, SigintStopsARenderWithoutWritingAnything) {
  const fs::path dir = test::scratch_dir();
  const fs::path out = dir / "render.exr";
  const fs::path err = dir / "stderr.txt";
  // A render of minutes: the reference tracer at many samples per pixel.
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int fd = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::execl(SPECULUM_BINARY, SPECULUM_BINARY, "--threads", "2", "render", "-t", "reference", "--spp", "4096",
            "--width", "128", "--height", "128", "-o", out.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait until the handler is installed (a signal before that would kill the process like
  // any program's), or the process has ended on its own (then the test fails below).
  int status = 0;
  bool ended = false;
  while (!catches_sigint(pid)) {
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      ended = true;
      break;
    }
    ::usleep(10'000);
  }
  ASSERT_FALSE(ended) << test::slurp(err);
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const std::string message = test::slurp(err);
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_EQ(message.rfind("speculum: interrupted", 0), 0u) << message;
  // Nothing but the test's own stderr capture in the directory: no image, no temporary file.
  for (const auto& entry : fs::directory_iterator(dir)) EXPECT_EQ(entry.path(), err) << entry.path();
}

}  // namespace
}  // namespace speculum
