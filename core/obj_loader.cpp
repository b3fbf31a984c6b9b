// OBJ + .mtl through tinyobjloader (see obj_loader.h).
#include "core/obj_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <unordered_map>

#include <glm/geometric.hpp>

#include <tiny_obj_loader.h>

#include "core/error.h"
#include "core/image.h"
#include "core/mesh_normals.h"

namespace speculum {
namespace {

namespace fs = std::filesystem;

// Inside `root` (both made absolute and normal, symlinks resolved where they exist).
bool inside(const fs::path& file, const fs::path& root) {
  std::error_code ec;
  const fs::path f = fs::weakly_canonical(fs::absolute(file), ec);
  const fs::path r = fs::weakly_canonical(fs::absolute(root), ec);
  const fs::path rel = f.lexically_relative(r);
  return !rel.empty() && *rel.begin() != "..";
}

// A name as written in a .mtl or mtllib line: Windows separators become '/'.
fs::path as_path(std::string name) {
  std::replace(name.begin(), name.end(), '\\', '/');
  return fs::path(name);
}

// A material name as tinyobjloader can match it: it reads only the first word of a
// `usemtl` line, so names with spaces ("Hard Shiny Plastic") are joined by '_' in both the
// OBJ's `usemtl` and the .mtl's `newmtl` lines before parsing.
std::string joined_name(const std::string& rest) {
  std::istringstream in(rest);
  std::string out;
  for (std::string word; in >> word;) out += (out.empty() ? "" : "_") + word;
  return out;
}

// `text` with every `keyword NAME WITH SPACES` line's name joined; `originals` (optional)
// receives joined → original name.
std::string join_names(const std::string& text, const std::string& keyword,
                       std::map<std::string, std::string>* originals) {
  std::string out;
  out.reserve(text.size());
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    const std::size_t p = line.find_first_not_of(" \t");
    if (p != std::string::npos && line.compare(p, keyword.size(), keyword) == 0 &&
        p + keyword.size() < line.size() && (line[p + keyword.size()] == ' ' || line[p + keyword.size()] == '\t')) {
      const std::string rest = line.substr(p + keyword.size());
      const std::string name = joined_name(rest);
      if (originals) {
        std::string original = rest.substr(std::min(rest.size(), rest.find_first_not_of(" \t")));
        while (!original.empty() && std::isspace(static_cast<unsigned char>(original.back()))) original.pop_back();
        (*originals)[name] = original;
      }
      out += keyword + " " + name;
    } else {
      out += line;
    }
    if (end < text.size()) out += '\n';
    at = end + 1;
  }
  return out;
}

// Which optional keys each material of a .mtl states. tinyobjloader fills absent keys with
// defaults that cannot be told from stated values (Pr 0, Ni 1), so the text is scanned.
struct StatedKeys {
  bool pr = false, pm = false, ni = false;
};

// Reads the .mtl files a `mtllib` names, relative to the OBJ's folder and only inside it,
// and remembers each material's folder (its textures resolve against it) and stated keys.
class MtlReader : public tinyobj::MaterialReader {
 public:
  MtlReader(const fs::path& obj_dir, bool allow_outside) : dir_(obj_dir), allow_outside_(allow_outside) {}
  ~MtlReader() override = default;

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* names, std::string*, std::string*) override {
    const fs::path file = dir_ / as_path(name);
    std::error_code ec;
    if (!allow_outside_ && !inside(file, dir_)) {
      problems_.push_back("material library '" + name + "' lies outside the OBJ's folder: ignored");
      return false;
    }
    if (!fs::is_regular_file(file, ec)) {
      problems_.push_back("material library '" + name + "' not found: default material used");
      return false;
    }
    std::ifstream in(file, std::ios::binary);
    std::stringstream raw;
    raw << in.rdbuf();
    std::map<std::string, std::string> originals;
    const std::string text = join_names(raw.str(), "newmtl", &originals);
    const std::size_t first = materials->size();
    std::string warn, err;
    std::istringstream parse(text);
    tinyobj::LoadMtl(names, materials, &parse, &warn, &err);
    std::map<std::string, StatedKeys> stated;
    std::istringstream scan(text);
    std::string current;
    for (std::string line; std::getline(scan, line);) {
      std::istringstream ls(line);
      std::string key;
      ls >> key;
      if (key == "newmtl") {
        std::getline(ls >> std::ws, current);
        while (!current.empty() && (current.back() == '\r' || current.back() == ' ')) current.pop_back();
      } else if (key == "Pr") {
        stated[current].pr = true;
      } else if (key == "Pm") {
        stated[current].pm = true;
      } else if (key == "Ni") {
        stated[current].ni = true;
      }
    }
    for (std::size_t i = first; i < materials->size(); ++i) {
      folders_.push_back(file.parent_path());
      keys_.push_back(stated[(*materials)[i].name]);
      if (auto it = originals.find((*materials)[i].name); it != originals.end())
        (*materials)[i].name = it->second;
    }
    return true;
  }

  const std::vector<std::string>& problems() const { return problems_; }
  const fs::path& folder(std::size_t material) const { return folders_[material]; }
  const StatedKeys& keys(std::size_t material) const { return keys_[material]; }

 private:
  fs::path dir_;
  bool allow_outside_ = false;
  std::vector<std::string> problems_;
  std::vector<fs::path> folders_;
  std::vector<StatedKeys> keys_;
};

// Converts the .mtl materials to scene materials, decoding each texture once.
class MtlConverter {
 public:
  MtlConverter(const std::string& path, const fs::path& obj_dir, const MtlReader& reader,
               Scene& scene, LoadReport& report)
      : path_(path), dir_(obj_dir), reader_(reader), scene_(scene), report_(report) {}

  Material convert(const tinyobj::material_t& t, std::size_t index) {
    const StatedKeys& keys = reader_.keys(index);
    Material m;
    m.name = t.name.empty() ? "material " + std::to_string(index) : t.name;
    m.base_color = glm::vec4(t.diffuse[0], t.diffuse[1], t.diffuse[2], 1.0f);
    m.roughness = keys.pr ? t.roughness : roughness_from_phong_exponent(t.shininess);
    m.metallic = keys.pm ? t.metallic : 0.0f;
    m.emissive = glm::vec3(t.emission[0], t.emission[1], t.emission[2]);
    // No alpha blending here: a see-through OBJ surface is a refractor (d is opacity).
    m.transmission = 1.0f - t.dissolve;
    m.ior = keys.ni && t.ior >= 1.0f ? t.ior : 1.5f;
    const float all = m.base_color.x + m.base_color.y + m.base_color.z + m.roughness +
                      m.metallic + m.emissive.x + m.emissive.y + m.emissive.z + m.transmission + m.ior;
    if (!std::isfinite(all)) throw InputError(path_, "material '" + m.name + "' has a NaN or infinite value");
    m.base_color = glm::clamp(m.base_color, glm::vec4(0.0f), glm::vec4(1.0f));
    m.roughness = std::clamp(m.roughness, 0.0f, 1.0f);
    m.metallic = std::clamp(m.metallic, 0.0f, 1.0f);
    m.transmission = std::clamp(m.transmission, 0.0f, 1.0f);
    m.emissive = glm::max(m.emissive, glm::vec3(0.0f));
    m.base_color_texture.texture = texture(t.diffuse_texname, index);
    m.emissive_texture.texture = texture(t.emissive_texname, index);
    for (const auto& [key, name] : {std::pair{"map_Ks", &t.specular_texname},
                                    {"map_Bump/bump", &t.bump_texname}, {"norm", &t.normal_texname},
                                    {"map_Pr", &t.roughness_texname}, {"map_Pm", &t.metallic_texname},
                                    {"map_d", &t.alpha_texname}})
      if (!name->empty())
        report_.warn("material '" + m.name + "': " + key + " texture '" + *name + "' is not used");
    return m;
  }

 private:
  // The scene texture for `name` (a .mtl texture, relative to that .mtl's folder), or -1.
  int texture(const std::string& name, std::size_t material) {
    if (name.empty()) return -1;
    const fs::path file = (reader_.folder(material) / as_path(name)).lexically_normal();
    if (auto it = cache_.find(file.string()); it != cache_.end()) return it->second;
    int index = -1;
    std::error_code ec;
    if (!report_.allow_external_files && !inside(file, dir_)) {
      report_.substitute(path_, "texture '" + name + "' lies outside the OBJ's folder: drawn without it");
    } else if (!fs::is_regular_file(file, ec)) {
      report_.substitute(path_, "texture '" + name + "' not found: drawn without it");
    } else {
      try {
        scene_.textures.push_back(read_image(file.string(), true));
        scene_.texture_sources.push_back(path_ + ": '" + name + "' (sRGB)");
        index = static_cast<int>(scene_.textures.size()) - 1;
      } catch (const InputError& e) {
        report_.substitute(path_, "texture '" + name + "' could not be decoded (" + e.problem() +
                                      "): drawn without it");
      }
    }
    cache_[file.string()] = index;
    return index;
  }

  const std::string& path_;
  fs::path dir_;
  const MtlReader& reader_;
  Scene& scene_;
  LoadReport& report_;
  std::map<std::string, int> cache_;
};

// Each distinct (position, normal, uv) corner is one vertex, numbered in order of first use.
struct CornerHash {
  std::size_t operator()(const std::tuple<int, int, int>& k) const {
    const auto [a, b, c] = k;
    return std::hash<std::uint64_t>()((std::uint64_t(std::uint32_t(a)) * 0x9E3779B97F4A7C15ull) ^
                                      (std::uint64_t(std::uint32_t(b)) << 21) ^ std::uint32_t(c));
  }
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

// tinyobjloader reads a coordinate it cannot parse ("nan", "inf", a word) as 0, which
// would move the vertex silently: every `v` line's three coordinates (the OBJ format's
// "v x y z [w]") must start with a finite number (as strtod reads it; a trailing oddity
// such as assimp's "3.1+e2" reads as 3.1). It also reads face indices with atoi, so an
// index past the int range wraps to any vertex: every `f` corner's indices ("v", "v/vt",
// "v//vn", "v/vt/vn") must be integers of at most 10 digits.
void check_vertex_lines(const std::string& path, const std::string& text) {
  std::size_t vertex = 0, at = 0, line = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    std::size_t p = text.find_first_not_of(" \t", at);
    // p is npos when only blanks are left (p + 1 would wrap to 0).
    ++line;
    if (p != std::string::npos && p + 1 < end && text[p] == 'f' && (text[p + 1] == ' ' || text[p + 1] == '\t')) {
      std::istringstream ls(text.substr(p + 2, end - p - 2));
      for (std::string corner; ls >> corner;) {
        std::size_t from = 0;
        for (int k = 0; k < 3 && from <= corner.size(); ++k) {
          std::size_t to = corner.find('/', from);
          if (to == std::string::npos) to = corner.size();
          const std::string index = corner.substr(from, to - from);
          const std::size_t digits = index.size() - (index[0] == '-' ? 1 : 0);
          if (!index.empty() && (digits == 0 || digits > 10 ||
                                 index.find_first_not_of("0123456789", index[0] == '-' ? 1 : 0) != std::string::npos ||
                                 std::stoll(index) > 2147483647ll || std::stoll(index) < -2147483647ll))
            throw InputError(path, "line " + std::to_string(line) + ": face index '" + index.substr(0, 20) +
                                       "' is not an integer within the int range");
          from = to + 1;
        }
      }
    }
    if (p != std::string::npos && p + 1 < end && text[p] == 'v' && (text[p + 1] == ' ' || text[p + 1] == '\t')) {
      ++vertex;
      std::istringstream ls(text.substr(p + 2, end - p - 2));
      std::string token;
      for (int k = 0; k < 3; ++k) {
        if (!(ls >> token))
          throw InputError(path, "vertex " + std::to_string(vertex) + " has " + std::to_string(k) +
                                     " coordinates (OBJ's v line needs x y z)");
        char* stop = nullptr;
        const double x = std::strtod(token.c_str(), &stop);
        // A value past a float's range overflows to infinity when tinyobjloader reads it.
        if (stop == token.c_str() || !(std::fabs(x) < double(std::numeric_limits<float>::max())))
          throw InputError(path, "non-finite vertex " + std::to_string(vertex) + ": coordinate '" + token.substr(0, 20) +
                                     "' is NaN, infinite, past a float's range or unreadable");
      }
    }
    at = end + 1;
  }
}

}  // namespace

float roughness_from_phong_exponent(float exponent) {
  if (!(exponent > 0.0f)) return 1.0f;
  return std::clamp(std::pow(1.0f / (exponent + 1.0f), 0.25f), 0.0f, 1.0f);
}

Scene load_obj(const std::string& path, LoadReport& report) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "file not found");
  if (fs::is_directory(path, ec)) throw InputError(path, "is a directory");
  if (fs::file_size(path, ec) == 0 || ec) throw InputError(path, "file is empty");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path, "cannot open file");
  std::stringstream raw;
  raw << file.rdbuf();
  const std::string text = join_names(raw.str(), "usemtl", nullptr);
  check_vertex_lines(path, text);
  std::istringstream in(text);

  const fs::path dir = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  MtlReader reader(dir, report.allow_external_files);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  bool ok = false;
  try {
    ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &reader, true, false);
  } catch (const std::bad_alloc&) {
    throw InputError(path, "out of memory while reading");
  }
  if (!ok) {
    const auto errors = lines_of(err);
    throw InputError(path, errors.empty() ? "tinyobjloader could not read the file" : errors.front());
  }
  for (const std::string& p : reader.problems()) report.substitute(path, p);
  // tinyobjloader's own warnings; a usemtl naming no material is reported in our words,
  // and not at all when the library itself is missing (that warning says it already).
  std::size_t degenerate = 0;
  for (const std::string& w : lines_of(warn)) {
    // tinyobjloader's "Degenerated face found\n." for each face of fewer than 3 corners.
    if (w.rfind("Degenerated face found", 0) == 0) {
      ++degenerate;
      continue;
    }
    if (w == ".") continue;
    if (w.find("Material file") != std::string::npos || w.find("Failed to load material file") != std::string::npos)
      continue;
    const std::size_t open = w.find("[ '"), close = w.find("' ] not found in .mtl");
    if (open != std::string::npos && close != std::string::npos && close > open) {
      if (reader.problems().empty())
        report.warn("usemtl '" + w.substr(open + 3, close - open - 3) + "' names no material" +
                    (materials.empty() ? " (the file has no mtllib)" : " of the .mtl") +
                    ": default material used");
      continue;
    }
    report.warn(w);
  }
  if (degenerate) report.warn(std::to_string(degenerate) + " faces with fewer than 3 corners left out");

  Scene scene;
  scene.name = path;
  TriangleMesh& mesh = scene.mesh;
  const std::size_t np = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3,
                    nt = attrib.texcoords.size() / 2;
  for (std::size_t i = 0; i < attrib.vertices.size(); ++i)
    if (!std::isfinite(attrib.vertices[i]))
      throw InputError(path, "non-finite vertex " + std::to_string(i / 3 + 1) + " (NaN or infinite position)");

  // Scene materials for the .mtl materials in use, in .mtl order; -1 and unknown: default.
  MtlConverter converter(path, dir, reader, scene, report);
  std::vector<int> material_map(materials.size(), -1);
  int default_material = -1;
  auto scene_material = [&](int id) -> std::uint32_t {
    if (id < 0 || static_cast<std::size_t>(id) >= materials.size()) {
      if (default_material < 0) {
        default_material = static_cast<int>(scene.materials.size());
        scene.materials.push_back(speculum::default_material());
      }
      return static_cast<std::uint32_t>(default_material);
    }
    int& slot = material_map[static_cast<std::size_t>(id)];
    if (slot < 0) {
      slot = static_cast<int>(scene.materials.size());
      scene.materials.push_back(converter.convert(materials[static_cast<std::size_t>(id)], static_cast<std::size_t>(id)));
    }
    return static_cast<std::uint32_t>(slot);
  };

  std::unordered_map<std::tuple<int, int, int>, std::uint32_t, CornerHash> corners;
  std::vector<std::uint32_t> position_of;  // per scene vertex: its OBJ position
  std::vector<std::uint32_t> position_indices;
  std::vector<bool> has_normal;             // per scene vertex: the file gave a normal
  const std::string stem = fs::path(path).stem().string();
  for (const tinyobj::shape_t& shape : shapes) {
    const auto& idx = shape.mesh.indices;
    const std::size_t faces = shape.mesh.num_face_vertices.size();
    if (faces == 0) continue;
    Object obj;
    obj.name = shape.name.empty() ? stem : shape.name;
    obj.first_triangle = static_cast<std::uint32_t>(mesh.triangle_count());
    std::size_t at = 0;
    for (std::size_t f = 0; f < faces; ++f) {
      const std::size_t n = shape.mesh.num_face_vertices[f];
      if (at + n > idx.size()) throw InputError(path, "face list is inconsistent");
      if (n != 3) {  // triangulated already; a face of fewer corners is dropped
        at += n;
        continue;
      }
      for (std::size_t k = 0; k < 3; ++k) {
        const tinyobj::index_t& c = idx[at + k];
        if (c.vertex_index < 0 || static_cast<std::size_t>(c.vertex_index) >= np)
          throw InputError(path, "a face indexes vertex " + std::to_string(c.vertex_index + 1) +
                                     " of " + std::to_string(np));
        if (c.normal_index >= 0 && static_cast<std::size_t>(c.normal_index) >= nn)
          throw InputError(path, "a face indexes normal " + std::to_string(c.normal_index + 1) +
                                     " of " + std::to_string(nn));
        if (c.texcoord_index >= 0 && static_cast<std::size_t>(c.texcoord_index) >= nt)
          throw InputError(path, "a face indexes texture coordinate " +
                                     std::to_string(c.texcoord_index + 1) + " of " + std::to_string(nt));
        const auto key = std::make_tuple(c.vertex_index, c.normal_index, c.texcoord_index);
        auto [it, added] = corners.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
        if (added) {
          const std::size_t v = static_cast<std::size_t>(c.vertex_index);
          mesh.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
          glm::vec2 uv(0.0f);
          if (c.texcoord_index >= 0) {
            const std::size_t t = static_cast<std::size_t>(c.texcoord_index);
            uv = glm::vec2(attrib.texcoords[2 * t], 1.0f - attrib.texcoords[2 * t + 1]);
            if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
          }
          mesh.uvs.push_back(uv);
          glm::vec3 normal(0.0f);
          if (c.normal_index >= 0) {
            const std::size_t q = static_cast<std::size_t>(c.normal_index);
            normal = glm::vec3(attrib.normals[3 * q], attrib.normals[3 * q + 1], attrib.normals[3 * q + 2]);
          }
          mesh.normals.push_back(normal);
          has_normal.push_back(c.normal_index >= 0);
          position_of.push_back(static_cast<std::uint32_t>(v));
        }
        mesh.indices.push_back(it->second);
        position_indices.push_back(static_cast<std::uint32_t>(c.vertex_index));
      }
      const std::uint32_t material = scene_material(shape.mesh.material_ids[f]);
      if (mesh.triangle_material.size() == obj.first_triangle) obj.material = material;
      mesh.triangle_material.push_back(material);
      mesh.triangle_object.push_back(static_cast<std::uint32_t>(scene.objects.size()));
      at += 3;
      if (mesh.positions.size() >= 0xfffffff0u) throw InputError(path, "too many vertices");
    }
    obj.triangle_count = static_cast<std::uint32_t>(mesh.triangle_count() - obj.first_triangle);
    if (obj.triangle_count > 0) scene.objects.push_back(obj);
  }
  if (mesh.indices.empty()) throw InputError(path, "contains no faces");

  // Normals: the file's where a corner has a sane one; elsewhere area-weighted over the OBJ's
  // positions (so corners split only by their uvs stay smooth).
  std::vector<glm::vec3> smooth;
  std::size_t bad = 0;
  for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
    glm::vec3& n = mesh.normals[i];
    const float len = glm::length(n);
    if (len > 1e-6f && std::isfinite(len)) {
      n /= len;
      continue;
    }
    if (has_normal[i]) ++bad;
    if (smooth.empty()) {
      std::vector<glm::vec3> obj_positions(np);
      for (std::size_t v = 0; v < np; ++v)
        obj_positions[v] = glm::vec3(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
      smooth = area_weighted_normals(obj_positions, position_indices);
    }
    n = smooth[position_of[i]];
  }
  if (bad) report.warn(std::to_string(bad) + " zero or non-finite normals, recomputed");
  return scene;
}

}  // namespace speculum
