// One libFuzzer target per parser: SPECULUM_FUZZ_TARGET names the entry in fuzz_entries.cpp.
// Success and InputError return normally; any other exception escapes and libFuzzer reports
// it (as it reports crashes, leaks and inputs slower than -timeout).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstdio>

#include "tests/fuzz/fuzz_entries.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const speculum::fuzz::Target* target = [] {
    const speculum::fuzz::Target* t = speculum::fuzz::find_target(SPECULUM_FUZZ_TARGET);
    if (!t) {
      std::fprintf(stderr, "no fuzz target '%s'\n", SPECULUM_FUZZ_TARGET);
      std::abort();
    }
    return t;
  }();
  (void)target->run({data, size});
  return 0;
}
