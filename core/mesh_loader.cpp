// PLY/OFF/STL through OpenMesh, OBJ through core/obj_loader.h (see mesh_loader.h). Headers with element counts are
// checked against the file size first, so an absurd count cannot make OpenMesh reserve
// gigabytes; OpenMesh's own stream logging is silenced (the CLI prints one line).
#include "core/mesh_loader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
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

// A strict PLY header check: OpenMesh's PLY reader reads out of bounds on some malformed
// headers (found by mutating tests/data/good/tetra.ply under ASan), so only well-formed
// headers reach it.
void check_ply_header(const std::string& path, std::istream& in, std::uintmax_t size) {
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
      return;
    }
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        bad();
      format = true;
      binary = w[1] != "ascii";
    } else if (w[0] == "element") {
      if (w.size() != 3 || w[2].find_first_not_of("0123456789") != std::string::npos || w[2].size() > 12) bad();
      const unsigned long long n = std::stoull(w[2]);
      if (n > size / (binary ? 1 : 2))
        throw InputError(path, "header declares " + w[2] + " " + w[1] + " elements but the file has only " +
                                   std::to_string(size) + " bytes");
      element = true;
      vertex = vertex || w[1] == "vertex";
      face = face || w[1] == "face";
    } else if (w[0] == "property") {
      if (!element) bad();
      if (w.size() == 3) {
        if (!kTypes.count(w[1])) bad();
      } else if (w.size() == 5 && w[1] == "list") {
        if (!kTypes.count(w[2]) || !kTypes.count(w[3])) bad();
      } else {
        bad();
      }
    } else {
      bad();
    }
  }
  throw InputError(path, "PLY header has no end_header line");
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
    std::string magic;
    in >> magic;
    if (magic.find("OFF") == std::string::npos) throw InputError(path, "missing OFF header");
    if (magic.find("ST") != std::string::npos || magic.find("n") != std::string::npos ||
        magic.find("4") != std::string::npos) {
      // Exotic OFF variants: let OpenMesh judge the header.
    } else if (magic.find("BINARY") == std::string::npos) {
      long long nv = -1, nf = -1, ne = -1;
      in >> nv >> nf >> ne;
      // Headers with comments are left to OpenMesh; a plain counts line is checked here.
      if (in && nv >= 0 && nf >= 0) {
        too_many(static_cast<unsigned long long>(nv), "vertices", 6);
        too_many(static_cast<unsigned long long>(nf), "faces", 8);
      }
    }
  } else if (ext == ".ply") {
    check_ply_header(path, in, size);
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
