// Tests that need something outside the project (Chromium, gnuplot, GNU parallel, OSMesa, Debian's
// assimp-testmodels) say so instead of passing quietly without it: under CI (the CI
// environment variable set, as .ci/run does) a missing dependency fails the test with what to
// install; elsewhere the test is skipped, and GoogleTest lists it as skipped.
#pragma once

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace speculum::test {

inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && *ci != '\0' && std::string(ci) != "0" && std::string(ci) != "false";
}

}  // namespace speculum::test

// In a TEST body: returns from the test (failing under CI, skipping elsewhere) unless
// `available`. `package` names what to install, e.g. "the Debian package assimp-testmodels".
#define SPECULUM_REQUIRE(available, package)                                                  \
  do {                                                                                         \
    if (!(available)) {                                                                        \
      if (::speculum::test::in_ci())                                                           \
        FAIL() << "missing test dependency: install " << package << " (.ci/setup.sh does)";    \
      else                                                                                     \
        GTEST_SKIP() << "skipped: install " << package << " to run this test (.ci/setup.sh)"; \
    }                                                                                          \
  } while (0)
