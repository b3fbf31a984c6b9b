// glTF export (see gltf_writer.h).
#include "core/gltf_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>
#include <unordered_map>

#include <tiny_gltf.h>
#include <stb/stb_image_write.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/error.h"
#include "core/output_file.h"
#include "core/gltf_environment.h"

namespace speculum {
namespace {

using tinygltf::Value;

struct Writer {
  const Scene& scene;
  tinygltf::Model model;
  // Every extension written anywhere, recorded as it is written (put_extension), so
  // extensionsUsed lists exactly those (glTF 2.0 spec §3.12: every extension used anywhere
  // in the asset is listed in the top-level extensionsUsed).
  std::set<std::string> extensions_used;
  std::vector<unsigned char>& bin() { return model.buffers[0].data; }

  int add_view(const void* data, std::size_t bytes, int target) {
    auto& b = bin();
    while (b.size() % 4) b.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = b.size();
    v.byteLength = bytes;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    b.insert(b.end(), p, p + bytes);
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size() - 1);
  }

  template <class T>
  int add_accessor(const std::vector<T>& items, int type, int component_type, int target) {
    tinygltf::Accessor a;
    a.bufferView = add_view(items.data(), items.size() * sizeof(T), target);
    a.componentType = component_type;
    a.type = type;
    a.count = items.size();
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }

  void add_image(const ImageRGBA& img, bool srgb) {
    std::vector<unsigned char> px(img.pixels.size() * 4);
    auto q = [](float v) {
      return static_cast<unsigned char>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
    };
    for (std::size_t i = 0; i < img.pixels.size(); ++i) {
      const glm::vec4 c = img.pixels[i];
      px[4 * i + 0] = q(srgb ? linear_to_srgb(c.x) : c.x);
      px[4 * i + 1] = q(srgb ? linear_to_srgb(c.y) : c.y);
      px[4 * i + 2] = q(srgb ? linear_to_srgb(c.z) : c.z);
      px[4 * i + 3] = q(c.w);
    }
    std::vector<unsigned char> png;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
          auto* out = static_cast<std::vector<unsigned char>*>(ctx);
          const auto* p = static_cast<const unsigned char*>(data);
          out->insert(out->end(), p, p + size);
        },
        &png, img.width, img.height, 4, px.data(), img.width * 4);
    tinygltf::Image image;
    image.mimeType = "image/png";
    image.bufferView = add_view(png.data(), png.size(), 0);
    model.images.push_back(image);
    tinygltf::Texture tex;
    tex.source = static_cast<int>(model.images.size() - 1);
    tex.sampler = 0;
    model.textures.push_back(tex);
  }

  void put_extension(tinygltf::ExtensionMap& map, const char* name, Value::Object body) {
    map[name] = Value(std::move(body));
    extensions_used.insert(name);
  }

  void set_transform_ext(const TextureRef& ref, tinygltf::ExtensionMap& ext) {
    const glm::mat3& m = ref.uv_transform;
    if (m == glm::mat3(1.0f)) return;
    // uv_transform = T R S (gltf_material.h): column 0 = sx (cos, -sin), column 1 = sy (sin, cos).
    Value::Object t;
    t["offset"] = Value(Value::Array{Value(double(m[2][0])), Value(double(m[2][1]))});
    t["rotation"] = Value(double(std::atan2(-m[0][1], m[0][0])));
    t["scale"] = Value(Value::Array{Value(double(glm::length(glm::vec2(m[0])))),
                                    Value(double(glm::length(glm::vec2(m[1]))))});
    put_extension(ext, "KHR_texture_transform", std::move(t));
  }

  template <class Info>
  void bind(const TextureRef& ref, Info& info) {
    if (!ref.valid()) return;
    info.index = ref.texture;
    info.texCoord = ref.texcoord;
    set_transform_ext(ref, info.extensions);
  }

  void add_material(const Material& m) {
    tinygltf::Material g;
    g.name = m.name;
    auto& pbr = g.pbrMetallicRoughness;
    pbr.baseColorFactor = {m.base_color.x, m.base_color.y, m.base_color.z, m.base_color.w};
    pbr.metallicFactor = m.metallic;
    pbr.roughnessFactor = m.roughness;
    bind(m.base_color_texture, pbr.baseColorTexture);
    bind(m.metallic_roughness_texture, pbr.metallicRoughnessTexture);
    bind(m.normal_texture, g.normalTexture);
    if (m.normal_texture.valid()) g.normalTexture.scale = m.normal_scale;
    bind(m.emissive_texture, g.emissiveTexture);
    g.doubleSided = m.double_sided;
    const float peak = std::max({m.emissive.x, m.emissive.y, m.emissive.z});
    if (peak > 1.0f) {
      // emissiveFactor is limited to [0,1]: carry the rest as KHR_materials_emissive_strength.
      g.emissiveFactor = {m.emissive.x / peak, m.emissive.y / peak, m.emissive.z / peak};
      Value::Object e;
      e["emissiveStrength"] = Value(double(peak));
      put_extension(g.extensions, "KHR_materials_emissive_strength", std::move(e));
    } else {
      g.emissiveFactor = {m.emissive.x, m.emissive.y, m.emissive.z};
    }
    if (m.transmission > 0.0f || m.transmission_texture.valid()) {
      Value::Object t;
      t["transmissionFactor"] = Value(double(m.transmission));
      if (m.transmission_texture.valid()) {
        Value::Object ti;
        ti["index"] = Value(m.transmission_texture.texture);
        ti["texCoord"] = Value(m.transmission_texture.texcoord);
        // A textureInfo inside an extension is plain JSON to tinygltf: its own extensions
        // object is built by hand.
        tinygltf::ExtensionMap ti_ext;
        set_transform_ext(m.transmission_texture, ti_ext);
        if (!ti_ext.empty()) ti["extensions"] = Value(Value::Object(ti_ext.begin(), ti_ext.end()));
        t["transmissionTexture"] = Value(ti);
      }
      put_extension(g.extensions, "KHR_materials_transmission", std::move(t));
    }
    if (m.ior != 1.5f) {
      Value::Object t;
      t["ior"] = Value(double(m.ior));
      put_extension(g.extensions, "KHR_materials_ior", std::move(t));
    }
    model.materials.push_back(g);
  }

  void add_object(const Object& obj) {
    const auto& mesh = scene.mesh;
    // Each object gets its own vertex set: the global vertices it uses, in their original
    // order (so a scene whose objects own contiguous vertex ranges round-trips bit-exactly).
    const std::size_t first = obj.first_triangle, count = obj.triangle_count;
    std::vector<std::uint32_t> order(mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * first),
                                     mesh.indices.begin() + static_cast<std::ptrdiff_t>(3 * (first + count)));
    std::sort(order.begin(), order.end());
    order.erase(std::unique(order.begin(), order.end()), order.end());
    std::unordered_map<std::uint32_t, std::uint32_t> local;
    for (std::size_t i = 0; i < order.size(); ++i) local.emplace(order[i], static_cast<std::uint32_t>(i));
    std::vector<std::uint32_t> indices;
    indices.reserve(3 * count);
    for (std::size_t i = 3 * first; i < 3 * (first + count); ++i) indices.push_back(local.at(mesh.indices[i]));
    std::vector<glm::vec3> pos, nrm;
    std::vector<glm::vec2> uv0, uv1;
    std::vector<glm::vec4> tan;
    for (std::uint32_t g : order) {
      pos.push_back(mesh.positions[g]);
      nrm.push_back(mesh.normals[g]);
      uv0.push_back(mesh.uvs[g]);
      if (!mesh.uvs1.empty()) uv1.push_back(mesh.uvs1[g]);
      if (!mesh.tangents.empty()) tan.push_back(mesh.tangents[g]);
    }
    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.material = static_cast<int>(obj.material);
    const int pa = add_accessor(pos, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    Bounds b;
    for (const auto& p : pos) b.grow(p);
    model.accessors[static_cast<std::size_t>(pa)].minValues = {b.lo.x, b.lo.y, b.lo.z};
    model.accessors[static_cast<std::size_t>(pa)].maxValues = {b.hi.x, b.hi.y, b.hi.z};
    prim.attributes["POSITION"] = pa;
    prim.attributes["NORMAL"] = add_accessor(nrm, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    prim.attributes["TEXCOORD_0"] = add_accessor(uv0, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!uv1.empty())
      prim.attributes["TEXCOORD_1"] = add_accessor(uv1, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    if (!tan.empty())
      prim.attributes["TANGENT"] = add_accessor(tan, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
    prim.indices = add_accessor(indices, TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Mesh m;
    m.name = obj.name;
    m.primitives.push_back(prim);
    model.meshes.push_back(m);
    tinygltf::Node node;
    node.name = obj.name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    add_root(node);
  }

  void add_root(const tinygltf::Node& node) {
    model.nodes.push_back(node);
    model.scenes[0].nodes.push_back(static_cast<int>(model.nodes.size() - 1));
  }

  // A node at `eye` whose -Z axis points along `forward` and +Y toward `up`.
  static void place(tinygltf::Node& node, glm::vec3 eye, glm::vec3 forward, glm::vec3 up) {
    const glm::vec3 z = -glm::normalize(forward);
    if (glm::length(glm::cross(up, z)) < 1e-6f) up = std::fabs(z.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    const glm::vec3 x = glm::normalize(glm::cross(up, z));
    const glm::vec3 y = glm::cross(z, x);
    const glm::quat q = glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
    node.translation = {eye.x, eye.y, eye.z};
    node.rotation = {q.x, q.y, q.z, q.w};
  }

  void add_camera(const Camera& c) {
    tinygltf::Camera g;
    g.name = c.name;
    g.type = "perspective";
    g.perspective.yfov = glm::radians(static_cast<double>(c.vfov_degrees));
    g.perspective.znear = c.znear;
    g.perspective.zfar = c.zfar;
    if (c.aspect > 0.0f) g.perspective.aspectRatio = c.aspect;
    model.cameras.push_back(g);
    tinygltf::Node node;
    node.name = c.name;
    node.camera = static_cast<int>(model.cameras.size() - 1);
    place(node, c.eye, c.target - c.eye, c.up);
    add_root(node);
  }

  void add_light(const Light& l) {
    tinygltf::Light g;
    g.name = l.name;
    g.type = l.type == LightType::Point ? "point" : l.type == LightType::Spot ? "spot" : "directional";
    g.color = {l.color.x, l.color.y, l.color.z};
    g.intensity = l.intensity;
    g.range = l.range;
    if (l.type == LightType::Spot) {
      g.spot.innerConeAngle = l.inner_cone;
      g.spot.outerConeAngle = l.outer_cone;
    }
    model.lights.push_back(g);
    tinygltf::Node node;
    node.name = l.name;
    Value::Object ext;
    ext["light"] = Value(static_cast<int>(model.lights.size() - 1));
    put_extension(node.extensions, "KHR_lights_punctual", std::move(ext));
    place(node, l.position, l.direction, glm::vec3(0, 1, 0));
    add_root(node);
  }

  // The environment as root extras (schema in gltf_environment.h); an equirect image goes
  // into the binary buffer as raw little-endian float32 RGBA, so it survives bit-exactly.
  void add_environment(const Environment& env) {
    auto num = [](float v) { return Value(static_cast<double>(v)); };
    Value::Object e;
    e["color"] = Value(Value::Array{num(env.constant.x), num(env.constant.y), num(env.constant.z)});
    e["intensity"] = num(env.intensity);
    if (env.has_image()) {
      const ImageRGBA& img = env.equirect;
      std::vector<unsigned char> bytes(img.pixels.size() * gltf::kEquirectBytesPerPixel);
      for (std::size_t i = 0; i < img.pixels.size(); ++i)
        for (int c = 0; c < 4; ++c) {
          std::uint32_t bits = 0;
          std::memcpy(&bits, &img.pixels[i][c], 4);
          for (int k = 0; k < 4; ++k)
            bytes[16 * i + 4 * static_cast<std::size_t>(c) + static_cast<std::size_t>(k)] =
                static_cast<unsigned char>(bits >> (8 * k));
        }
      Value::Object q;
      q["bufferView"] = Value(add_view(bytes.data(), bytes.size(), 0));
      q["width"] = Value(img.width);
      q["height"] = Value(img.height);
      q["format"] = Value(std::string(gltf::kEquirectFormat));
      e["equirect"] = Value(q);
    }
    Value::Object root;
    root[gltf::kEnvironmentExtrasKey] = Value(e);
    model.extras = Value(root);
  }
};

std::vector<bool> srgb_textures(const Scene& scene) {
  std::vector<bool> srgb(scene.textures.size(), false);
  for (const auto& m : scene.materials)
    for (const TextureRef* t : {&m.base_color_texture, &m.emissive_texture})
      if (t->valid() && static_cast<std::size_t>(t->texture) < srgb.size())
        srgb[static_cast<std::size_t>(t->texture)] = true;
  return srgb;
}

}  // namespace

void write_gltf(const Scene& scene, const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext != ".glb" && ext != ".gltf")
    throw InputError(path, "export needs a .glb or .gltf file name");
  Writer w{scene, {}, {}};
  auto& model = w.model;
  model.asset.version = "2.0";
  model.asset.generator = "speculum";
  model.buffers.emplace_back();
  model.scenes.emplace_back();
  model.defaultScene = 0;
  tinygltf::Sampler sampler;  // repeat wrapping, linear filtering
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  model.samplers.push_back(sampler);
  const auto srgb = srgb_textures(scene);
  for (std::size_t i = 0; i < scene.textures.size(); ++i) w.add_image(scene.textures[i], srgb[i]);
  for (const auto& m : scene.materials) w.add_material(m);
  for (const auto& o : scene.objects) w.add_object(o);
  for (const auto& c : scene.cameras) w.add_camera(c);
  for (const auto& l : scene.lights) w.add_light(l);

  w.add_environment(scene.environment);
  model.extensionsUsed.assign(w.extensions_used.begin(), w.extensions_used.end());
  if (model.textures.empty()) model.samplers.clear();

  // Whole or nothing, and the system's reason if the file cannot be created
  // (core/output_file.h); buffers and images are embedded, so the temporary name is not
  // referenced from inside the file.
  OutputFile file(path);
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(&model, file.temp_path(), true, true, ext == ".gltf", ext == ".glb"))
    throw InputError(path, "cannot write: the glTF writer failed");
  file.commit();
}

}  // namespace speculum
