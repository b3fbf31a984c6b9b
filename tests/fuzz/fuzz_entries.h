// The entry points the fuzzers (tests/fuzz/fuzz_*.cpp, built with -DSPECULUM_FUZZ=ON) and the
// corpus replay test (tests/fuzz/corpus_replay_test.cpp, in the ordinary build) share: one per
// parser that reads a user's bytes. Each writes the bytes where the loader expects a file and
// loads it; bad input must end as an InputError, which counts as `rejected`. Anything else that
// escapes (another exception, a crash, a sanitizer report) is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace speculum::fuzz {

enum class Outcome { loaded, rejected };

struct Target {
  const char* name;         // also the corpus folder: tests/fuzz/corpus/<name>/
  const char* description;  // what the bytes are
  Outcome (*run)(std::span<const std::uint8_t> bytes);
};

std::span<const Target> targets();
const Target* find_target(std::string_view name);

// Inputs of the multi-file targets (gltf, glb, obj) carry a second file after this line: the
// buffer `fuzz.bin` beside a glTF, the material library `fuzz.mtl` beside an OBJ. Without it,
// only the first file exists and a reference to the second one is a missing file.
inline constexpr std::string_view kPartMarker = "\n%%speculum-fuzz-part%%\n";

// Scene specs whose size would build more triangles than this are parsed but not built: the
// build is bounded (kMaxSceneSize) but would exceed the fuzzers' one-second budget per input.
inline constexpr std::uint64_t kMaxFuzzSceneSize = 50'000;

}  // namespace speculum::fuzz
