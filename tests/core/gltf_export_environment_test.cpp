// glTF export drops nothing silently: the environment survives export -> load bit-exactly
// through the root extras (core/gltf_environment.h), malformed extras are InputError naming
// the file, and extensionsUsed lists exactly the extensions written anywhere in the JSON.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/gltf_writer.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "scene_test_util.h"

namespace speculum {
namespace {

using nlohmann::json;

// The glTF JSON of a written file: the whole file for .gltf, the JSON chunk for .glb
// (glTF 2.0 spec §4.4: 12-byte header, then chunk length, chunk type, chunk data).
json read_json(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (path.extension() == ".glb") {
    EXPECT_GE(bytes.size(), 20u);
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return json::parse(bytes.substr(20, length));
  }
  return json::parse(bytes);
}

// Every key of every "extensions" object anywhere in the document (nested ones included,
// e.g. a textureInfo inside KHR_materials_transmission).
void collect_extensions(const json& j, std::set<std::string>& out) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key() == "extensions" && it.value().is_object())
        for (auto e = it.value().begin(); e != it.value().end(); ++e) out.insert(e.key());
      collect_extensions(it.value(), out);
    }
  } else if (j.is_array()) {
    for (const json& item : j) collect_extensions(item, out);
  }
}

std::set<std::string> extensions_used(const json& doc) {
  std::set<std::string> used;
  if (doc.contains("extensionsUsed"))
    for (const json& name : doc["extensionsUsed"]) used.insert(name.get<std::string>());
  return used;
}

// Exact equality, float bits included (so -0.0 vs 0.0 or a rounding would fail). memcmp may
// not be given the null data() of an empty vector, even for zero bytes.
bool same_bits(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec4)) == 0);
}

void expect_same_environment(const Environment& back, const Environment& src) {
  EXPECT_EQ(back.constant, src.constant);
  EXPECT_EQ(back.intensity, src.intensity);
  ASSERT_EQ(back.has_image(), src.has_image());
  EXPECT_EQ(back.equirect.width, src.equirect.width);
  EXPECT_EQ(back.equirect.height, src.equirect.height);
  EXPECT_TRUE(same_bits(back.equirect.pixels, src.equirect.pixels));
}

// A small scene (no environment of its own) to hang hand-made environments and materials on.
Scene small_scene() {
  SceneOptions o;
  o.size = 1000;
  Scene s = load_scene("bowl", o);
  s.environment = Environment{};
  return s;
}

// An equirect whose pixels are all different and include awkward floats: tiny, huge,
// negative zero, a value that is not a short decimal.
ImageRGBA awkward_equirect(int w, int h) {
  ImageRGBA img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img.at(x, y) = glm::vec4(0.1f * static_cast<float>(x) + 1e-3f * static_cast<float>(y),
                               1.0f / 3.0f + static_cast<float>(y), 7.25f * static_cast<float>(x * y), 1.0f);
  img.at(0, 0) = glm::vec4(std::numeric_limits<float>::denorm_min(), 3.0e38f, -0.0f, 0.5f);
  return img;
}

TEST(GltfExportEnvironment, EveryBuiltinSceneKeepsItsEnvironment) {
  const auto dir = testing::temp_dir("export_env_builtin");
  int images = 0, constants = 0;
  for (const BuiltinScene& def : builtin_scenes()) {
    SceneOptions o;
    o.size = 2000;
    const Scene src = load_scene(def.name, o);
    (src.environment.has_image() ? images : constants) += 1;
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(std::string(def.name) + ext);
      const std::string path = (dir / (std::string(def.name) + ext)).string();
      write_gltf(src, path);
      const Scene back = load_scene(path);
      expect_same_environment(back.environment, src.environment);
      EXPECT_EQ(back.environment.source, path);
      // The environment is extras, not an extension: nothing extra is declared.
      EXPECT_EQ(extensions_used(read_json(path)).count("speculum_environment"), 0u);
    }
  }
  // Both kinds were exercised, so the checks above covered pixels as well as constants.
  EXPECT_GT(images, 0);
  EXPECT_GT(constants, 0);
  std::filesystem::remove_all(dir);
}

TEST(GltfExportEnvironment, HandMadeEnvironmentsRoundTripBitExactly) {
  const auto dir = testing::temp_dir("export_env_hand");
  Scene constant = small_scene();
  constant.environment.constant = glm::vec3(0.7f, 1.3f, 1e-7f);
  constant.environment.intensity = 0.125f;
  Scene image = small_scene();
  image.environment.constant = glm::vec3(0.1f, 0.2f, 0.3f);  // kept even though the image wins
  image.environment.intensity = 2.75f;
  image.environment.equirect = awkward_equirect(7, 3);
  for (const Scene* src : {&constant, &image})
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(std::string(src->environment.has_image() ? "image" : "constant") + ext);
      const std::string path = (dir / (std::string("hand") + ext)).string();
      write_gltf(*src, path);
      expect_same_environment(load_scene(path).environment, src->environment);
    }
  std::filesystem::remove_all(dir);
}

TEST(GltfExportEnvironment, FilesWithoutItKeepTheDefaultAndForeignExtrasAreIgnored) {
  const Scene plain = load_scene(SPECULUM_TEST_DATA "/good/triangle.gltf");
  expect_same_environment(plain.environment, Environment{});

  const auto dir = testing::temp_dir("export_env_foreign");
  const auto path = dir / "foreign.gltf";
  write_gltf(small_scene(), path.string());
  const json written = read_json(path);
  for (const json& extras : {json{{"authoring_tool", {{"version", 3}}}}, json("a string"), json(42)}) {
    SCOPED_TRACE(extras.dump());
    json doc = written;
    doc["extras"] = extras;
    testing::write_text(path, doc.dump());
    expect_same_environment(load_scene(path.string()).environment, Environment{});
  }
  // An unknown key inside ours is reported, not fatal.
  json doc = written;
  doc["extras"]["speculum_environment"]["rotation"] = 1.5;
  testing::write_text(path, doc.dump());
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  load_scene(path.string(), o);
  bool reported = false;
  for (const std::string& w : report.warnings) reported |= w.find("rotation") != std::string::npos;
  EXPECT_TRUE(reported);
  std::filesystem::remove_all(dir);
}

TEST(GltfExportEnvironment, MalformedEnvironmentExtrasAreInputErrorNamingTheFile) {
  const auto dir = testing::temp_dir("export_env_bad");
  Scene src = small_scene();
  src.environment.equirect = awkward_equirect(4, 2);
  const auto good = dir / "good.gltf";
  write_gltf(src, good.string());
  const json written = read_json(good);
  ASSERT_TRUE(written["extras"]["speculum_environment"].contains("equirect"));

  using Edit = std::function<void(json& env)>;
  const std::vector<std::pair<const char*, Edit>> edits = {
      {"not an object", [](json& e) { e = 5; }},
      {"color of 2", [](json& e) { e["color"] = {1.0, 2.0}; }},
      {"color not numbers", [](json& e) { e["color"] = {"a", 0, 0}; }},
      {"color beyond float", [](json& e) { e["color"] = {1e39, 0, 0}; }},
      {"negative intensity", [](json& e) { e["intensity"] = -1.0; }},
      {"intensity a string", [](json& e) { e["intensity"] = "bright"; }},
      {"equirect not an object", [](json& e) { e["equirect"] = "sky.hdr"; }},
      {"no height", [](json& e) { e["equirect"].erase("height"); }},
      {"no such bufferView", [](json& e) { e["equirect"]["bufferView"] = 999; }},
      {"zero width", [](json& e) { e["equirect"]["width"] = 0; }},
      {"width disagrees with the bytes", [](json& e) { e["equirect"]["width"] = 5; }},
      {"other format", [](json& e) { e["equirect"]["format"] = "RGB8"; }},
  };
  const auto bad = dir / "bad.gltf";
  for (const auto& [name, edit] : edits) {
    SCOPED_TRACE(name);
    json doc = written;
    edit(doc["extras"]["speculum_environment"]);
    testing::write_text(bad, doc.dump());
    try {
      load_scene(bad.string());
      ADD_FAILURE() << "loaded";
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), bad.string());
      EXPECT_NE(e.problem().find("speculum_environment"), std::string::npos) << e.what();
    }
  }

  // A non-finite pixel is rejected on load, wherever it came from.
  src.environment.equirect.at(3, 1).y = std::numeric_limits<float>::quiet_NaN();
  const auto nan = dir / "nan.glb";
  write_gltf(src, nan.string());
  try {
    load_scene(nan.string());
    ADD_FAILURE() << "loaded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), nan.string());
    EXPECT_NE(e.problem().find("pixel 3,1"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// uv' = T R S (u, v, 1), as KHR_texture_transform composes offset, rotation and scale;
// R = [[cos, sin], [-sin, cos]] (rows), written by columns for glm.
glm::mat3 uv_transform(glm::vec2 offset, float rotation, glm::vec2 scale) {
  const float c = std::cos(rotation), s = std::sin(rotation);
  return glm::mat3(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1) * glm::mat3(c, -s, 0, s, c, 0, 0, 0, 1) *
         glm::mat3(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
}

float max_difference(const glm::mat3& a, const glm::mat3& b) {
  float d = 0.0f;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) d = std::max(d, std::fabs(a[c][r] - b[c][r]));
  return d;
}

struct Slot {
  const char* name;
  TextureRef Material::*ref;
};
constexpr Slot kSlots[] = {{"baseColor", &Material::base_color_texture},
                           {"metallicRoughness", &Material::metallic_roughness_texture},
                           {"normal", &Material::normal_texture},
                           {"emissive", &Material::emissive_texture},
                           {"transmission", &Material::transmission_texture}};

Scene with_texture(Scene s) {
  s.textures.push_back(ImageRGBA(2, 2, glm::vec4(0.5f, 0.25f, 0.75f, 1.0f)));
  s.texture_sources.push_back("test texture");
  return s;
}

TEST(GltfExportExtensions, ATransformOnAnyTextureIsDeclared) {
  const auto dir = testing::temp_dir("export_ext_slot");
  const Scene base = with_texture(small_scene());
  const glm::mat3 transform = uv_transform({0.25f, 0.5f}, 0.3f, {2.0f, 3.0f});
  for (const Slot& slot : kSlots) {
    SCOPED_TRACE(slot.name);
    Scene s = base;
    TextureRef& ref = s.materials[0].*slot.ref;
    ref.texture = static_cast<int>(s.textures.size() - 1);
    ref.uv_transform = transform;
    const auto path = dir / "slot.gltf";
    write_gltf(s, path.string());
    const json doc = read_json(path);
    std::set<std::string> written;
    collect_extensions(doc, written);
    EXPECT_EQ(written.count("KHR_texture_transform"), 1u);
    EXPECT_EQ(extensions_used(doc), written);
    // And the transform itself comes back on the same texture.
    const Scene back = load_scene(path.string());
    const TextureRef& loaded = back.materials[0].*slot.ref;
    ASSERT_TRUE(loaded.valid());
    EXPECT_LT(max_difference(loaded.uv_transform, transform), 1e-5f);
  }
  std::filesystem::remove_all(dir);
}

TEST(GltfExportExtensions, ExtensionsUsedIsExactlyWhatIsWritten) {
  const auto dir = testing::temp_dir("export_ext_all");
  // Every extension the writer knows, at once: transforms on all five textures, emissive
  // strength, IOR, transmission and punctual lights (the living room has lights).
  SceneOptions o;
  o.size = 2000;
  Scene s = with_texture(load_scene("living-room", o));
  Material& m = s.materials[0];
  for (const Slot& slot : kSlots) {
    (m.*slot.ref).texture = static_cast<int>(s.textures.size() - 1);
    (m.*slot.ref).uv_transform = uv_transform({0.1f, 0.0f}, 0.0f, {1.0f, 2.0f});
  }
  m.emissive = glm::vec3(4.0f, 2.0f, 1.0f);
  m.ior = 1.33f;
  ASSERT_FALSE(s.lights.empty());
  // A scene with no extension at all declares none.
  Scene bare = small_scene();
  bare.lights.clear();
  for (Material& bm : bare.materials) bm = Material{};
  for (const Scene* scene : {&s, &bare})
    for (const char* ext : {".glb", ".gltf"}) {
      SCOPED_TRACE(std::string(scene == &s ? "all" : "bare") + ext);
      const auto path = dir / (std::string("all") + ext);
      write_gltf(*scene, path.string());
      const json doc = read_json(path);
      std::set<std::string> written;
      collect_extensions(doc, written);
      EXPECT_EQ(extensions_used(doc), written);
      EXPECT_EQ(written.size(), scene == &s ? 5u : 0u);
      EXPECT_FALSE(doc.contains("extensionsRequired"));
    }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace speculum
