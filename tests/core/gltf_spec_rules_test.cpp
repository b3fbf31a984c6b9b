// The glTF 2.0 specification's validation rules the loader checks before it uses a value:
// one small file per rule, built here from a valid one-triangle asset with a single change,
// which must load (valid variants) or fail with one line naming the problem.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/error.h"
#include "core/scene_loader.h"
#include "tests/core/scene_test_util.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

std::string base64(const std::vector<unsigned char>& b) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < b.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(b[i]) << 16 | (i + 1 < b.size() ? std::uint32_t(b[i + 1]) << 8 : 0) |
                            (i + 2 < b.size() ? b[i + 2] : 0);
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += i + 1 < b.size() ? k[v >> 6 & 63] : '=';
    out += i + 2 < b.size() ? k[v & 63] : '=';
  }
  return out;
}

template <class T>
void put(std::vector<unsigned char>& b, T v) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  b.insert(b.end(), raw, raw + sizeof(T));
}

// A valid asset: one triangle (0,0,0) (1,0,0) (0,1,0), ushort indices, normalized ubyte
// texture coordinates. Each field is the JSON a test may replace.
struct Asset {
  std::vector<unsigned char> bytes;
  std::string accessors, buffer_views, attributes, primitive_extra, node, top_extra;
  std::string buffer_uri;  // empty: a data URI of `bytes`

  Asset() {
    for (float f : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put(bytes, f);  // 0..35
    for (std::uint16_t i : {0, 1, 2, 0}) put(bytes, i);                          // 36..43 (one pad)
    for (std::uint8_t u : {0, 0, 255, 0, 0, 255, 0, 0}) put(bytes, u);            // 44..51 (two pad)
    buffer_views = R"({"buffer":0,"byteOffset":0,"byteLength":36},)"
                   R"({"buffer":0,"byteOffset":36,"byteLength":6},)"
                   R"({"buffer":0,"byteOffset":44,"byteLength":6})";
    accessors = R"({"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},)"
                R"({"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"},)"
                R"({"bufferView":2,"componentType":5121,"normalized":true,"count":3,"type":"VEC2"})";
    attributes = R"("POSITION":0,"TEXCOORD_0":2)";
    node = R"("mesh":0)";
  }
  std::string json() const {
    const std::string uri = buffer_uri.empty() ? "data:application/octet-stream;base64," + base64(bytes) : buffer_uri;
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{)" + node + "}]," +
           R"("meshes":[{"primitives":[{"attributes":{)" + attributes + R"(},"indices":1)" + primitive_extra + "}]}]," +
           R"("buffers":[{"byteLength":)" + std::to_string(bytes.size()) + R"(,"uri":")" + uri + R"("}],)" +
           R"("bufferViews":[)" + buffer_views + R"(],"accessors":[)" + accessors + "]" + top_extra + "}";
  }
};

fs::path spec_rules_dir() {
  const fs::path dir = fs::temp_directory_path() / ("speculum_spec_rules_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// The InputError's message ("" when the file loads); `scene` receives the loaded scene.
std::string load_error(const std::string& name, const std::string& contents, Scene* scene = nullptr) {
  const fs::path file = spec_rules_dir() / name;
  testing::write_text(file, contents);
  try {
    Scene s = load_scene(file.string());
    if (scene) *scene = std::move(s);
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find(file.string()), std::string::npos) << "names the file: " << m;
    return m;
  }
  return "";
}

#define EXPECT_REJECTED(name, asset, text)                                   \
  do {                                                                       \
    const std::string e_ = load_error(name, (asset).json());                 \
    EXPECT_NE(e_.find(text), std::string::npos) << name << ": '" << e_ << "'"; \
  } while (0)

TEST(GltfSpecRules, ValidAssetLoadsWithNormalizedTexcoords) {
  Scene s;
  ASSERT_EQ(load_error("valid.gltf", Asset().json(), &s), "");
  ASSERT_EQ(s.mesh.uvs.size(), 3u);
  EXPECT_EQ(s.mesh.uvs[1], glm::vec2(1.0f, 0.0f));  // ubyte 255 normalized is 1
  EXPECT_EQ(s.mesh.uvs[2], glm::vec2(0.0f, 1.0f));
}

TEST(GltfSpecRules, NormalizedFloatOrUnsignedIntAccessorIsRejected) {
  Asset a;
  a.accessors = R"({"bufferView":0,"componentType":5126,"normalized":true,"count":3,"type":"VEC3"},)" +
                a.accessors.substr(a.accessors.find("},") + 2);
  EXPECT_REJECTED("normalized_float.gltf", a, "is normalized with a float or unsigned int componentType");
}

TEST(GltfSpecRules, IntegerTexcoordsMustBeNormalized) {
  Asset a;
  a.accessors.replace(a.accessors.find(R"("normalized":true,)"), 18, "");
  EXPECT_REJECTED("texcoord_not_normalized.gltf", a, "TEXCOORD_0: accessor 2 has integer components but is not normalized");
}

TEST(GltfSpecRules, ByteStrideMustBeAMultipleOfTheComponentSize) {
  Asset a;
  a.buffer_views.replace(0, a.buffer_views.find("},") + 1, R"({"buffer":0,"byteOffset":0,"byteLength":36,"byteStride":14})");
  EXPECT_REJECTED("stride_14.gltf", a, "byteStride");  // tinygltf's words or ours
  EXPECT_REJECTED("stride_14.gltf", a, "14");
  // A multiple of 4 but smaller than the 12-byte element.
  Asset small;
  small.buffer_views.replace(0, small.buffer_views.find("},") + 1, R"({"buffer":0,"byteOffset":0,"byteLength":36,"byteStride":8})");
  EXPECT_REJECTED("stride_8.gltf", small, "has an invalid byteStride 8 for 12-byte elements");
}

TEST(GltfSpecRules, ByteOffsetsMustBeAlignedToTheComponentSize) {
  Asset accessor_offset;  // accessor.byteOffset 2 with float components
  accessor_offset.accessors.replace(accessor_offset.accessors.find(R"("bufferView":0,)"), 15, R"("bufferView":0,"byteOffset":2,)");
  accessor_offset.buffer_views.replace(0, accessor_offset.buffer_views.find("},") + 1,
                                       R"({"buffer":0,"byteOffset":0,"byteLength":38})");
  accessor_offset.bytes.insert(accessor_offset.bytes.begin() + 36, {0, 0});  // the view stays inside the buffer
  accessor_offset.buffer_views = R"({"buffer":0,"byteOffset":0,"byteLength":38},)"
                                 R"({"buffer":0,"byteOffset":38,"byteLength":6},)"
                                 R"({"buffer":0,"byteOffset":46,"byteLength":6})";
  EXPECT_REJECTED("accessor_offset_2.gltf", accessor_offset, "byteOffset 2 (bufferView 0 at 0) is not a multiple of its component size 4");
  Asset view_offset;  // bufferView.byteOffset 2 + accessor.byteOffset 0
  view_offset.bytes.insert(view_offset.bytes.begin(), {0, 0});
  view_offset.buffer_views = R"({"buffer":0,"byteOffset":2,"byteLength":36},)"
                             R"({"buffer":0,"byteOffset":38,"byteLength":6},)"
                             R"({"buffer":0,"byteOffset":46,"byteLength":6})";
  EXPECT_REJECTED("view_offset_2.gltf", view_offset, "(bufferView 0 at 2) is not a multiple of its component size 4");
}

// Sparse positions: vertex 2 moved from (0,1,0) to (0,2,0) by a one-element sparse part.
Asset sparse_asset(const std::vector<std::uint16_t>& indices) {
  Asset a;
  const std::size_t at = a.bytes.size();  // 52
  for (std::uint16_t i : indices) put(a.bytes, i);
  while (a.bytes.size() % 4) a.bytes.push_back(0);
  const std::size_t values_at = a.bytes.size();
  for (std::size_t k = 0; k < indices.size(); ++k)
    for (float f : {0.f, 2.f, 0.f}) put(a.bytes, f);
  a.buffer_views += R"(,{"buffer":0,"byteOffset":)" + std::to_string(at) + R"(,"byteLength":)" +
                    std::to_string(2 * indices.size()) + R"(},{"buffer":0,"byteOffset":)" + std::to_string(values_at) +
                    R"(,"byteLength":)" + std::to_string(12 * indices.size()) + "}";
  const std::string sparse = R"("sparse":{"count":)" + std::to_string(indices.size()) +
                             R"(,"indices":{"bufferView":3,"componentType":5123},"values":{"bufferView":4}})";
  a.accessors.replace(0, a.accessors.find("},") + 1,
                      std::string(R"({"bufferView":0,)") + R"("componentType":5126,"count":3,"type":"VEC3",)" + sparse + "}");
  return a;
}

TEST(GltfSpecRules, SparseAccessorsReplaceTheirElements) {
  Scene s;
  ASSERT_EQ(load_error("sparse.gltf", sparse_asset({2}).json(), &s), "");
  ASSERT_EQ(s.mesh.positions.size(), 3u);
  EXPECT_EQ(s.mesh.positions[0], glm::vec3(0, 0, 0));
  EXPECT_EQ(s.mesh.positions[1], glm::vec3(1, 0, 0));
  EXPECT_EQ(s.mesh.positions[2], glm::vec3(0, 2, 0));
}

TEST(GltfSpecRules, SparseIndicesMustBeStrictlyIncreasingAndInRange) {
  EXPECT_REJECTED("sparse_repeat.gltf", sparse_asset({1, 1}), "sparse indices that are not strictly increasing (1 then 1)");
  EXPECT_REJECTED("sparse_decreasing.gltf", sparse_asset({2, 1}), "not strictly increasing (2 then 1)");
  EXPECT_REJECTED("sparse_range.gltf", sparse_asset({3}), "sparse index 3 out of range (count 3)");
  Asset too_many = sparse_asset({0, 1, 2});
  too_many.accessors.replace(too_many.accessors.find(R"("count":3,)"), 10, R"("count":2,)");
  EXPECT_REJECTED("sparse_count.gltf", too_many, "sparse.count 3 outside [1, count 2]");
  Asset past = sparse_asset({2});
  past.accessors.replace(past.accessors.find(R"("values":{"bufferView":4})"), 25,
                         R"("values":{"bufferView":4,"byteOffset":4})");
  EXPECT_REJECTED("sparse_past_view.gltf", past, "sparse.values reads past the end of bufferView 4");
}

TEST(GltfSpecRules, IndexDataIsUnnormalizedTightlyPackedAndNeverTheRestartValue) {
  Asset normalized;
  normalized.accessors.replace(normalized.accessors.find(R"("componentType":5123,)"), 21,
                               R"("componentType":5123,"normalized":true,)");
  EXPECT_REJECTED("indices_normalized.gltf", normalized, "indices accessor 1 is normalized");
  Asset strided;
  strided.buffer_views.replace(strided.buffer_views.find(R"("byteLength":6},)"), 16,
                               R"("byteLength":10,"byteStride":4},)");
  EXPECT_REJECTED("indices_stride.gltf", strided, "index data must be tightly packed");
  Asset restart;
  restart.bytes[40] = 0xff;  // index 2 = 65535
  restart.bytes[41] = 0xff;
  EXPECT_REJECTED("indices_restart.gltf", restart, "index 2 = 65535 is the primitive restart value");
}

TEST(GltfSpecRules, EveryAttributeNamesAnExistingAccessor) {
  Asset a;
  a.attributes += R"(,"COLOR_0":7)";
  EXPECT_REJECTED("color_accessor.gltf", a, "attribute COLOR_0 names accessor 7 which does not exist");
}

TEST(GltfSpecRules, MatrixExcludesTranslationRotationScale) {
  Asset a;
  a.node = R"("mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1],"translation":[1,0,0])";
  EXPECT_REJECTED("matrix_and_trs.gltf", a, "node 0 has both a matrix and translation/rotation/scale");
  Asset matrix_only;
  matrix_only.node = R"("mesh":0,"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,5,0,0,1])";
  Scene s;
  ASSERT_EQ(load_error("matrix_only.gltf", matrix_only.json(), &s), "");
  EXPECT_EQ(s.mesh.positions[0], glm::vec3(5, 0, 0));
}

TEST(GltfSpecRules, TextureSamplerMustExist) {
  Asset a;
  a.primitive_extra = R"(,"material":0)";
  a.top_extra = R"(,"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
                R"("textures":[{"source":0,"sampler":3}],"images":[{"uri":"missing.png"}])";
  EXPECT_REJECTED("sampler.gltf", a, "texture 0 names sampler 3 which does not exist");
}

TEST(GltfSpecRules, ExtensionIntegersMustBeIntegers) {
  Asset a;
  a.primitive_extra = R"(,"material":0)";
  a.top_extra = R"(,"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0,)"
                R"("extensions":{"KHR_texture_transform":{"texCoord":1e300}}}}}],)"
                R"("textures":[{"source":0}],"images":[{"uri":"missing.png"}])";
  EXPECT_REJECTED("texcoord_1e300.gltf", a, "KHR_texture_transform.texCoord must be an integer");
}

TEST(GltfSpecRules, PerspectiveCameraNeedsPositiveFieldOfViewAndNearPlane) {
  for (const char* camera : {R"({"yfov":0,"znear":0.1})", R"({"yfov":0.8,"znear":0})",
                             R"({"yfov":0.8,"znear":1,"zfar":0.5})", R"({"yfov":4,"znear":0.1})"}) {
    Asset a;
    a.node = R"("mesh":0,"camera":0)";
    a.top_extra = std::string(R"(,"cameras":[{"type":"perspective","perspective":)") + camera + "}]";
    EXPECT_REJECTED("camera.gltf", a, "camera 0 needs 0 < yfov < pi, znear > 0 and zfar > znear");
  }
}

TEST(GltfSpecRules, SpotConesAndRangeAreChecked) {
  Asset a;
  a.node = R"("mesh":0,"extensions":{"KHR_lights_punctual":{"light":0}})";
  a.top_extra = R"(,"extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","spot":{"innerConeAngle":0.2,"outerConeAngle":2.0}}]}})";
  EXPECT_REJECTED("spot.gltf", a, "light 0 has a negative range or spot cone angles outside");
  Asset fractional = a;
  fractional.node = R"("mesh":0,"extensions":{"KHR_lights_punctual":{"light":0.5}})";
  EXPECT_REJECTED("light_index.gltf", fractional, "node 0 has a malformed KHR_lights_punctual");
}

TEST(GltfSpecRules, DataUrisMustBeValidBase64OfTheDeclaredLength) {
  Asset bad_char;
  bad_char.buffer_uri = "data:application/octet-stream;base64," + base64(bad_char.bytes);
  bad_char.buffer_uri[bad_char.buffer_uri.size() - 10] = '!';
  EXPECT_REJECTED("base64_char.gltf", bad_char, "buffers[0] data URI has invalid base64 at character");
  Asset bad_pad;
  bad_pad.buffer_uri = "data:application/octet-stream;base64," + base64(bad_pad.bytes) + "=A==";
  EXPECT_REJECTED("base64_pad.gltf", bad_pad, "buffers[0] data URI has invalid base64");
  Asset not_base64;
  not_base64.buffer_uri = "data:application/octet-stream,AAAA";
  EXPECT_REJECTED("not_base64.gltf", not_base64, "buffers[0] data URI is not base64");
  Asset short_data;  // 52 bytes declared, 48 encoded
  short_data.buffer_uri = "data:application/octet-stream;base64," +
                          base64(std::vector<unsigned char>(short_data.bytes.begin(), short_data.bytes.end() - 4));
  EXPECT_NE(load_error("base64_short.gltf", short_data.json()), "");
}

TEST(GltfSpecRules, SchemaShapesAreChecked) {
  Asset a;
  std::string json = a.json();
  json.replace(json.find(R"("primitives":[{)"), 15, R"("primitives":{"p":{)");
  json.replace(json.find(R"(,"indices":1}]})"), 15, R"(,"indices":1}}})");
  EXPECT_NE(load_error("primitives_object.gltf", json).find("meshes[0].primitives must be a non-empty array"),
            std::string::npos);
  json = a.json();
  json.replace(json.find(R"("nodes":[{)"), 10, R"("nodes":[7,{)");
  EXPECT_NE(load_error("node_not_object.gltf", json).find("nodes[0] is not an object"), std::string::npos);
}

// A missing image beside a scene named without a folder (the current directory's) is a
// missing texture, not a file outside the scene's folder.
TEST(GltfSpecRules, MissingImageBesideASceneInTheCurrentDirectoryIsNotOutside) {
  Asset a;
  a.primitive_extra = R"(,"material":0)";
  a.top_extra = R"(,"materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],)"
                R"("textures":[{"source":0}],"images":[{"uri":"missing.png"}])";
  const fs::path dir = spec_rules_dir();
  std::ofstream(dir / "cwd.gltf") << a.json();
  const fs::path before = fs::current_path();
  fs::current_path(dir);
  LoadReport report;
  SceneOptions o;
  o.report = &report;
  std::string error;
  try {
    (void)load_scene("cwd.gltf", o);
  } catch (const InputError& e) {
    error = e.what();
  }
  fs::current_path(before);
  EXPECT_EQ(error, "");
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("'missing.png' is missing or could not be decoded"), std::string::npos)
      << report.warnings[0];
}

// A .glb of `json` (padded to 4 bytes) followed by the given chunks (type, payload).
std::string glb(std::string json, const std::vector<std::pair<std::uint32_t, std::vector<unsigned char>>>& chunks,
                int json_pad = -1) {
  std::vector<unsigned char> b;
  while (json.size() % 4) json += ' ';
  const std::uint32_t json_len = json_pad < 0 ? static_cast<std::uint32_t>(json.size()) : static_cast<std::uint32_t>(json_pad);
  put(b, 0x46546C67u);
  put(b, 2u);
  put(b, 0u);  // total, below
  put(b, json_len);
  put(b, 0x4E4F534Au);
  b.insert(b.end(), json.begin(), json.begin() + json_len);
  for (const auto& [type, payload] : chunks) {
    put(b, static_cast<std::uint32_t>(payload.size()));
    put(b, type);
    b.insert(b.end(), payload.begin(), payload.end());
  }
  const std::uint32_t total = static_cast<std::uint32_t>(b.size());
  std::memcpy(&b[8], &total, 4);
  return std::string(b.begin(), b.end());
}

// An image's bufferView is decoded while tinygltf parses: it must lie inside its buffer's
// declared byteLength before then (found by fuzzing: the decoder read past tinygltf's copy).
TEST(GltfSpecRules, ImageBufferViewMustLieInsideItsBuffer) {
  Asset inside;
  inside.buffer_views += R"(,{"buffer":0,"byteOffset":44,"byteLength":8})";
  inside.top_extra = R"(,"images":[{"bufferView":3,"mimeType":"image/png"}])";
  EXPECT_EQ(load_error("image_view_inside.gltf", inside.json()), "") << "not a PNG: left out, the scene loads";
  Asset past = inside;
  past.buffer_views = inside.buffer_views.substr(0, inside.buffer_views.rfind(",{")) +
                      R"(,{"buffer":0,"byteOffset":44,"byteLength":4096})";
  EXPECT_REJECTED("image_view_past.gltf", past, "images[0] uses bufferView 3, which runs past the end of buffer 0");
}

TEST(GltfSpecRules, GlbChunkLayoutIsChecked) {
  Asset a;
  std::string json = a.json();
  // The buffer is the BIN chunk: no uri.
  const std::size_t uri = json.find(R"(,"uri":")");
  json.erase(uri, json.find('"', uri + 8) + 1 - uri);
  const std::vector<unsigned char> bin = a.bytes;
  constexpr std::uint32_t kBin = 0x004E4942u, kOther = 0x12345678u;
  EXPECT_EQ(load_error("ok.glb", glb(json, {{kBin, bin}})), "");
  EXPECT_EQ(load_error("unknown_chunk.glb", glb(json, {{kBin, bin}, {kOther, {1, 2, 3, 4}}})), "")
      << "chunks of unknown types are skipped";
  std::string odd = json;
  while (odd.size() % 4 != 1) odd += ' ';
  EXPECT_NE(load_error("json_unaligned.glb", glb(odd, {{kBin, bin}}, static_cast<int>(odd.size())))
                .find("JSON chunk length"),
            std::string::npos);
  EXPECT_NE(load_error("two_bin.glb", glb(json, {{kBin, bin}, {kBin, bin}})).find("BIN chunk must directly follow"),
            std::string::npos);
  EXPECT_NE(load_error("bin_late.glb", glb(json, {{kOther, {0, 0, 0, 0}}, {kBin, bin}})).find("BIN chunk must directly follow"),
            std::string::npos);
  EXPECT_NE(load_error("two_json.glb", glb(json, {{kBin, bin}, {0x4E4F534Au, {' ', ' ', ' ', ' '}}}))
                .find("second JSON chunk"),
            std::string::npos);
  std::vector<unsigned char> bin3(bin.begin(), bin.end());
  bin3.resize(bin.size() + 3);  // a chunk length that is not a multiple of 4
  EXPECT_NE(load_error("bin_unaligned.glb", glb(json, {{kBin, bin3}})).find("length is not a multiple of 4"),
            std::string::npos);
  EXPECT_NE(load_error("trailing.glb", glb(json, {{kBin, bin}}) + "junk").find("(trailing data)"), std::string::npos);
  std::string cut = glb(json, {{kBin, bin}});
  cut.resize(cut.size() - 5);
  std::uint32_t total = static_cast<std::uint32_t>(cut.size());
  std::memcpy(&cut[8], &total, 4);  // a consistent total, a chunk running past it
  EXPECT_NE(load_error("chunk_past_end.glb", cut).find("runs past the end"), std::string::npos);
}

}  // namespace
}  // namespace speculum
