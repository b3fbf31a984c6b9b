// The fuzzers' corpora and crash reproducers replayed in the ordinary build, through the same
// entry points as the libFuzzer targets (fuzz_entries.h): every file loads or is rejected with
// an InputError; no other exception escapes (a crash fails the whole binary, and the
// sanitizer builds of the suite catch memory errors on the same files).
#include <algorithm>
#include <cstring>
#include <optional>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/fuzz/fuzz_entries.h"

namespace fs = std::filesystem;
using speculum::fuzz::Outcome;
using speculum::fuzz::Target;

namespace {

std::vector<std::uint8_t> read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// Runs `file` through `target`; any exception but InputError (which run() turns into
// `rejected`) is a failure naming the file.
std::optional<Outcome> replay(const Target& target, const fs::path& file) {
  const std::vector<std::uint8_t> bytes = read_bytes(file);
  try {
    return target.run(bytes);
  } catch (const std::exception& e) {
    ADD_FAILURE() << target.name << " " << file << ": escaped with " << e.what();
  } catch (...) {
    ADD_FAILURE() << target.name << " " << file << ": escaped with a non-standard exception";
  }
  return std::nullopt;
}

const fs::path kFuzzDir = SPECULUM_FUZZ_DIR;
const fs::path kData = SPECULUM_TEST_DATA;

}  // namespace

TEST(FuzzCorpus, EveryTargetHasASeedCorpus) {
  for (const Target& t : speculum::fuzz::targets())
    EXPECT_GE(files_in(kFuzzDir / "corpus" / t.name).size(), 3u) << "tests/fuzz/corpus/" << t.name;
}

TEST(FuzzCorpus, CorpusFilesLoadOrAreRejected) {
  for (const Target& t : speculum::fuzz::targets()) {
    int loaded = 0, rejected = 0;
    for (const fs::path& f : files_in(kFuzzDir / "corpus" / t.name)) {
      const auto outcome = replay(t, f);
      if (outcome == Outcome::loaded) ++loaded;
      if (outcome == Outcome::rejected) ++rejected;
    }
    // A corpus that only fails would mean the harness never reaches the parser's success path.
    EXPECT_GT(loaded, 0) << t.name << ": no corpus file loads";
    EXPECT_GT(rejected, 0) << t.name << ": no corpus file is rejected";
  }
}

// Each file made a fuzzer crash, leak or time out before the loader was fixed; some are
// rejected now, some load (a .glb whose embedded image stb_image overflowed on loads without
// that texture).
TEST(FuzzCorpus, CrashReproducersLoadOrAreRejected) {
  int replayed = 0;
  for (const Target& t : speculum::fuzz::targets())
    for (const fs::path& f : files_in(kFuzzDir / "crashes" / t.name)) {
      EXPECT_TRUE(replay(t, f).has_value()) << f;
      ++replayed;
    }
  EXPECT_GE(replayed, 7);
}

// The harness is the loader: the good files load and the bad ones are rejected through it, as
// through load_scene (tests/core/bad_input_test.cpp).
TEST(FuzzCorpus, HarnessLoadsGoodFilesAndRejectsBadOnes) {
  int checked = 0;
  for (const char* kind : {"good", "bad"}) {
    for (const fs::path& f : files_in(kData / kind)) {
      const std::string ext = f.extension().string();
      const Target* t = ext.empty() ? nullptr : speculum::fuzz::find_target(ext.substr(1));
      if (!t) continue;
      ++checked;
      EXPECT_EQ(replay(*t, f), std::string(kind) == "good" ? Outcome::loaded : Outcome::rejected) << f;
    }
  }
  EXPECT_GT(checked, 40);
}

TEST(FuzzCorpus, SplitsACompanionFileAtThePartMarker) {
  // An OBJ whose material library comes after the marker: loads, and the same OBJ naming a
  // library that is not there loads too (a missing .mtl is a warning), but a glTF whose
  // external buffer is missing is rejected and the same glTF with the buffer loads.
  const std::string tri = R"({"asset":{"version":"2.0"},"buffers":[{"uri":"fuzz.bin","byteLength":36}],
"bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,"componentType":5126,
"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],"meshes":[{"primitives":[{"attributes":
{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
  std::string bin(36, '\0');
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(bin.data(), v, sizeof v);
  const Target& gltf = *speculum::fuzz::find_target("gltf");
  auto run = [](const Target& t, const std::string& s) {
    return t.run({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()});
  };
  EXPECT_EQ(run(gltf, tri), Outcome::rejected);
  EXPECT_EQ(run(gltf, tri + std::string(speculum::fuzz::kPartMarker) + bin), Outcome::loaded);
  EXPECT_EQ(run(gltf, tri), Outcome::rejected);  // the previous input's buffer is gone
}
