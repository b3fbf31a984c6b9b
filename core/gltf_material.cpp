// glTF materials and textures (see gltf_material.h).
#include "core/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/error.h"
#include "core/image.h"

namespace speculum::gltf {
namespace {

constexpr std::int64_t kMaxTexturePixels = std::int64_t{1} << 28;

float number(const tinygltf::Value& obj, const char* key, float fallback) {
  if (!obj.IsObject() || !obj.Has(key) || !obj.Get(key).IsNumber()) return fallback;
  return static_cast<float>(obj.Get(key).GetNumberAsDouble());
}

// An integer property of an extension's object (tinygltf leaves extensions as raw JSON
// values): `fallback` when absent, InputError when it is not an integer an int holds — a
// double such as 1e300 would otherwise be converted with undefined behaviour.
int integer(const std::string& path, const tinygltf::Value& obj, const char* key, int fallback,
            const std::string& what) {
  if (!obj.IsObject() || !obj.Has(key)) return fallback;
  const tinygltf::Value& v = obj.Get(key);
  const double x = v.IsNumber() ? v.GetNumberAsDouble() : 0.5;
  if (!(x >= -2147483648.0 && x <= 2147483647.0) || std::floor(x) != x)
    throw InputError(path, what + "." + key + " must be an integer");
  return static_cast<int>(x);
}

const tinygltf::Value* extension(const tinygltf::ExtensionMap& ext, const char* name) {
  auto it = ext.find(name);
  return it == ext.end() || !it->second.IsObject() ? nullptr : &it->second;
}

}  // namespace

// uv' = T * R * S * (u, v, 1) (KHR_texture_transform). R turns the uvs counter-clockwise by
// `rotation` (the image appears turned clockwise, v pointing down): u' = cos·u + sin·v,
// v' = -sin·u + cos·v, the rotation the extension's own example needs to select the lower
// left quadrant (offset [0, 1], rotation π/2, scale 0.5). The extension's GLSL listing
// writes the transpose into a column-major mat3, which turns the other way and points
// TextureTransformTest's arrow at the red marker. glm is column-major: columns below.
glm::mat3 texture_transform(const tinygltf::Value& t) {
  float ox = 0, oy = 0, sx = 1, sy = 1;
  if (t.Has("offset") && t.Get("offset").IsArray() && t.Get("offset").ArrayLen() == 2) {
    ox = static_cast<float>(t.Get("offset").Get(0).GetNumberAsDouble());
    oy = static_cast<float>(t.Get("offset").Get(1).GetNumberAsDouble());
  }
  if (t.Has("scale") && t.Get("scale").IsArray() && t.Get("scale").ArrayLen() == 2) {
    sx = static_cast<float>(t.Get("scale").Get(0).GetNumberAsDouble());
    sy = static_cast<float>(t.Get("scale").Get(1).GetNumberAsDouble());
  }
  const float r = number(t, "rotation", 0.0f);
  const float c = std::cos(r), s = std::sin(r);
  const glm::mat3 translation(1, 0, 0, 0, 1, 0, ox, oy, 1);
  const glm::mat3 rotation(c, -s, 0, s, c, 0, 0, 0, 1);
  const glm::mat3 scale(sx, 0, 0, 0, sy, 0, 0, 0, 1);
  return translation * rotation * scale;
}

namespace {

bool finite(float x) { return std::isfinite(x); }

}  // namespace

bool extension_supported(const std::string& name) {
  static const char* const kSupported[] = {
      "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_emissive_strength",
      "KHR_lights_punctual", "KHR_texture_transform"};
  return std::any_of(std::begin(kSupported), std::end(kSupported),
                     [&](const char* s) { return name == s; });
}

MaterialTable::MaterialTable(const std::string& path, const tinygltf::Model& model, Scene& scene,
                             LoadReport& report)
    : path_(path), model_(model), scene_(scene), report_(report),
      material_map_(model.materials.size(), -1) {}

std::uint32_t MaterialTable::scene_material(int index) {
  if (index < 0) {
    if (default_material_ < 0) {
      default_material_ = static_cast<int>(scene_.materials.size());
      scene_.materials.push_back(default_material());
    }
    return static_cast<std::uint32_t>(default_material_);
  }
  if (static_cast<std::size_t>(index) >= model_.materials.size())
    throw InputError(path_, "material index " + std::to_string(index) + " out of range (" +
                                std::to_string(model_.materials.size()) + " materials)");
  int& slot = material_map_[static_cast<std::size_t>(index)];
  if (slot < 0) {
    Material m = convert(static_cast<std::size_t>(index));
    slot = static_cast<int>(scene_.materials.size());
    scene_.materials.push_back(std::move(m));
  }
  return static_cast<std::uint32_t>(slot);
}

Material MaterialTable::convert(std::size_t index) {
  const tinygltf::Material& g = model_.materials[index];
  const std::string what = "material " + std::to_string(index) + (g.name.empty() ? "" : " '" + g.name + "'");
  Material m;
  m.name = g.name.empty() ? "material " + std::to_string(index) : g.name;
  const auto& pbr = g.pbrMetallicRoughness;
  if (pbr.baseColorFactor.size() == 4)
    m.base_color = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                             pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
  m.metallic = static_cast<float>(pbr.metallicFactor);
  m.roughness = static_cast<float>(pbr.roughnessFactor);
  if (g.emissiveFactor.size() == 3)
    m.emissive = glm::vec3(g.emissiveFactor[0], g.emissiveFactor[1], g.emissiveFactor[2]);
  m.double_sided = g.doubleSided;
  m.normal_scale = static_cast<float>(g.normalTexture.scale);
  if (const auto* e = extension(g.extensions, "KHR_materials_emissive_strength"))
    m.emissive *= number(*e, "emissiveStrength", 1.0f);
  if (const auto* e = extension(g.extensions, "KHR_materials_ior")) m.ior = number(*e, "ior", 1.5f);
  if (const auto* e = extension(g.extensions, "KHR_materials_transmission")) {
    m.transmission = number(*e, "transmissionFactor", 0.0f);
    if (e->Has("transmissionTexture")) {
      const auto& ti = e->Get("transmissionTexture");
      const int tex = integer(path_, ti, "index", -1, what + " transmissionTexture");
      const int set = integer(path_, ti, "texCoord", 0, what + " transmissionTexture");
      tinygltf::ExtensionMap ext;
      if (ti.Has("extensions") && ti.Get("extensions").IsObject()) {
        const auto& ev = ti.Get("extensions");
        for (const auto& k : ev.Keys()) ext[k] = ev.Get(k);
      }
      bind(tex, set, ext, false, what + " transmissionTexture", m.transmission_texture);
    }
  }
  const float all = m.base_color.x + m.base_color.y + m.base_color.z + m.base_color.w +
                    m.metallic + m.roughness + m.emissive.x + m.emissive.y + m.emissive.z +
                    m.normal_scale + m.ior + m.transmission;
  if (!finite(all)) throw InputError(path_, what + " has a NaN or infinite factor");
  // Out-of-range factors are clamped (the schema bounds them; renderers must not explode).
  m.base_color = glm::clamp(m.base_color, glm::vec4(0.0f), glm::vec4(1.0f));
  m.metallic = std::clamp(m.metallic, 0.0f, 1.0f);
  m.roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  m.transmission = std::clamp(m.transmission, 0.0f, 1.0f);
  m.emissive = glm::max(m.emissive, glm::vec3(0.0f));
  if (m.ior < 1.0f) m.ior = 1.5f;  // ior 0 (or nonsense): the glTF default

  if (pbr.baseColorTexture.index >= 0)
    bind(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
         true, what + " baseColorTexture", m.base_color_texture);
  if (pbr.metallicRoughnessTexture.index >= 0)
    bind(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
         pbr.metallicRoughnessTexture.extensions, false, what + " metallicRoughnessTexture",
         m.metallic_roughness_texture);
  if (g.normalTexture.index >= 0)
    bind(g.normalTexture.index, g.normalTexture.texCoord, g.normalTexture.extensions, false,
         what + " normalTexture", m.normal_texture);
  if (g.emissiveTexture.index >= 0)
    bind(g.emissiveTexture.index, g.emissiveTexture.texCoord, g.emissiveTexture.extensions, true,
         what + " emissiveTexture", m.emissive_texture);
  return m;
}

void MaterialTable::bind(int texture, int texcoord, const tinygltf::ExtensionMap& ext, bool srgb,
                         const std::string& what, TextureRef& ref) {
  if (texture < 0) return;
  ref.texture = scene_texture(texture, srgb, what);
  ref.texcoord = texcoord;
  if (const auto* t = extension(ext, "KHR_texture_transform")) {
    ref.uv_transform = texture_transform(*t);
    ref.texcoord = integer(path_, *t, "texCoord", ref.texcoord, what + " KHR_texture_transform");
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        if (!finite(ref.uv_transform[c][r]))
          throw InputError(path_, what + " has a non-finite KHR_texture_transform");
  }
  if (ref.texcoord < 0 || ref.texcoord > 1) {
    // Only TEXCOORD_0/1 are kept; fall back to set 0 rather than reject the asset.
    ref.texcoord = 0;
  }
}

int MaterialTable::scene_texture(int texture, bool srgb, const std::string& what) {
  if (static_cast<std::size_t>(texture) >= model_.textures.size())
    throw InputError(path_, what + " names texture " + std::to_string(texture) +
                                " which does not exist");
  auto key = std::make_pair(texture, srgb);
  if (auto it = texture_map_.find(key); it != texture_map_.end()) return it->second;
  const tinygltf::Texture& t = model_.textures[static_cast<std::size_t>(texture)];
  if (t.sampler >= 0 && static_cast<std::size_t>(t.sampler) >= model_.samplers.size())
    throw InputError(path_, what + ": texture " + std::to_string(texture) + " names sampler " +
                                std::to_string(t.sampler) + " which does not exist");
  if (t.source < 0 || static_cast<std::size_t>(t.source) >= model_.images.size())
    throw InputError(path_, what + ": texture " + std::to_string(texture) +
                                " has no valid image source");
  const tinygltf::Image& img = model_.images[static_cast<std::size_t>(t.source)];
  const std::string name = !img.uri.empty() && img.uri.rfind("data:", 0) != 0
                               ? "'" + img.uri + "'"
                               : "image " + std::to_string(t.source);
  // A texture that cannot be had is left out (the material's factors alone, as if the
  // texture were white) with one warning per image, or an error under --strict.
  auto unusable = [&](const std::string& problem) {
    report_.substitute(path_, "texture image " + name + " " + problem + ": drawn without it");
    texture_map_[key] = -1;
    return -1;
  };
  if (img.image.empty() || img.width <= 0 || img.height <= 0)
    return unusable("is missing or could not be decoded");
  const int nc = img.component;
  const int bytes = img.bits == 16 ? 2 : img.bits == 8 ? 1 : 0;
  if (nc < 1 || nc > 4 || bytes == 0) return unusable("has an unsupported pixel format");
  const std::int64_t pixels = std::int64_t{img.width} * img.height;
  if (pixels > kMaxTexturePixels ||
      img.image.size() != static_cast<std::size_t>(pixels) * static_cast<std::size_t>(nc * bytes))
    return unusable("has an inconsistent size");

  ImageRGBA out(img.width, img.height, glm::vec4(0, 0, 0, 1));
  const float scale = bytes == 2 ? 1.0f / 65535.0f : 1.0f / 255.0f;
  for (std::size_t i = 0; i < out.pixels.size(); ++i) {
    float c[4] = {0, 0, 0, 1};
    for (int k = 0; k < nc; ++k) {
      const std::size_t at = (i * static_cast<std::size_t>(nc) + static_cast<std::size_t>(k)) * static_cast<std::size_t>(bytes);
      std::uint32_t v = img.image[at];
      if (bytes == 2) {
        std::uint16_t s;
        std::memcpy(&s, &img.image[at], 2);
        v = s;
      }
      c[k] = static_cast<float>(v) * scale;
    }
    glm::vec4 px = nc == 1 ? glm::vec4(c[0], c[0], c[0], 1)
                 : nc == 2 ? glm::vec4(c[0], c[0], c[0], c[1])
                           : glm::vec4(c[0], c[1], c[2], c[3]);
    if (srgb) px = glm::vec4(srgb_to_linear(px.x), srgb_to_linear(px.y), srgb_to_linear(px.z), px.w);
    out.pixels[i] = px;
  }
  const int index = static_cast<int>(scene_.textures.size());
  scene_.textures.push_back(std::move(out));
  scene_.texture_sources.push_back(path_ + ": " + name + (srgb ? " (sRGB)" : " (linear)"));
  texture_map_[key] = index;
  return index;
}

}  // namespace speculum::gltf
