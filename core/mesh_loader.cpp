// PLY/OFF/STL through OpenMesh, OBJ through core/obj_loader.h (see mesh_loader.h). Headers with element counts are
// checked against the file size first, so an absurd count cannot make OpenMesh reserve
// gigabytes; OpenMesh's own stream logging is silenced (the CLI prints one line).
#include "core/mesh_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <vector>
#include <cstring>

#include <glm/geometric.hpp>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "core/error.h"
#include "core/mesh_normals.h"
#include "core/obj_loader.h"

namespace speculum {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

std::string lower_ext(const std::string& path) {
  std::string e = std::filesystem::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

// The layout a PLY header declares: per element its count and properties.
struct PlyProperty {
  bool list = false;
  int count_bytes = 0;  // list: size of the count's type
  int item_bytes = 0;   // the scalar's size, or each list item's
  bool count_signed = false;
};
struct PlyElement {
  unsigned long long count = 0;
  std::vector<PlyProperty> properties;
};
struct PlyLayout {
  bool binary = false, big_endian = false;
  std::vector<PlyElement> elements;
};

int ply_type_bytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "double" || t == "float64") return 8;
  return 4;
}

// A strict PLY header check: OpenMesh's PLY reader reads out of bounds on some malformed
// headers (found by mutating tests/data/good/tetra.ply under ASan), so only well-formed
// headers reach it.
PlyLayout check_ply_header(const std::string& path, std::istream& in, std::uintmax_t size) {
  PlyLayout layout;
  static const std::set<std::string> kTypes = {
      "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
      "int16", "uint16", "int32", "uint32", "float32", "float64"};
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "ply") throw InputError(path, "missing 'ply' magic line");
  bool format = false, element = false, vertex = false, face = false, binary = false;
  int lines = 0;
  while (std::getline(in, line)) {
    if (++lines > 10000) throw InputError(path, "PLY header too long");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::vector<std::string> w;
    for (std::string t; ls >> t;) w.push_back(t);
    auto bad = [&] { throw InputError(path, "malformed PLY header line: '" + line.substr(0, 60) + "'"); };
    if (w.empty()) bad();
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (w.size() != 1 || !format || !vertex) bad();
      // Checked here because OpenMesh rejects some face-less files (e.g. point clouds with
      // extra properties) with no reason given.
      if (!face) throw InputError(path, "contains no faces (the header declares no face element)");
      layout.binary = binary;
      return layout;
    }
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad();
      format = true;
      binary = w[1] != "ascii";
      layout.big_endian = w[1] == "binary_big_endian";
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string::npos || w[2].size() > 12) bad();
      const unsigned long long n = std::stoull(w[2]);
      if (n > size / (binary ? 1 : 2))
        throw InputError(path, "header declares " + w[2] + " " + w[1] + " elements but the file has only " +
                                   std::to_string(size) + " bytes");
      element = true;
      layout.elements.push_back({n, {}});
      vertex = vertex || w[1] == "vertex";
      face = face || w[1] == "face";
    } else if (w[0] == "property") {
      if (!element) bad();
      if (w.size() == 3) {
        if (!kTypes.count(w[1])) bad();
        layout.elements.back().properties.push_back({false, 0, ply_type_bytes(w[1]), false});
      } else if (w.size() == 5 && w[1] == "list") {
        if (!kTypes.count(w[2]) || !kTypes.count(w[3])) bad();
        if (w[2] == "float" || w[2] == "double" || w[2] == "float32" || w[2] == "float64") bad();
        layout.elements.back().properties.push_back(
            {true, ply_type_bytes(w[2]), ply_type_bytes(w[3]), w[2][0] != 'u'});
      } else {
        bad();
      }
    } else {
      bad();
    }
  }
  throw InputError(path, "PLY header has no end_header line");
}

// Walks the data a PLY header declares, before OpenMesh does: OpenMesh trusts every list
// count (a face claiming 4 billion corners made it append vertex handles until memory ran
// out), so each count must be a whole number >= 0 whose items the file still holds, and the
// file must hold every element the header declares (PLY's element data follow the header in
// declaration order, each property in turn; ASCII separates values by white space).
void check_ply_body(const std::string& path, std::istream& in, const PlyLayout& layout) {
  auto truncated = [&](const char* what) {
    throw InputError(path, std::string("PLY data truncated or malformed: ") + what);
  };
  if (!layout.binary) {
    std::string tok;
    for (const PlyElement& e : layout.elements)
      for (unsigned long long i = 0; i < e.count; ++i)
        for (const PlyProperty& p : e.properties) {
          if (!(in >> tok)) truncated("fewer values than the header declares");
          if (!p.list) continue;
          if (tok.empty() || tok.size() > 9 || tok.find_first_not_of("0123456789") != std::string::npos)
            throw InputError(path, "PLY list count '" + tok.substr(0, 20) + "' is not a whole number below 10^9");
          for (unsigned long n = std::stoul(tok); n > 0; --n)
            if (!(in >> tok)) truncated("a list is longer than the data left");
        }
    return;
  }
  const std::string body{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::size_t at = 0;
  auto need = [&](unsigned long long bytes) {
    if (bytes > body.size() - at) truncated("fewer bytes than the header declares");
  };
  for (const PlyElement& e : layout.elements) {
    const bool has_list = std::any_of(e.properties.begin(), e.properties.end(), [](const PlyProperty& p) { return p.list; });
    if (!has_list) {
      unsigned long long stride = 0;
      for (const PlyProperty& p : e.properties) stride += static_cast<unsigned long long>(p.item_bytes);
      if (stride && e.count > (body.size() - at) / stride) truncated("fewer bytes than the header declares");
      at += static_cast<std::size_t>(stride * e.count);
      continue;
    }
    for (unsigned long long i = 0; i < e.count; ++i)
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          need(static_cast<unsigned long long>(p.item_bytes));
          at += static_cast<std::size_t>(p.item_bytes);
          continue;
        }
        need(static_cast<unsigned long long>(p.count_bytes));
        unsigned char b[4] = {};
        std::memcpy(b, body.data() + at, static_cast<std::size_t>(p.count_bytes));
        at += static_cast<std::size_t>(p.count_bytes);
        if (layout.big_endian) std::reverse(b, b + p.count_bytes);
        std::uint32_t raw = 0;
        for (int k = p.count_bytes - 1; k >= 0; --k) raw = (raw << 8) | b[k];
        long long n = raw;
        if (p.count_signed && (raw >> (8 * p.count_bytes - 1)) & 1u) n = -1;
        if (n < 0) throw InputError(path, "PLY list count is negative");
        need(static_cast<unsigned long long>(n) * static_cast<unsigned long long>(p.item_bytes));
        at += static_cast<std::size_t>(n) * static_cast<std::size_t>(p.item_bytes);
      }
  }
}

// Rejects headers that promise more elements than the file could hold (each vertex or
// face takes at least a few bytes in every encoding).
void check_declared_counts(const std::string& path, const std::string& ext, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  auto too_many = [&](unsigned long long n, const char* what, unsigned long long min_bytes) {
    if (n > size / min_bytes)
      throw InputError(path, std::string("header declares ") + std::to_string(n) + " " + what +
                                 " but the file has only " + std::to_string(size) + " bytes");
  };
  if (ext == ".off") {
    // The first line is the keyword alone, "[ST][C][N][4][n]OFF" (Geomview's OFF), or it and
    // BINARY: OpenMesh reads the counts from the lines after it, so a keyword line with
    // anything else on it would leave them unread.
    std::string first_line;
    std::getline(in, first_line);
    std::istringstream fl(first_line);
    std::string magic, binary_word, extra;
    fl >> magic >> binary_word >> extra;
    static const std::regex kKeyword("(ST)?C?N?4?n?OFF");
    if (!std::regex_match(magic, kKeyword)) {
      if (magic.find("OFF") == std::string::npos) throw InputError(path, "missing OFF header");
      throw InputError(path, "OFF header: '" + magic.substr(0, 20) + "' is not an OFF keyword ([ST][C][N][4][n]OFF)");
    }
    // Texture coordinates (ST), 4D (4) and n-dimensional (n) vertices are refused: OpenMesh's
    // reading of them does not follow the values the header implies (a fuzzed STOFF file made
    // it read a coordinate as a corner count and exhaust memory), so they cannot be checked.
    if (magic.find("ST") != std::string::npos || magic.find('4') != std::string::npos ||
        magic.find('n') != std::string::npos)
      throw InputError(path, "OFF variant '" + magic + "' is not supported (OFF, COFF, NOFF and CNOFF are)");
    if ((!binary_word.empty() && binary_word != "BINARY") || !extra.empty())
      throw InputError(path, "OFF header: the first line must hold only the keyword (and BINARY)");
    if (binary_word.empty()) {
      // The counts "nv nf ne" follow the keyword ("[ST][C][N][4][n]OFF"; nOFF first gives the
      // dimension), after any '#' comment lines. Every variant's counts are checked: OpenMesh
      // reserves what they claim.
      auto next = [&](std::string& tok) {
        while (in >> tok) {
          if (tok[0] != '#') return true;
          std::string rest;
          std::getline(in, rest);
        }
        return false;
      };
      auto whole = [&](const char* what) {
        std::string tok;
        if (!next(tok) || tok.size() > 12 || tok.find_first_not_of("0123456789") != std::string::npos)
          throw InputError(path, std::string("OFF header: the ") + what + " is not a whole number");
        return std::stoull(tok);
      };
      if (magic.find('n') != std::string::npos) (void)whole("dimension");
      const unsigned long long nv = whole("vertex count");
      const unsigned long long nf = whole("face count");
      (void)whole("edge count");  // read by OpenMesh too, so the walk below starts where it does
      too_many(nv, "vertices", 6);
      too_many(nf, "faces", 2);
      // OpenMesh reads the vertices and then the faces as a stream of values (a vertex with
      // colours from its own line), each face a corner count and that many indices, trusting
      // the count: a face claiming 444400000 corners, or -50, made it append handles until
      // memory ran out. Each count must be >= 0 and fit in the values left in the file. A
      // value that is not a whole number means the faces carry colours, which OpenMesh parses
      // its own way: the walk stops there.
      const bool colours = magic.find('C') != std::string::npos;
      const std::size_t per_vertex = (magic.find('n') != std::string::npos ? 0 : magic.find('4') != std::string::npos ? 4 : 3) +
                                     (magic.find('N') != std::string::npos ? 3 : 0) +
                                     (magic.starts_with("ST") ? 2 : 0);
      std::string line;
      if (colours || per_vertex < 3) {
        std::getline(in, line);  // the rest of the counts line
        for (unsigned long long left = nv; left > 0 && std::getline(in, line);) {
          std::istringstream ls(line);
          std::string first;
          if ((ls >> first) && first[0] != '#') --left;
        }
      }
      std::vector<std::string> values;
      for (std::string t; in >> t;) values.push_back(std::move(t));
      std::size_t at = 0;
      if (!(colours || per_vertex < 3)) at = static_cast<std::size_t>(std::min<unsigned long long>(nv * per_vertex, values.size()));
      for (unsigned long long f = 0; f < nf && at < values.size(); ++f) {
        const std::string& count = values[at++];
        if (count.size() > 1 && count[0] == '-' && count.find_first_not_of("0123456789", 1) == std::string::npos)
          throw InputError(path, "OFF face " + std::to_string(f) + " has a negative corner count " + count.substr(0, 20));
        if (count.size() > 12 || count.find_first_not_of("0123456789") != std::string::npos) break;
        const unsigned long long n = std::stoull(count);
        if (n > values.size() - at)
          throw InputError(path, "OFF face " + std::to_string(f) + " claims " + count +
                                     " corners but the file holds only " + std::to_string(values.size() - at) +
                                     " more values");
        at += static_cast<std::size_t>(n);
      }
    }
  } else if (ext == ".ply") {
    const PlyLayout layout = check_ply_header(path, in, size);
    check_ply_body(path, in, layout);
  } else if (ext == ".stl") {
    char head[84] = {};
    in.read(head, 84);
    const bool ascii = std::string(head, std::min<std::streamsize>(in.gcount(), 5)) == "solid";
    if (!ascii) {
      if (in.gcount() < 84) throw InputError(path, "truncated binary STL header");
      std::uint32_t n = 0;
      std::memcpy(&n, head + 80, 4);
      if (84 + 50ull * n > size)
        throw InputError(path, "binary STL declares " + std::to_string(n) +
                                   " triangles but the file is truncated");
    }
  }
}

struct SilenceOpenMesh {
  SilenceOpenMesh() {
    omerr().disable();
    omlog().disable();
    omout().disable();
  }
};

// The size of an existing, non-empty regular file.
std::uintmax_t checked_file_size(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "cannot read file size");
  if (size == 0) throw InputError(path, "file is empty");
  return size;
}

// Reads the file with OpenMesh, asking for vertex normals and texture coordinates; `opt`
// then says which of them the file had.
void read_with_openmesh(const std::string& path, OmMesh& om, OpenMesh::IO::Options& opt) {
  om.request_vertex_normals();
  om.request_vertex_texcoords2D();
  opt = OpenMesh::IO::Options::VertexNormal | OpenMesh::IO::Options::VertexTexCoord;
  bool ok = false;
  try {
    ok = OpenMesh::IO::read_mesh(om, path, opt);
  } catch (const std::bad_alloc&) {
    throw InputError(path, "out of memory while reading (absurd counts?)");
  } catch (const std::exception& e) {
    throw InputError(path, std::string("OpenMesh failed: ") + e.what());
  }
  if (!ok) throw InputError(path, "OpenMesh could not read the file (malformed or truncated)");
  if (om.n_faces() == 0) throw InputError(path, "contains no faces");
  if (om.n_vertices() >= 0xfffffff0u) throw InputError(path, "too many vertices");
}

// Positions (all finite) and the triangles among the faces (faces with fewer than three
// vertices are dropped, larger ones keep their first three).
void copy_positions_and_triangles(const std::string& path, const OmMesh& om, TriangleMesh& mesh) {
  mesh.positions.reserve(om.n_vertices());
  for (auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    const glm::vec3 q(p[0], p[1], p[2]);
    if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z))
      throw InputError(path, "vertex " + std::to_string(vh.idx()) + " has a NaN or infinite position");
    mesh.positions.push_back(q);
  }
  for (auto fh : om.faces()) {
    std::uint32_t tri[3];
    int k = 0;
    for (auto vh : om.fv_range(fh)) {
      if (k == 3) break;
      const int idx = vh.idx();
      if (idx < 0 || static_cast<std::size_t>(idx) >= mesh.positions.size())
        throw InputError(path, "face " + std::to_string(fh.idx()) + " indexes a missing vertex");
      tri[k++] = static_cast<std::uint32_t>(idx);
    }
    if (k != 3) continue;
    mesh.indices.insert(mesh.indices.end(), tri, tri + 3);
  }
  if (mesh.indices.empty()) throw InputError(path, "contains no triangles");
}

// Normals: the file's when present and sane, else area-weighted from the triangles.
void copy_or_compute_normals(const std::string& path, const OmMesh& om, const OpenMesh::IO::Options& opt,
                             TriangleMesh& mesh, LoadReport* report) {
  bool file_normals = opt.check(OpenMesh::IO::Options::VertexNormal);
  if (file_normals) {
    mesh.normals.reserve(mesh.positions.size());
    for (auto vh : om.vertices()) {
      const auto& n = om.normal(vh);
      glm::vec3 q(n[0], n[1], n[2]);
      const float len = glm::length(q);
      if (!(len > 1e-6f) || !std::isfinite(len)) {
        file_normals = false;
        break;
      }
      mesh.normals.push_back(q / len);
    }
    if (!file_normals && report) report->warn("bad normals in file, recomputed");
  }
  if (!file_normals) mesh.normals = area_weighted_normals(mesh.positions, mesh.indices);
}

// Texture coordinates: the file's (a non-finite pair becomes 0), else all 0.
void copy_uvs(const OmMesh& om, const OpenMesh::IO::Options& opt, TriangleMesh& mesh) {
  if (opt.check(OpenMesh::IO::Options::VertexTexCoord)) {
    for (auto vh : om.vertices()) {
      const auto& t = om.texcoord2D(vh);
      glm::vec2 uv(t[0], t[1]);
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
      mesh.uvs.push_back(uv);
    }
  } else {
    mesh.uvs.assign(mesh.positions.size(), glm::vec2(0.0f));
  }
}

// These formats carry no materials: the whole mesh is one object (named after the file)
// with one default material.
void add_single_object(const std::string& path, Scene& scene) {
  const std::size_t nt = scene.mesh.triangle_count();
  scene.mesh.triangle_material.assign(nt, 0);
  scene.mesh.triangle_object.assign(nt, 0);
  scene.materials.push_back(default_material());
  Object obj;
  obj.name = std::filesystem::path(path).stem().string();
  obj.triangle_count = static_cast<std::uint32_t>(nt);
  scene.objects.push_back(obj);
}

}  // namespace

Scene load_mesh_file(const std::string& path, LoadReport* report) {
  if (lower_ext(path) == ".obj") {  // OBJ carries materials: tinyobjloader reads it
    LoadReport local;
    Scene scene = load_obj(path, report ? *report : local);
    finish_scene(scene);
    return scene;
  }
  static const SilenceOpenMesh silence;
  const std::uintmax_t size = checked_file_size(path);
  check_declared_counts(path, lower_ext(path), size);
  OmMesh om;
  OpenMesh::IO::Options opt;
  read_with_openmesh(path, om, opt);

  Scene scene;
  scene.name = path;
  copy_positions_and_triangles(path, om, scene.mesh);
  copy_or_compute_normals(path, om, opt, scene.mesh, report);
  copy_uvs(om, opt, scene.mesh);
  add_single_object(path, scene);
  finish_scene(scene);
  return scene;
}

}  // namespace speculum
