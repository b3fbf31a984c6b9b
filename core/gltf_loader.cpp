// glTF 2.0 → Scene (see gltf_loader.h). The container is checked before tinygltf sees it,
// every reference and accessor is checked before it is followed (glTF 2.0 §3, §5).
#include "core/gltf_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <utility>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/gltf_accessors.h"
#include "core/gltf_environment.h"
#include "core/gltf_material.h"
#include "core/mesh_normals.h"
#include "core/png_check.h"

namespace speculum {
namespace {

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{2} << 30;  // tinygltf takes 32-bit sizes

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  if (s.size() > 300) s = s.substr(0, 300) + "...";
  return s;
}

std::vector<unsigned char> read_file_bytes(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "cannot read file size: " + ec.message());
  if (size == 0) throw InputError(path, "file is empty");
  if (size >= kMaxFileBytes) throw InputError(path, "file is too large (over 2 GiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
  if (!in) throw InputError(path, "could not read the whole file");
  return bytes;
}

std::uint32_t le32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 |
         std::uint32_t(p[3]) << 24;
}

// The GLB header and chunk table (glTF 2.0 §4.4), checked so a truncated or lying
// container is rejected here rather than read out of bounds.
void check_glb_container(const std::string& path, const std::vector<unsigned char>& b) {
  if (b.size() < 20) throw InputError(path, "truncated .glb: shorter than its 20-byte header");
  if (le32(&b[0]) != 0x46546C67u) throw InputError(path, "not a .glb file (bad magic)");
  if (le32(&b[4]) == 1) throw InputError(path, "glTF 1.0 is not supported, 2.0 is");
  if (le32(&b[4]) != 2) throw InputError(path, "unsupported .glb version " + std::to_string(le32(&b[4])));
  const std::uint64_t total = le32(&b[8]);
  if (total > b.size())
    throw InputError(path, "truncated .glb: header says " + std::to_string(total) +
                               " bytes, file has " + std::to_string(b.size()));
  if (total < b.size())
    throw InputError(path, ".glb header says " + std::to_string(total) + " bytes, file has " +
                               std::to_string(b.size()) + " (trailing data)");
  const std::uint64_t json_len = le32(&b[12]);
  if (le32(&b[16]) != 0x4E4F534Au) throw InputError(path, "first .glb chunk is not JSON");
  if (20 + json_len > total) throw InputError(path, "truncated .glb: JSON chunk runs past the end");
  // Every chunk starts and ends on a 4-byte boundary (the JSON padded with spaces, the BIN
  // chunk with zeros); a BIN chunk may follow the JSON chunk only directly, once; chunks of
  // other types are skipped (glTF 2.0 §4.4.3).
  if (json_len == 0 || json_len % 4 != 0)
    throw InputError(path, ".glb JSON chunk length " + std::to_string(json_len) + " is not a positive multiple of 4");
  std::uint64_t at = 20 + json_len;
  for (int chunk = 1; at < total; ++chunk) {
    if (at + 8 > total) throw InputError(path, "truncated .glb: chunk " + std::to_string(chunk) + " header runs past the end");
    const std::uint64_t len = le32(&b[at]);
    const std::uint32_t type = le32(&b[at + 4]);
    if (at + 8 + len > total)
      throw InputError(path, "truncated .glb: chunk " + std::to_string(chunk) + " runs past the end");
    if (len % 4 != 0) throw InputError(path, ".glb chunk " + std::to_string(chunk) + " length is not a multiple of 4");
    if (type == 0x4E4F534Au) throw InputError(path, ".glb has a second JSON chunk");
    if (type == 0x004E4942u && chunk != 1)
      throw InputError(path, ".glb BIN chunk must directly follow the JSON chunk, once");
    at += 8 + len;
  }
}

// Data URIs of buffers and images hold base64 (RFC 4648 §4): tinygltf's decoder stops at
// the first character outside the alphabet and keeps what it decoded, so a corrupted
// payload could load as a shorter, or padded-out, garbage buffer.
void check_data_uri(const std::string& path, const std::string& uri, const std::string& where) {
  const std::size_t comma = uri.find(',');
  if (comma == std::string::npos || uri.compare(0, 5, "data:") != 0) return;
  if (uri.rfind(";base64", comma) == std::string::npos || uri.rfind(";base64", comma) + 7 != comma)
    throw InputError(path, where + " data URI is not base64");
  std::size_t n = uri.size() - comma - 1, pad = 0;
  for (std::size_t i = comma + 1; i < uri.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(uri[i]);
    if (c == '=') {
      ++pad;
      continue;
    }
    if (pad > 0 || !(std::isalnum(c) || c == '+' || c == '/'))
      throw InputError(path, where + " data URI has invalid base64 at character " + std::to_string(i - comma - 1));
  }
  if (pad > 2 || n % 4 == 1 || (pad > 0 && n % 4 != 0))
    throw InputError(path, where + " data URI has a base64 payload of invalid length " + std::to_string(n));
}

struct Loader {
  const std::string& path;
  const tinygltf::Model& model;
  Scene& scene;
  LoadReport* report;
  gltf::MaterialTable materials;
  std::vector<std::pair<int, glm::mat4>> camera_nodes;  // (camera index, world)
  std::vector<std::pair<int, glm::mat4>> light_nodes;   // (light index, world)
  std::size_t skipped_ortho = 0;

  void warn(const std::string& message) {
    if (report) report->warn(message);
  }

  glm::mat4 local_transform(const tinygltf::Node& node, std::size_t index) const {
    auto finite_all = [](const std::vector<double>& v) {
      return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
    };
    const std::string what = "node " + std::to_string(index);
    if (!finite_all(node.matrix) || !finite_all(node.translation) ||
        !finite_all(node.rotation) || !finite_all(node.scale))
      throw InputError(path, what + " has a NaN or infinite transform");
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16) throw InputError(path, what + " matrix must have 16 numbers");
      glm::mat4 m;
      for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[i]);
      return m;  // glTF stores column-major, as glm does
    }
    glm::mat4 m(1.0f);
    if (!node.translation.empty()) {
      if (node.translation.size() != 3) throw InputError(path, what + " translation needs 3 numbers");
      m[3] = glm::vec4(node.translation[0], node.translation[1], node.translation[2], 1.0);
    }
    if (!node.rotation.empty()) {
      if (node.rotation.size() != 4) throw InputError(path, what + " rotation needs 4 numbers");
      glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                  static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
      const float len = glm::length(q);
      if (!(len > 1e-12f)) throw InputError(path, what + " has a zero rotation quaternion");
      m = m * glm::mat4_cast(q / len);
    }
    if (!node.scale.empty()) {
      if (node.scale.size() != 3) throw InputError(path, what + " scale needs 3 numbers");
      m = m * glm::mat4(glm::vec4(node.scale[0], 0, 0, 0), glm::vec4(0, node.scale[1], 0, 0),
                        glm::vec4(0, 0, node.scale[2], 0), glm::vec4(0, 0, 0, 1));
    }
    return m;
  }

  static int attribute(const tinygltf::Primitive& prim, const char* name) {
    auto it = prim.attributes.find(name);
    return it == prim.attributes.end() ? -1 : it->second;
  }

  // The primitive's triangle topology (list, strip or fan); -1 (with a warning) for points
  // and lines, which are skipped.
  int triangle_mode(const tinygltf::Primitive& prim, const std::string& what) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode == TINYGLTF_MODE_TRIANGLES || mode == TINYGLTF_MODE_TRIANGLE_STRIP ||
        mode == TINYGLTF_MODE_TRIANGLE_FAN)
      return mode;
    if (mode < 0 || mode > 6) throw InputError(path, what + " has invalid mode " + std::to_string(mode));
    if (report) ++report->skipped_primitives;
    warn(what + ": points/lines primitive skipped");
    return -1;
  }

  // POSITION as local-space vertices, every coordinate finite.
  std::vector<glm::vec3> read_positions(const tinygltf::Primitive& prim, const std::string& what) const {
    const int pos_acc = attribute(prim, "POSITION");
    if (pos_acc < 0) throw InputError(path, what + " has no POSITION attribute");
    const auto pos_view = gltf::checked_accessor(model, pos_acc, path, what + " POSITION",
                                                 {TINYGLTF_TYPE_VEC3},
                                                 {TINYGLTF_COMPONENT_TYPE_FLOAT});
    const std::size_t nv = pos_view.count;
    const std::vector<float> pos = gltf::read_floats(pos_view);
    for (std::size_t i = 0; i < pos.size(); ++i)
      if (!std::isfinite(pos[i]))
        throw InputError(path, what + ": non-finite vertex " + std::to_string(i / 3) +
                                   " (NaN or infinite position)");
    std::vector<glm::vec3> p(nv);
    for (std::size_t i = 0; i < nv; ++i) p[i] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
    return p;
  }

  // The index list (0..nv-1 when the primitive has none), every index below nv.
  std::vector<std::uint32_t> read_indices(const tinygltf::Primitive& prim, std::size_t nv,
                                          const std::string& what) const {
    std::vector<std::uint32_t> idx;
    if (prim.indices >= 0) {
      const auto iv = gltf::checked_accessor(
          model, prim.indices, path, what + " indices", {TINYGLTF_TYPE_SCALAR},
          {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
           TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
      // glTF 2.0 §3.7.2.1: index data is tightly packed (its bufferView defines no
      // byteStride), not normalized, and never holds the component type's largest value
      // (the primitive restart value of graphics APIs).
      const tinygltf::Accessor& acc = model.accessors[static_cast<std::size_t>(prim.indices)];
      if (acc.normalized) throw InputError(path, what + " indices accessor " + std::to_string(prim.indices) + " is normalized");
      if (acc.bufferView >= 0 && model.bufferViews[static_cast<std::size_t>(acc.bufferView)].byteStride != 0)
        throw InputError(path, what + " indices accessor " + std::to_string(prim.indices) +
                                   " uses a bufferView with byteStride (index data must be tightly packed)");
      idx = gltf::read_indices(iv);
      const std::uint32_t restart = iv.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 0xffu
                                    : iv.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 0xffffu
                                                                                                  : 0xffffffffu;
      for (std::size_t i = 0; i < idx.size(); ++i)
        if (idx[i] == restart)
          throw InputError(path, what + " index " + std::to_string(i) + " = " + std::to_string(restart) +
                                     " is the primitive restart value, which glTF forbids");
      for (std::size_t i = 0; i < idx.size(); ++i)
        if (idx[i] >= nv)
          throw InputError(path, what + " index " + std::to_string(i) + " = " +
                                     std::to_string(idx[i]) + " is out of range (" +
                                     std::to_string(nv) + " vertices)");
    } else {
      idx.resize(nv);
      for (std::size_t i = 0; i < nv; ++i) idx[i] = static_cast<std::uint32_t>(i);
    }
    return idx;
  }

  // Strips and fans unrolled into a triangle list (glTF §3.7.2.1).
  std::vector<std::uint32_t> triangle_list(const std::vector<std::uint32_t>& idx, int mode,
                                           const std::string& what) {
    std::vector<std::uint32_t> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (idx.size() % 3 != 0)
        warn(what + ": index count not a multiple of 3, trailing indices ignored");
      tris.assign(idx.begin(), idx.begin() + static_cast<std::ptrdiff_t>(idx.size() / 3 * 3));
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 2; i < idx.size(); ++i) {
        // Odd triangles swap two vertices to keep the winding consistent.
        if (i % 2 == 0) tris.insert(tris.end(), {idx[i - 2], idx[i - 1], idx[i]});
        else tris.insert(tris.end(), {idx[i - 1], idx[i - 2], idx[i]});
      }
    } else {
      for (std::size_t i = 2; i < idx.size(); ++i) tris.insert(tris.end(), {idx[0], idx[i - 1], idx[i]});
    }
    return tris;
  }

  // NORMAL when every normal is usable, otherwise area-weighted normals of the triangles.
  std::vector<glm::vec3> read_normals(const tinygltf::Primitive& prim, const std::vector<glm::vec3>& p,
                                      const std::vector<std::uint32_t>& tris, const std::string& what) {
    const std::size_t nv = p.size();
    std::vector<glm::vec3> n;
    if (int a = attribute(prim, "NORMAL"); a >= 0) {
      const auto v = gltf::checked_accessor(model, a, path, what + " NORMAL", {TINYGLTF_TYPE_VEC3},
                                            {TINYGLTF_COMPONENT_TYPE_FLOAT});
      if (v.count != nv) throw InputError(path, what + " NORMAL count differs from POSITION count");
      const auto f = gltf::read_floats(v);
      n.resize(nv);
      std::size_t bad = 0;
      for (std::size_t i = 0; i < nv; ++i) {
        n[i] = {f[3 * i], f[3 * i + 1], f[3 * i + 2]};
        const float len = glm::length(n[i]);
        if (!std::isfinite(len) || len < 1e-6f) ++bad;
      }
      if (bad) {
        warn(what + ": " + std::to_string(bad) + " zero or non-finite normals, recomputed");
        n.clear();
      }
    }
    if (n.empty()) n = area_weighted_normals(p, tris);
    return n;
  }

  // Texture coordinate set `name` (empty when absent), every value finite.
  std::vector<glm::vec2> read_uv(const tinygltf::Primitive& prim, const char* name, std::size_t nv,
                                 const std::string& what) const {
    std::vector<glm::vec2> uv;
    const int a = attribute(prim, name);
    if (a < 0) return uv;
    const auto v = gltf::checked_accessor(
        model, a, path, what + " " + name, {TINYGLTF_TYPE_VEC2},
        {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
         TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (v.count != nv) throw InputError(path, what + " " + name + " count differs from POSITION count");
    // glTF 2.0 §3.7.2.1: integer texture coordinates are "unsigned byte normalized" or
    // "unsigned short normalized"; un-normalized they would be texel counts, not [0, 1].
    if (v.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT && !v.normalized)
      throw InputError(path, what + " " + name + ": accessor " + std::to_string(a) +
                                 " has integer components but is not normalized");
    const auto f = gltf::read_floats(v);
    uv.resize(nv);
    for (std::size_t i = 0; i < nv; ++i) {
      uv[i] = {f[2 * i], f[2 * i + 1]};
      if (!std::isfinite(uv[i].x) || !std::isfinite(uv[i].y))
        throw InputError(path, what + " " + name + " has a NaN or infinite value");
    }
    return uv;
  }

  // The local-space attributes of one primitive, one entry per vertex (uv0, uv1, t may be
  // empty), and its triangle list.
  struct PrimitiveGeometry {
    std::vector<glm::vec3> p, n;
    std::vector<glm::vec2> uv0, uv1;
    std::vector<glm::vec4> t;  // xyz tangent, w bitangent sign
    std::vector<std::uint32_t> tris;
  };

  // TANGENT when given, otherwise derived from the UV set the material's normal map reads
  // (none when the material has no normal map or that set is missing).
  std::vector<glm::vec4> read_tangents(const tinygltf::Primitive& prim, std::uint32_t material,
                                       const PrimitiveGeometry& g, const std::string& what) const {
    const std::size_t nv = g.p.size();
    std::vector<glm::vec4> t;
    if (int a = attribute(prim, "TANGENT"); a >= 0) {
      const auto v = gltf::checked_accessor(model, a, path, what + " TANGENT", {TINYGLTF_TYPE_VEC4},
                                            {TINYGLTF_COMPONENT_TYPE_FLOAT});
      if (v.count != nv) throw InputError(path, what + " TANGENT count differs from POSITION count");
      const auto f = gltf::read_floats(v);
      t.resize(nv);
      for (std::size_t i = 0; i < nv; ++i) {
        t[i] = {f[4 * i], f[4 * i + 1], f[4 * i + 2], f[4 * i + 3] < 0.0f ? -1.0f : 1.0f};
        if (!std::isfinite(glm::length(glm::vec3(t[i])))) throw InputError(path, what + " TANGENT has a NaN or infinite value");
      }
    } else if (scene.materials[material].normal_texture.valid()) {
      const int set = scene.materials[material].normal_texture.texcoord;
      const auto& uv = set == 1 && !g.uv1.empty() ? g.uv1 : g.uv0;
      if (!uv.empty()) t = uv_tangents(g.p, g.n, uv, g.tris);
    }
    return t;
  }

  // Appends the primitive's vertices to the scene mesh in world space: positions by M,
  // normals by the inverse transpose, tangents by M. Returns the first new vertex's index;
  // `det` receives det(M) (negative: a mirroring transform).
  std::uint32_t append_world_vertices(const PrimitiveGeometry& g, const glm::mat4& world,
                                      const std::string& what, float& det) {
    const std::size_t nv = g.p.size();
    const glm::mat3 m3(world);
    det = glm::determinant(m3);
    if (!std::isfinite(det) || std::fabs(det) < 1e-30f)
      throw InputError(path, what + " is instanced with a singular transform");
    const glm::mat3 nm = glm::transpose(glm::inverse(m3));
    auto& mesh = scene.mesh;
    const std::uint32_t base = static_cast<std::uint32_t>(mesh.positions.size());
    if (mesh.positions.size() + nv > std::size_t{0xfffffff0u})
      throw InputError(path, "too many vertices for 32-bit indices");
    // Scenes may lack tangents or TEXCOORD_1 for earlier objects: keep streams aligned.
    if (!g.t.empty() && mesh.tangents.size() < base)
      mesh.tangents.resize(base, glm::vec4(1, 0, 0, 1));
    if (!g.uv1.empty() && mesh.uvs1.size() < base) mesh.uvs1.resize(base, glm::vec2(0.0f));
    for (std::size_t i = 0; i < nv; ++i) {
      mesh.positions.push_back(glm::vec3(world * glm::vec4(g.p[i], 1.0f)));
      glm::vec3 wn = nm * g.n[i];
      const float len = glm::length(wn);
      wn = (len > 0.0f && std::isfinite(len)) ? wn / len : glm::vec3(0, 0, 1);
      mesh.normals.push_back(wn);
      mesh.uvs.push_back(g.uv0.empty() ? glm::vec2(0.0f) : g.uv0[i]);
      if (!g.uv1.empty()) mesh.uvs1.push_back(g.uv1[i]);
      if (!g.t.empty()) {
        glm::vec3 wt = m3 * glm::vec3(g.t[i]);
        wt -= wn * glm::dot(wn, wt);
        const float tl = glm::length(wt);
        wt = (tl > 1e-12f && std::isfinite(tl)) ? wt / tl : any_perpendicular(wn);
        // A mirroring transform flips the bitangent's handedness.
        mesh.tangents.push_back(glm::vec4(wt, det < 0.0f ? -g.t[i].w : g.t[i].w));
      }
    }
    if (!mesh.tangents.empty()) mesh.tangents.resize(mesh.positions.size(), glm::vec4(1, 0, 0, 1));
    if (!mesh.uvs1.empty()) mesh.uvs1.resize(mesh.positions.size(), glm::vec2(0.0f));
    return base;
  }

  // Appends the primitive's triangles (vertex indices from `base`) as a new scene object.
  void append_object(const tinygltf::Mesh& gmesh, std::size_t prim_index, const std::string& node_name,
                     const std::string& what, const std::vector<std::uint32_t>& tris,
                     std::uint32_t material, std::uint32_t base, float det) {
    auto& mesh = scene.mesh;
    const std::uint32_t object = static_cast<std::uint32_t>(scene.objects.size());
    Object obj;
    obj.name = node_name.empty() ? (gmesh.name.empty() ? what : gmesh.name) : node_name;
    if (gmesh.primitives.size() > 1) obj.name += "#" + std::to_string(prim_index);
    obj.first_triangle = static_cast<std::uint32_t>(mesh.triangle_count());
    obj.triangle_count = static_cast<std::uint32_t>(tris.size() / 3);
    obj.material = material;
    scene.objects.push_back(obj);
    for (std::size_t i = 0; i < tris.size(); i += 3) {
      // A mirroring transform (det < 0) reverses the winding: swap to keep it CCW.
      if (det < 0.0f) mesh.indices.insert(mesh.indices.end(), {base + tris[i], base + tris[i + 2], base + tris[i + 1]});
      else mesh.indices.insert(mesh.indices.end(), {base + tris[i], base + tris[i + 1], base + tris[i + 2]});
      mesh.triangle_material.push_back(material);
      mesh.triangle_object.push_back(object);
    }
  }

  [[noreturn]] void too_many(const char* what, std::uint64_t limit, int log2) const {
    throw InputError(path, "the scene holds more than the limit of " + std::to_string(limit) + " " + what + " (2^" +
                               std::to_string(log2) + ")");
  }

  // The scene's totals with this primitive, from its accessors' counts before anything is
  // read: each instance of a mesh adds its vertices again, so a small file could otherwise
  // claim any amount (an accessor with no bufferView is count zeros, from no bytes at all).
  void check_counts(const tinygltf::Primitive& prim, int mode) const {
    // A count past gltf::kMaxAccessorCount is left to checked_accessor, which names it.
    auto count = [&](int accessor) -> std::uint64_t {
      if (accessor < 0 || static_cast<std::size_t>(accessor) >= model.accessors.size()) return 0;
      const std::uint64_t n = model.accessors[static_cast<std::size_t>(accessor)].count;
      return n > gltf::kMaxAccessorCount ? 0 : n;
    };
    const std::uint64_t nv = count(attribute(prim, "POSITION"));
    const std::uint64_t corners = prim.indices >= 0 ? count(prim.indices) : nv;
    // A list makes corners/3 triangles; a strip or fan corners-2.
    const std::uint64_t tris = mode == TINYGLTF_MODE_TRIANGLES ? corners / 3 : (corners > 2 ? corners - 2 : 0);
    if (scene.mesh.vertex_count() + nv > kMaxSceneVertices) too_many("vertices", kMaxSceneVertices, 25);
    if (scene.mesh.triangle_count() + tris > kMaxSceneTriangles) too_many("triangles", kMaxSceneTriangles, 24);
  }

  // Converts one primitive instance into a scene object (skipped, with a warning, when it
  // has no triangles).
  void add_primitive(std::size_t mesh_index, std::size_t prim_index, const glm::mat4& world,
                     const std::string& node_name) {
    const tinygltf::Mesh& gmesh = model.meshes[mesh_index];
    const tinygltf::Primitive& prim = gmesh.primitives[prim_index];
    const std::string what = "mesh " + std::to_string(mesh_index) +
                             (gmesh.name.empty() ? "" : " '" + gmesh.name + "'") +
                             " primitive " + std::to_string(prim_index);
    // Every accessor the primitive names exists, also those of attributes not drawn here
    // (COLOR_0, JOINTS_0, ...): a file naming a missing one is broken (glTF 2.0 §3.7.2.1).
    for (const auto& [name, a] : prim.attributes)
      if (a < 0 || static_cast<std::size_t>(a) >= model.accessors.size())
        throw InputError(path, what + " attribute " + name + " names accessor " + std::to_string(a) +
                                   " which does not exist");
    const int mode = triangle_mode(prim, what);
    if (mode < 0) return;
    check_counts(prim, mode);
    PrimitiveGeometry g;
    g.p = read_positions(prim, what);
    const std::size_t nv = g.p.size();
    g.tris = triangle_list(read_indices(prim, nv, what), mode, what);
    if (g.tris.empty()) {
      warn(what + ": no triangles");
      return;
    }
    if (scene.mesh.triangle_count() + g.tris.size() / 3 > kMaxSceneTriangles) too_many("triangles", kMaxSceneTriangles, 24);
    g.n = read_normals(prim, g.p, g.tris, what);
    g.uv0 = read_uv(prim, "TEXCOORD_0", nv, what);
    g.uv1 = read_uv(prim, "TEXCOORD_1", nv, what);
    const std::uint32_t material = materials.scene_material(prim.material);
    g.t = read_tangents(prim, material, g, what);
    float det = 0.0f;
    const std::uint32_t base = append_world_vertices(g, world, what, det);
    append_object(gmesh, prim_index, node_name, what, g.tris, material, base, det);
  }

  // Depth-first flattening with an explicit stack; a node met again on the current
  // path is a cycle, a node met twice overall has two parents — both invalid glTF.
  void flatten(const std::vector<int>& roots) {
    const std::size_t nn = model.nodes.size();
    std::vector<std::uint8_t> state(nn, 0);  // 0 unseen, 1 on path, 2 done
    struct Frame { std::size_t node; glm::mat4 world; std::size_t next_child; };
    for (int root : roots) {
      if (root < 0 || static_cast<std::size_t>(root) >= nn)
        throw InputError(path, "scene names node " + std::to_string(root) + " which does not exist");
      if (state[static_cast<std::size_t>(root)] != 0)
        throw InputError(path, "node " + std::to_string(root) + " is listed as a root twice or also has a parent");
      std::vector<Frame> stack;
      auto enter = [&](std::size_t n, const glm::mat4& parent) {
        state[n] = 1;
        const glm::mat4 world = parent * local_transform(model.nodes[n], n);
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r)
            if (!std::isfinite(world[c][r]))
              throw InputError(path, "node " + std::to_string(n) +
                                         " has a world transform that overflows single precision");
        visit(n, world);
        stack.push_back({n, world, 0});
      };
      enter(static_cast<std::size_t>(root), glm::mat4(1.0f));
      while (!stack.empty()) {
        Frame& f = stack.back();
        const auto& children = model.nodes[f.node].children;
        if (f.next_child == children.size()) {
          state[f.node] = 2;
          stack.pop_back();
          continue;
        }
        const int c = children[f.next_child++];
        if (c < 0 || static_cast<std::size_t>(c) >= nn)
          throw InputError(path, "node " + std::to_string(f.node) + " has child " +
                                     std::to_string(c) + " which does not exist");
        const std::size_t child = static_cast<std::size_t>(c);
        if (state[child] == 1)
          throw InputError(path, "node graph has a cycle: node " + std::to_string(f.node) +
                                     " has ancestor node " + std::to_string(child) + " as a child");
        if (state[child] == 2)
          throw InputError(path, "node " + std::to_string(child) + " has more than one parent");
        const glm::mat4 world = f.world;  // copy: enter() may reallocate the stack
        enter(child, world);
      }
    }
  }

  void visit(std::size_t n, const glm::mat4& world) {
    const tinygltf::Node& node = model.nodes[n];
    if (node.mesh >= 0) {
      if (static_cast<std::size_t>(node.mesh) >= model.meshes.size())
        throw InputError(path, "node " + std::to_string(n) + " names mesh " +
                                   std::to_string(node.mesh) + " which does not exist");
      const auto& gm = model.meshes[static_cast<std::size_t>(node.mesh)];
      for (std::size_t p = 0; p < gm.primitives.size(); ++p)
        add_primitive(static_cast<std::size_t>(node.mesh), p, world, node.name);
    }
    if (node.camera >= 0) {
      if (static_cast<std::size_t>(node.camera) >= model.cameras.size())
        throw InputError(path, "node " + std::to_string(n) + " names camera " +
                                   std::to_string(node.camera) + " which does not exist");
      camera_nodes.emplace_back(node.camera, world);
    }
    if (auto it = node.extensions.find("KHR_lights_punctual"); it != node.extensions.end()) {
      const tinygltf::Value& v = it->second;
      if (!v.IsObject() || !v.Has("light") || !v.Get("light").IsInt())
        throw InputError(path, "node " + std::to_string(n) + " has a malformed KHR_lights_punctual");
      const int light = v.Get("light").Get<int>();
      if (light < 0 || static_cast<std::size_t>(light) >= model.lights.size())
        throw InputError(path, "node " + std::to_string(n) + " names light " +
                                   std::to_string(light) + " which does not exist");
      light_nodes.emplace_back(light, world);
    }
  }

  void add_cameras() {
    for (const auto& [index, world] : camera_nodes) {
      const tinygltf::Camera& gc = model.cameras[static_cast<std::size_t>(index)];
      if (gc.type != "perspective") {
        ++skipped_ortho;
        continue;
      }
      // glTF 2.0 §5.13: yfov > 0 and znear > 0; zfar, when given, > znear (absent: infinite).
      const auto& pp = gc.perspective;
      if (!(pp.yfov > 0.0 && pp.yfov < 3.14159265358979) || !(pp.znear > 0.0) || !std::isfinite(pp.znear) ||
          !(pp.zfar == 0.0 || (pp.zfar > pp.znear && std::isfinite(static_cast<float>(pp.zfar)))) ||
          pp.znear > std::numeric_limits<float>::max() || pp.aspectRatio < 0.0)
        throw InputError(path, "camera " + std::to_string(index) +
                                   " needs 0 < yfov < pi, znear > 0 and zfar > znear (or no zfar)");
      Camera cam;
      cam.name = gc.name.empty() ? "camera " + std::to_string(index) : gc.name;
      cam.eye = glm::vec3(world[3]);
      const glm::vec3 fwd = glm::normalize(glm::mat3(world) * glm::vec3(0, 0, -1));
      cam.target = cam.eye + fwd;
      cam.up = glm::normalize(glm::mat3(world) * glm::vec3(0, 1, 0));
      cam.vfov_degrees = static_cast<float>(glm::degrees(gc.perspective.yfov));
      cam.znear = static_cast<float>(gc.perspective.znear);
      cam.zfar = static_cast<float>(gc.perspective.zfar);
      if (gc.perspective.aspectRatio > 0.0 && std::isfinite(gc.perspective.aspectRatio))
        cam.aspect = static_cast<float>(gc.perspective.aspectRatio);
      if (!(cam.zfar > cam.znear)) {
        // Infinite far plane: reach past everything in the scene.
        const Bounds b = scene.bounds();
        const float reach = b.valid() ? glm::length(b.center() - cam.eye) + glm::length(b.extent()) : 1000.0f;
        cam.zfar = std::max(cam.znear * 2.0f, reach * 1.5f);
      }
      scene.cameras.push_back(cam);
    }
    if (skipped_ortho) warn(std::to_string(skipped_ortho) + " orthographic cameras skipped");
  }

  void add_lights() {
    for (const auto& [index, world] : light_nodes) {
      const tinygltf::Light& gl = model.lights[static_cast<std::size_t>(index)];
      Light l;
      l.name = gl.name.empty() ? "light " + std::to_string(index) : gl.name;
      if (gl.type == "point") l.type = LightType::Point;
      else if (gl.type == "spot") l.type = LightType::Spot;
      else if (gl.type == "directional") l.type = LightType::Directional;
      else throw InputError(path, "light " + std::to_string(index) + " has unknown type '" + gl.type + "'");
      if (gl.color.size() == 3) l.color = glm::vec3(gl.color[0], gl.color[1], gl.color[2]);
      l.intensity = static_cast<float>(gl.intensity);
      l.range = static_cast<float>(gl.range);
      l.inner_cone = static_cast<float>(gl.spot.innerConeAngle);
      l.outer_cone = static_cast<float>(gl.spot.outerConeAngle);
      l.position = glm::vec3(world[3]);
      l.direction = glm::normalize(glm::mat3(world) * glm::vec3(0, 0, -1));
      const float check = l.color.x + l.color.y + l.color.z + l.intensity + l.range +
                          l.position.x + l.position.y + l.position.z + l.direction.x +
                          l.direction.y + l.direction.z + l.inner_cone + l.outer_cone;
      // KHR_lights_punctual: range > 0 when given, 0 <= inner < outer <= pi/2 for spots
      // (inner == outer, a hard-edged spot some exporters write, is let through).
      const bool bad_cone = l.type == LightType::Spot &&
                            !(l.inner_cone >= 0.0f && l.inner_cone <= l.outer_cone && l.outer_cone > 0.0f &&
                              l.outer_cone <= 1.5707964f);
      if (l.range < 0.0f || bad_cone)
        throw InputError(path, "light " + std::to_string(index) +
                                   " has a negative range or spot cone angles outside 0 <= inner <= outer <= pi/2");
      if (!std::isfinite(check) || l.intensity < 0.0f)
        throw InputError(path, "light " + std::to_string(index) + " has non-finite or negative values");
      scene.lights.push_back(l);
    }
  }
};

// JSON nesting deeper than this is rejected before any parser recurses into it (glTF's own
// schema nests a few levels; extras may nest more, but not thousands).
constexpr int kMaxJsonDepth = 256;

// One pass over the text, skipping strings: the deepest [ / { nesting.
void check_json_depth(const std::string& path, const char* json, std::size_t size) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < size; ++i) {
    const char c = json[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw InputError(path, "JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// The glTF 2.0 schema's minimums for the fields that locate bytes (bufferView.schema.json,
// accessor.schema.json, buffer.schema.json): checked on the JSON itself, because a negative
// or fractional value would otherwise be converted to an unsigned size by the parser.
void check_schema_minimums(const std::string& path, const nlohmann::json& doc) {
  struct Field {
    const char* array;
    const char* name;
    double minimum, maximum;
    bool required;
  };
  static const Field kFields[] = {
      {"buffers", "byteLength", 1, 9007199254740991.0, true},
      {"bufferViews", "buffer", 0, 2147483647.0, true},
      {"bufferViews", "byteOffset", 0, 9007199254740991.0, false},
      {"bufferViews", "byteLength", 1, 9007199254740991.0, true},
      {"bufferViews", "byteStride", 4, 252, false},
      {"accessors", "bufferView", 0, 2147483647.0, false},
      {"accessors", "byteOffset", 0, 9007199254740991.0, false},
      {"accessors", "count", 1, 9007199254740991.0, true},
      {"accessors", "componentType", 5120, 5126, true},
      {"images", "bufferView", 0, 2147483647.0, false},
      {"textures", "source", 0, 2147483647.0, false},
  };
  for (const Field& f : kFields) {
    const auto arr = doc.find(f.array);
    if (arr == doc.end() || !arr->is_array()) continue;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const nlohmann::json& item = (*arr)[i];
      if (!item.is_object()) throw InputError(path, std::string(f.array) + "[" + std::to_string(i) + "] is not an object");
      const std::string where = std::string(f.array) + "[" + std::to_string(i) + "]." + f.name;
      const auto v = item.find(f.name);
      if (v == item.end()) {
        if (f.required) throw InputError(path, where + " is missing (required by glTF 2.0)");
        continue;
      }
      const bool integer = v->is_number_integer() || v->is_number_unsigned() ||
                           (v->is_number_float() && std::floor(v->get<double>()) == v->get<double>());
      const double x = v->is_number() ? v->get<double>() : 0.0;
      if (!v->is_number() || !integer || x < f.minimum || x > f.maximum)
        throw InputError(path, where + " is " + v->dump() + "; glTF 2.0 requires an integer in [" +
                                   std::to_string(static_cast<long long>(f.minimum)) + ", " +
                                   std::to_string(static_cast<long long>(f.maximum)) + "]");
    }
  }
}

// The glTF 2.0 schema's shapes that tinygltf skips silently when wrong (glTF.schema.json,
// mesh.schema.json, mesh.primitive.schema.json): the top-level collections are arrays of
// objects, a mesh's primitives a non-empty array of objects with an attributes object. A
// mesh whose "primitives" is an object would otherwise load as "no triangles".
void check_schema_shapes(const std::string& path, const nlohmann::json& doc) {
  for (const char* key : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                          "meshes", "nodes", "samplers", "scenes", "skins", "textures"}) {
    const auto c = doc.find(key);
    if (c == doc.end()) continue;
    if (!c->is_array()) throw InputError(path, std::string(key) + " is not an array");
    for (std::size_t i = 0; i < c->size(); ++i)
      if (!(*c)[i].is_object())
        throw InputError(path, std::string(key) + "[" + std::to_string(i) + "] is not an object");
  }
  if (const auto meshes = doc.find("meshes"); meshes != doc.end())
    for (std::size_t i = 0; i < meshes->size(); ++i) {
      const std::string where = "meshes[" + std::to_string(i) + "].primitives";
      const auto prims = (*meshes)[i].find("primitives");
      if (prims == (*meshes)[i].end() || !prims->is_array() || prims->empty())
        throw InputError(path, where + " must be a non-empty array (required by glTF 2.0)");
      for (std::size_t j = 0; j < prims->size(); ++j) {
        const auto& p = (*prims)[j];
        if (!p.is_object() || !p.contains("attributes") || !p["attributes"].is_object())
          throw InputError(path, where + "[" + std::to_string(j) + "] has no attributes object");
      }
    }
}

// tinygltf hands an image's bufferView to the image decoder while it parses, before any
// check of ours on the parsed model, and without checking that the view lies inside its
// buffer (glTF 2.0 §3.6.2: a bufferView is a range of its buffer's bytes): a view past
// the buffer's byteLength made the decoder read past the end of tinygltf's copy of it.
void check_image_buffer_views(const std::string& path, const nlohmann::json& doc) {
  const auto images = doc.find("images"), views = doc.find("bufferViews"), buffers = doc.find("buffers");
  if (images == doc.end() || views == doc.end() || buffers == doc.end()) return;
  auto number = [](const nlohmann::json& o, const char* key, double fallback) {
    const auto v = o.find(key);
    return v != o.end() && v->is_number() ? v->get<double>() : fallback;
  };
  for (std::size_t i = 0; i < images->size(); ++i) {
    const double view = number((*images)[i], "bufferView", -1.0);
    if (view < 0 || view >= double(views->size()) || view != std::floor(view)) continue;
    const nlohmann::json& v = (*views)[static_cast<std::size_t>(view)];
    const double buffer = number(v, "buffer", -1.0);
    if (buffer < 0 || buffer >= double(buffers->size()) || buffer != std::floor(buffer)) continue;
    const double length = number((*buffers)[static_cast<std::size_t>(buffer)], "byteLength", -1.0);
    const double end = number(v, "byteOffset", 0.0) + number(v, "byteLength", 0.0);
    if (length >= 0 && end > length)
      throw InputError(path, "images[" + std::to_string(i) + "] uses bufferView " +
                                 std::to_string(static_cast<long long>(view)) + ", which runs past the end of buffer " +
                                 std::to_string(static_cast<long long>(buffer)) + " (" +
                                 std::to_string(static_cast<long long>(end)) + " > " +
                                 std::to_string(static_cast<long long>(length)) + " bytes)");
  }
}

// An absolute URI (a path from /, or a file: URL) names a file wherever it is; tinygltf
// would append it to the scene's folder, which hides what the file asked for. Refused
// unless external files are allowed; relative URIs are checked where they resolve
// (ExternalFiles).
void check_uris_are_relative(const std::string& path, const nlohmann::json& doc) {
  for (const char* array : {"buffers", "images"}) {
    const auto arr = doc.find(array);
    if (arr == doc.end() || !arr->is_array()) continue;
    for (const auto& item : *arr) {
      if (!item.is_object()) continue;
      const auto uri = item.find("uri");
      if (uri == item.end() || !uri->is_string()) continue;
      const std::string u = uri->get<std::string>();
      if (u.rfind("data:", 0) == 0) continue;
      if (!u.empty() && (u[0] == '/' || u[0] == '\\' || u.rfind("file:", 0) == 0 ||
                         (u.size() > 1 && u[1] == ':')))
        throw InputError(path, "refers to '" + u + "' outside the scene's folder (--allow-external-files allows it)");
    }
  }
}

// What is checked on the JSON before tinygltf parses it: its nesting depth, the schema's
// minimums of the byte-locating fields, absolute URIs (unless allowed), and content this
// loader cannot read, named — otherwise a glTF 1.0 file (id-keyed objects where 2.0 has
// arrays) fails with "no triangles" or a schema complaint, and a Draco or
// meshopt-compressed one with "invalid bufferView". JSON that does not parse is left to
// tinygltf, which says where it breaks.
void check_before_parsing(const std::string& path, const char* json, std::size_t size,
                                           bool allow_external_files) {
  check_json_depth(path, json, size);
  const nlohmann::json doc = nlohmann::json::parse(json, json + size, nullptr, false);
  if (!doc.is_object()) return;
  check_schema_minimums(path, doc);
  // glTF 2.0 §3.5.3: "When matrix is defined, translation, rotation, and scale MUST NOT be
  // present" — which one a file meant is unknowable (tinygltf keeps the matrix silently).
  if (const auto nodes = doc.find("nodes"); nodes != doc.end() && nodes->is_array())
    for (std::size_t i = 0; i < nodes->size(); ++i) {
      const nlohmann::json& n = (*nodes)[i];
      if (n.is_object() && n.contains("matrix") && (n.contains("translation") || n.contains("rotation") || n.contains("scale")))
        throw InputError(path, "node " + std::to_string(i) + " has both a matrix and translation/rotation/scale");
    }
  for (const char* array : {"buffers", "images"})
    if (const auto arr = doc.find(array); arr != doc.end() && arr->is_array())
      for (std::size_t i = 0; i < arr->size(); ++i)
        if (const auto uri = (*arr)[i].find("uri"); uri != (*arr)[i].end() && uri->is_string())
          check_data_uri(path, uri->get<std::string>(), std::string(array) + "[" + std::to_string(i) + "]");
  if (!allow_external_files) check_uris_are_relative(path, doc);
  bool version1 = false;
  if (const auto asset = doc.find("asset"); asset != doc.end() && asset->is_object()) {
    if (const auto v = asset->find("version"); v != asset->end()) {
      if (v->is_number()) version1 = v->get<double>() < 2.0;
      else if (v->is_string()) version1 = v->get<std::string>().rfind("1", 0) == 0;
    }
  }
  // glTF 1.0 keeps its top-level collections in objects keyed by id (glTF 1.0 §5).
  for (const char* key : {"meshes", "accessors", "nodes", "bufferViews", "materials"})
    if (const auto c = doc.find(key); c != doc.end() && c->is_object() && !c->empty()) version1 = true;
  if (version1) throw InputError(path, "glTF 1.0 is not supported, 2.0 is");
  check_schema_shapes(path, doc);
  check_image_buffer_views(path, doc);
  const auto required = doc.find("extensionsRequired");
  if (required == doc.end() || !required->is_array()) return;
  std::string missing;
  int count = 0;
  for (const auto& e : *required)
    if (e.is_string() && !gltf::extension_supported(e.get<std::string>()))
      missing += (count++ ? ", " : "") + e.get<std::string>();
  if (count == 1) throw InputError(path, "extension " + missing + " is not supported");
  if (count > 1) throw InputError(path, "extensions " + missing + " are not supported");
}

// tinygltf's own image decoder, except that an image it cannot decode is kept empty instead
// of failing the whole file: MaterialTable then names it and leaves the texture out (or
// fails under --strict), as for a missing image file.
// Decodes a glTF image (PNG or JPEG, glTF 2.0 §3.9.1 "image.mimeType") into 8-bit channels with
// OpenImageIO (libpng, libjpeg), reading from memory. tinygltf's own decoder, Debian's libstb,
// overflows a heap buffer on some malformed images (found by fuzzing .glb files), so it is
// not used. An image that is neither, too large or undecodable is left empty: the material
// loader treats it as a missing texture (gltf_material.cpp).
bool tolerant_image_loader(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                           const unsigned char* bytes, int size, void*) {
  image->image.clear();
  image->width = image->height = 0;
  static constexpr unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  static constexpr unsigned char kJpeg[3] = {0xff, 0xd8, 0xff};
  const char* format = size >= 8 && std::memcmp(bytes, kPng, 8) == 0    ? "png"
                       : size >= 3 && std::memcmp(bytes, kJpeg, 3) == 0 ? "jpeg"
                                                                        : nullptr;
  if (!format) return true;
  constexpr long long kMaxPixels = 1ll << 28;  // as read_image (core/image_io.cpp)
  if (is_png(bytes, static_cast<std::size_t>(size)) &&
      !png_problem(bytes, static_cast<std::size_t>(size), kMaxPixels).empty())
    return true;  // undecodable: left empty, named by MaterialTable
  // The PNG or JPEG reader alone: ImageInput::open would fall back to every other format,
  // and OpenImageIO 2.4's DPX reader reads past the end of a memory buffer.
  OIIO::Filesystem::IOMemReader reader(bytes, static_cast<std::size_t>(size));
  auto in = OIIO::ImageInput::create(format);  // a format name: no file is opened
  OIIO::ImageSpec spec;
  if (!in || !in->set_ioproxy(&reader) || !in->open(std::string("image.") + format, spec)) {
    if (in) (void)in->geterror();  // clears OpenImageIO's pending messages
    (void)OIIO::geterror();
    return true;
  }
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 ||
      static_cast<long long>(spec.width) * spec.height > kMaxPixels)
    return true;
  const int nc = std::min(spec.nchannels, 4);
  std::vector<unsigned char> pixels(static_cast<std::size_t>(spec.width) * spec.height * nc);
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, pixels.data())) return true;
  image->image = std::move(pixels);
  image->width = spec.width;
  image->height = spec.height;
  image->component = nc;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  return true;
}

// tinygltf's file access for image and buffer URIs: paths are taken literally (tinygltf's
// default expands them with wordexp, i.e. `~` and `$VAR`), and unless allowed, a file whose
// real path (after `..` and symlinks) lies outside the scene's folder is neither tested nor
// read: the first one is remembered and the load fails naming it. Its other candidate, the
// URI against the current directory, is outside too unless the scene lies there.
struct ExternalFiles {
  std::filesystem::path folder;
  bool allow = false;
  std::string refused;

  bool inside(const std::string& file) {
    if (allow) return true;
    std::error_code ec;
    // Absolute first: weakly_canonical leaves a relative path whose first component does
    // not exist relative, which no folder contains (a missing image next to a scene given
    // without a folder was named as outside it).
    const auto root = std::filesystem::weakly_canonical(std::filesystem::absolute(folder.empty() ? "." : folder), ec);
    const auto real = std::filesystem::weakly_canonical(std::filesystem::absolute(file), ec);
    if (!ec) {
      const auto rel = real.lexically_relative(root);
      if (!rel.empty() && *rel.begin() != ".." && !rel.is_absolute()) return true;
    }
    // tinygltf also tries the URI against the current directory ("./uri"); that candidate
    // is never used (URIs resolve against the scene's folder) and not worth naming.
    const std::string base = folder.string();
    if (refused.empty() && (base.empty() || file.rfind(base, 0) == 0)) refused = file;
    return false;
  }
  static bool exists(const std::string& file, void* self) {
    return static_cast<ExternalFiles*>(self)->inside(file) && tinygltf::FileExists(file, nullptr);
  }
  static std::string expand(const std::string& file, void*) { return file; }
  static bool read(std::vector<unsigned char>* out, std::string* err, const std::string& file, void* self) {
    if (!static_cast<ExternalFiles*>(self)->inside(file)) {
      if (err) *err += "refused: " + file + "\n";
      return false;
    }
    return tinygltf::ReadWholeFile(out, err, file, nullptr);
  }
  static bool refuse_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) {
    return false;
  }
};

// Reads and parses the file (JSON .gltf or binary .glb) after check_before_parsing, with
// external files confined to the scene's folder (ExternalFiles).
tinygltf::Model parse_model(const std::string& path, LoadReport* report) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  const bool is_glb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".glb" || ext == ".GLB" || is_glb) check_glb_container(path, bytes);
  const bool allow_external = report && report->allow_external_files;
  if (is_glb)
    check_before_parsing(path, reinterpret_cast<const char*>(bytes.data()) + 20, le32(&bytes[12]),
                                          allow_external);
  else
    check_before_parsing(path, reinterpret_cast<const char*>(bytes.data()), bytes.size(),
                                          allow_external);

  tinygltf::TinyGLTF parser;
  // No user data: tinygltf's decoder then uses its default options, as without a loader.
  parser.SetImageLoader(tolerant_image_loader, nullptr);
  ExternalFiles external{std::filesystem::path(path).parent_path(), allow_external, {}};
  parser.SetFsCallbacks(tinygltf::FsCallbacks{&ExternalFiles::exists, &ExternalFiles::expand,
                                               &ExternalFiles::read, &ExternalFiles::refuse_write, &external});
  tinygltf::Model model;
  std::string err, warn;
  const std::string base_dir = std::filesystem::path(path).parent_path().string();
  const bool ok =
      is_glb ? parser.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                           static_cast<unsigned>(bytes.size()), base_dir)
             : parser.LoadASCIIFromString(&model, &err, &warn,
                                          reinterpret_cast<const char*>(bytes.data()),
                                          static_cast<unsigned>(bytes.size()), base_dir);
  if (!external.refused.empty())
    throw InputError(path, "refers to '" + external.refused +
                               "' outside the scene's folder (--allow-external-files allows it)");
  if (!ok) throw InputError(path, one_line(err.empty() ? "tinygltf could not parse the file" : err));
  // tinygltf's warnings, one per line; those about images it could not load are left to
  // MaterialTable, which names the texture once and only when a material uses it.
  if (report) {
    std::size_t at = 0;
    while (at < warn.size()) {
      std::size_t end = warn.find('\n', at);
      if (end == std::string::npos) end = warn.size();
      const std::string line = one_line(warn.substr(at, end - at));
      at = end + 1;
      if (line.empty() || line.rfind("File not found", 0) == 0 ||
          line.find("Failed to load external 'uri' for image") != std::string::npos)
        continue;
      report->warn(line);
    }
  }

  for (const std::string& e : model.extensionsRequired)
    if (!gltf::extension_supported(e)) throw InputError(path, "extension " + e + " is not supported");
  return model;
}

// The root nodes to flatten: the default scene's (scene 0 when none is named), or every
// parentless node when the file has no scenes.
std::vector<int> root_nodes(const tinygltf::Model& model, const std::string& path) {
  std::vector<int> roots;
  if (!model.scenes.empty()) {
    int s = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (static_cast<std::size_t>(s) >= model.scenes.size())
      throw InputError(path, "default scene " + std::to_string(s) + " does not exist");
    roots = model.scenes[static_cast<std::size_t>(s)].nodes;
  } else {
    // No scene: every node without a parent is a root (the spec leaves this open).
    std::vector<char> has_parent(model.nodes.size(), 0);
    for (const auto& node : model.nodes)
      for (int c : node.children)
        if (c >= 0 && static_cast<std::size_t>(c) < model.nodes.size()) has_parent[static_cast<std::size_t>(c)] = 1;
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
      if (!has_parent[i]) roots.push_back(static_cast<int>(i));
  }
  return roots;
}

// One finite float from `v` (a JSON number), or InputError naming `what`.
float finite_number(const std::string& path, const tinygltf::Value& v, const std::string& what) {
  const double x = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
  if (!std::isfinite(x) || std::fabs(x) > std::numeric_limits<float>::max())
    throw InputError(path, what + " must be a finite number");
  return static_cast<float>(x);
}

int positive_int(const std::string& path, const tinygltf::Value& v, const std::string& what, int max) {
  if (!v.IsInt() || v.Get<int>() < 1 || v.Get<int>() > max)
    throw InputError(path, what + " must be an integer in [1, " + std::to_string(max) + "]");
  return v.Get<int>();
}

// The equirect image of extras.speculum_environment.equirect (gltf_environment.h): its
// bufferView must hold exactly width x height RGBA32F pixels inside its buffer.
ImageRGBA read_equirect(const std::string& path, const tinygltf::Model& model, const tinygltf::Value& q) {
  const std::string what = std::string("extras.") + gltf::kEnvironmentExtrasKey + ".equirect";
  if (!q.IsObject()) throw InputError(path, what + " must be an object");
  for (const char* key : {"bufferView", "width", "height", "format"})
    if (!q.Has(key)) throw InputError(path, what + " has no \"" + key + "\"");
  if (!q.Get("format").IsString() || q.Get("format").Get<std::string>() != gltf::kEquirectFormat)
    throw InputError(path, what + ".format must be \"" + gltf::kEquirectFormat + "\"");
  const int width = positive_int(path, q.Get("width"), what + ".width", gltf::kMaxEquirectSide);
  const int height = positive_int(path, q.Get("height"), what + ".height", gltf::kMaxEquirectSide);
  const tinygltf::Value& bv = q.Get("bufferView");
  if (!bv.IsInt() || bv.Get<int>() < 0 || static_cast<std::size_t>(bv.Get<int>()) >= model.bufferViews.size())
    throw InputError(path, what + ".bufferView does not name a bufferView");
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(bv.Get<int>())];
  const std::uint64_t bytes = std::uint64_t(width) * std::uint64_t(height) * gltf::kEquirectBytesPerPixel;
  if (view.byteLength != bytes || (view.byteStride != 0 && view.byteStride != gltf::kEquirectBytesPerPixel))
    throw InputError(path, what + ": bufferView " + std::to_string(bv.Get<int>()) + " holds " +
                               std::to_string(view.byteLength) + " bytes, " + std::to_string(width) +
                               "x" + std::to_string(height) + " RGBA32F needs " + std::to_string(bytes));
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size() ||
      std::uint64_t(view.byteOffset) + bytes > model.buffers[static_cast<std::size_t>(view.buffer)].data.size())
    throw InputError(path, what + ": bufferView " + std::to_string(bv.Get<int>()) +
                               " runs past the end of its buffer");
  const unsigned char* p = model.buffers[static_cast<std::size_t>(view.buffer)].data.data() + view.byteOffset;
  ImageRGBA img(width, height);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      const std::uint32_t bits = le32(p + 16 * i + 4 * static_cast<std::size_t>(c));
      float v;
      std::memcpy(&v, &bits, 4);
      if (!std::isfinite(v))
        throw InputError(path, what + " pixel " + std::to_string(i % static_cast<std::size_t>(width)) +
                                   "," + std::to_string(i / static_cast<std::size_t>(width)) +
                                   " has a NaN or infinite value");
      img.pixels[i][c] = v;
    }
  return img;
}

// Scene::environment from the root extras a speculum export writes (gltf_environment.h);
// left at its default (black) when the file carries none. Extras that are not an object, or
// carry other keys, belong to other tools and are left alone.
void read_environment(const std::string& path, const tinygltf::Model& model, Scene& scene,
                      LoadReport* report) {
  if (!model.extras.IsObject() || !model.extras.Has(gltf::kEnvironmentExtrasKey)) return;
  const std::string what = std::string("extras.") + gltf::kEnvironmentExtrasKey;
  const tinygltf::Value& e = model.extras.Get(gltf::kEnvironmentExtrasKey);
  if (!e.IsObject()) throw InputError(path, what + " must be an object");
  Environment env;
  if (e.Has("color")) {
    const tinygltf::Value& c = e.Get("color");
    if (!c.IsArray() || c.ArrayLen() != 3) throw InputError(path, what + ".color must be an array of 3 numbers");
    for (int k = 0; k < 3; ++k) env.constant[k] = finite_number(path, c.Get(k), what + ".color");
  }
  if (e.Has("intensity")) {
    env.intensity = finite_number(path, e.Get("intensity"), what + ".intensity");
    if (env.intensity < 0.0f) throw InputError(path, what + ".intensity must not be negative");
  }
  if (e.Has("equirect")) env.equirect = read_equirect(path, model, e.Get("equirect"));
  env.source = path;
  for (const std::string& key : e.Keys())
    if (key != "color" && key != "intensity" && key != "equirect" && report)
      report->warn(what + ": unknown key \"" + key + "\" ignored");
  scene.environment = std::move(env);
}

}  // namespace

Scene load_gltf(const std::string& path, LoadReport* report_or_null) {
  LoadReport local;
  LoadReport* report = report_or_null ? report_or_null : &local;
  const tinygltf::Model model = parse_model(path, report);
  Scene scene;
  scene.name = path;
  Loader loader{path, model, scene, report, gltf::MaterialTable(path, model, scene, *report), {}, {}, 0};

  // Materials in file order (not order of use), so indices match the file's.
  for (std::size_t i = 0; i < model.materials.size(); ++i) loader.materials.scene_material(static_cast<int>(i));
  const std::vector<int> roots = root_nodes(model, path);
  loader.flatten(roots);
  if (scene.mesh.triangle_count() == 0)
    throw InputError(path, "contains no triangles to render" +
                               std::string(report && report->skipped_primitives
                                               ? " (points/lines primitives are skipped)"
                                               : ""));
  loader.add_cameras();
  loader.add_lights();
  read_environment(path, model, scene, report);
  loader.materials.finish();
  finish_scene(scene);
  return scene;
}

}  // namespace speculum
