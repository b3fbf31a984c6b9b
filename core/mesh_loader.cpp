// PLY/STL through OpenMesh, OFF through our own reader (core/off_reader.h), OBJ through
// core/obj_loader.h (see mesh_loader.h). PLY and STL headers with element counts are checked
// against the file size first, so an absurd count cannot make OpenMesh reserve gigabytes;
// OpenMesh's own stream logging is silenced (the CLI prints one line).
#include "core/mesh_loader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
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
#include "core/off_reader.h"

namespace speculum {
namespace {

using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

constexpr std::uintmax_t kMaxOffFileBytes = std::uintmax_t{2} << 30;

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
  bool coordinate = false;  // x, y or z of a vertex
  bool item_float = false, item_signed = false;
  bool corners = false;  // a face's vertex_indices (or vertex_index) list
};
struct PlyElement {
  unsigned long long count = 0;
  bool vertex = false;
  std::vector<PlyProperty> properties;
  bool face = false;
};
// What the body walk learned: faces with fewer than 3 corners (OpenMesh drops them) and
// the triangles the others make when fanned.
struct PlyFaces {
  unsigned long long short_faces = 0, triangles = 0;
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
      if ((w[1] == "vertex" && n > kMaxSceneVertices) || (w[1] == "face" && n > kMaxSceneTriangles))
        throw InputError(path, "header declares " + w[2] + " " + w[1] + " elements: more than the limit of " +
                                   std::to_string(w[1] == "vertex" ? kMaxSceneVertices : kMaxSceneTriangles) +
                                   (w[1] == "vertex" ? " (2^25)" : " (2^24)"));
      element = true;
      layout.elements.push_back({n, w[1] == "vertex", {}, w[1] == "face"});
      vertex = vertex || w[1] == "vertex";
      face = face || w[1] == "face";
    } else if (w[0] == "property") {
      if (!element) bad();
      if (w.size() == 3) {
        if (!kTypes.count(w[1])) bad();
        layout.elements.back().properties.push_back(
            {false, 0, ply_type_bytes(w[1]), false,
             layout.elements.back().vertex && (w[2] == "x" || w[2] == "y" || w[2] == "z"),
             w[1].find("float") != std::string::npos || w[1] == "double", w[1][0] != 'u', false});
      } else if (w.size() == 5 && w[1] == "list") {
        if (!kTypes.count(w[2]) || !kTypes.count(w[3])) bad();
        if (w[2] == "float" || w[2] == "double" || w[2] == "float32" || w[2] == "float64") bad();
        const bool face_corners = w[4] == "vertex_indices" || w[4] == "vertex_index";
        if (face_corners && (w[3].find("float") != std::string::npos || w[3] == "double")) bad();
        layout.elements.back().properties.push_back(
            {true, ply_type_bytes(w[2]), ply_type_bytes(w[3]), w[2][0] != 'u', false,
             w[3].find("float") != std::string::npos || w[3] == "double", w[3][0] != 'u',
             face_corners && layout.elements.back().face});
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
PlyFaces check_ply_body(const std::string& path, std::istream& in, const PlyLayout& layout) {
  auto truncated = [&](const char* what) {
    throw InputError(path, std::string("PLY data truncated or malformed: ") + what);
  };
  unsigned long long vertices = 0;
  for (const PlyElement& e : layout.elements)
    if (e.vertex) vertices += e.count;
  PlyFaces faces;
  // A face's corner `v` (its `k`th) must name a vertex the file has.
  auto corner = [&](long long v, unsigned long long face, unsigned long long k) {
    if (v < 0 || static_cast<unsigned long long>(v) >= vertices)
      throw InputError(path, "face " + std::to_string(face) + " corner " + std::to_string(k) + " indexes vertex " +
                                 std::to_string(v) + ", the file has " + std::to_string(vertices) + " vertices");
  };
  auto count_face = [&](unsigned long long corners) {
    if (corners < 3) ++faces.short_faces;
    else faces.triangles += corners - 2;
  };
  if (!layout.binary) {
    std::string tok;
    // One ASCII value of the property's type: an integer within its type's range (PLY
    // writes integer types as integers), or a number for float types.
    auto value = [&](bool is_float, bool is_signed, int bytes, const char* what) -> double {
      if (!(in >> tok)) truncated("fewer values than the header declares");
      char* stop = nullptr;
      errno = 0;
      if (is_float) {
        const double x = std::strtod(tok.c_str(), &stop);
        if (*stop != '\0' || stop == tok.c_str())
          throw InputError(path, std::string(what) + " '" + tok.substr(0, 20) + "' is not a number");
        return x;
      }
      const long long x = std::strtoll(tok.c_str(), &stop, 10);
      const long long lo = is_signed ? -(1ll << (8 * bytes - 1)) : 0;
      const long long hi = is_signed ? (1ll << (8 * bytes - 1)) - 1 : (1ll << (8 * bytes)) - 1;
      if (*stop != '\0' || stop == tok.c_str() || errno == ERANGE || x < lo || x > hi)
        throw InputError(path, std::string(what) + " '" + tok.substr(0, 20) + "' is not an integer of its declared type");
      return static_cast<double>(x);
    };
    for (const PlyElement& e : layout.elements)
      for (unsigned long long i = 0; i < e.count; ++i)
        for (const PlyProperty& p : e.properties) {
          if (!p.list) {
            const double x = value(p.item_float, p.item_signed, p.item_bytes, "PLY value");
            // OpenMesh's stream read stops at a value past a float's range and the faces go
            // unread ("no faces"): name the vertex instead.
            if (p.coordinate && !(std::fabs(x) < double(std::numeric_limits<float>::max())))
              throw InputError(path, "non-finite vertex " + std::to_string(i) + " (coordinate '" + tok.substr(0, 20) +
                                         "' is NaN, infinite or overflows a float)");
            continue;
          }
          if (!(in >> tok)) truncated("fewer values than the header declares");
          if (tok.empty() || tok.size() > 9 || tok.find_first_not_of("0123456789") != std::string::npos)
            throw InputError(path, "PLY list count '" + tok.substr(0, 20) + "' is not a whole number below 10^9");
          const unsigned long n = std::stoul(tok);
          if (p.corners) count_face(n);
          for (unsigned long k = 0; k < n; ++k) {
            const double x = value(p.item_float, p.item_signed, p.item_bytes, "PLY list item");
            if (p.corners) corner(static_cast<long long>(x), i, k);
          }
        }
    return faces;
  }
  const std::string body{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::size_t at = 0;
  auto need = [&](unsigned long long bytes) {
    if (bytes > body.size() - at) truncated("fewer bytes than the header declares");
  };
  // An integer of `bytes` bytes at `at`, in the file's byte order.
  auto integer = [&](int bytes, bool is_signed) -> long long {
    unsigned char b[8] = {};
    bytes = std::clamp(bytes, 1, 8);  // PLY integers are 1-8 bytes; stated for the compiler's bounds
    std::memcpy(b, body.data() + at, static_cast<std::size_t>(bytes));
    if (layout.big_endian) std::reverse(b, b + bytes);
    std::uint64_t raw = 0;
    for (int k = bytes - 1; k >= 0; --k) raw = (raw << 8) | b[k];
    if (is_signed && (raw >> (8 * bytes - 1)) & 1u) return static_cast<long long>(raw) - (1ll << (8 * bytes - 1)) * 2;
    return static_cast<long long>(raw);
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
        const long long n = integer(p.count_bytes, p.count_signed);
        at += static_cast<std::size_t>(p.count_bytes);
        if (n < 0) throw InputError(path, "PLY list count is negative");
        need(static_cast<unsigned long long>(n) * static_cast<unsigned long long>(p.item_bytes));
        if (p.corners) {
          count_face(static_cast<unsigned long long>(n));
          for (long long k = 0; k < n; ++k)
            corner(integer(p.item_bytes, p.item_signed), i, static_cast<unsigned long long>(k)),
                at += static_cast<std::size_t>(p.item_bytes);
        } else {
          at += static_cast<std::size_t>(n) * static_cast<std::size_t>(p.item_bytes);
        }
      }
  }
  return faces;
}

// An ASCII STL walked before OpenMesh reads it, which takes a word where a number belongs as
// 0 and keeps only three vertices of a facet: the grammar of the format ("solid name",
// then per facet "facet normal ni nj nk", "outer loop", exactly three "vertex x y z",
// "endloop", "endfacet"; "endsolid name"), every vertex coordinate a finite number.
void check_ascii_stl(const std::string& path, std::istream& in) {
  std::string line;
  unsigned long long lineno = 0, facets = 0;
  enum { kSolid, kFacet, kOuter, kVertex, kEndLoop, kEndFacet } want = kSolid;
  int vertices = 0;
  auto bad = [&](const std::string& what) {
    throw InputError(path, "ASCII STL line " + std::to_string(lineno) + ": " + what);
  };
  auto numbers = [&](std::istringstream& ls, const char* what, bool finite) {
    for (int k = 0; k < 3; ++k) {
      std::string tok;
      if (!(ls >> tok)) bad(std::string(what) + " needs 3 numbers");
      char* stop = nullptr;
      const double x = std::strtod(tok.c_str(), &stop);
      if (*stop != '\0' || stop == tok.c_str()) bad(std::string(what) + " '" + tok.substr(0, 20) + "' is not a number");
      if (finite && !(std::fabs(x) < double(std::numeric_limits<float>::max())))
        bad("non-finite vertex (coordinate '" + tok.substr(0, 20) + "' is NaN, infinite or overflows a float)");
    }
  };
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string w;
    if (!(ls >> w)) continue;
    std::transform(w.begin(), w.end(), w.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    std::string w2;
    switch (want) {
      case kSolid:
        if (w != "solid") bad("expected 'solid', found '" + w.substr(0, 20) + "'");
        want = kFacet;
        continue;  // the rest of the line is the solid's name
      case kFacet:
        if (w == "endsolid") {
          want = kSolid;
          continue;
        }
        if (w != "facet" || !(ls >> w2) || w2 != "normal") bad("expected 'facet normal' or 'endsolid'");
        numbers(ls, "facet normal", false);  // the normal is recomputed: NaN is harmless
        if (++facets > kMaxSceneTriangles)
          throw InputError(path, "more than the limit of " + std::to_string(kMaxSceneTriangles) + " facets (2^24)");
        want = kOuter;
        break;
      case kOuter:
        if (w != "outer" || !(ls >> w2) || w2 != "loop") bad("expected 'outer loop'");
        want = kVertex;
        vertices = 0;
        break;
      case kVertex:
        if (w == "endloop") bad("a facet has " + std::to_string(vertices) + " vertices, not 3");
        if (w != "vertex") bad("expected 'vertex'");
        numbers(ls, "vertex", true);
        if (++vertices == 3) want = kEndLoop;
        break;
      case kEndLoop:
        if (w == "vertex") bad("a facet has more than 3 vertices");
        if (w != "endloop") bad("expected 'endloop'");
        want = kEndFacet;
        break;
      case kEndFacet:
        if (w != "endfacet") bad("expected 'endfacet'");
        want = kFacet;
        break;
    }
    if (ls >> w2) bad("unexpected '" + w2.substr(0, 20) + "' at the end of the line");
  }
  // A file that stops between facets without "endsolid" is accepted (some exporters omit it).
  if (want != kSolid && want != kFacet) throw InputError(path, "ASCII STL is truncated inside a facet");
  if (facets == 0) throw InputError(path, "contains no faces (no facets)");
}

// Rejects headers that promise more elements than the file could hold (each vertex or
// face takes at least a few bytes in every encoding) and bodies that break the format.
PlyFaces check_declared_counts(const std::string& path, const std::string& ext, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  if (ext == ".ply") {
    const PlyLayout layout = check_ply_header(path, in, size);
    return check_ply_body(path, in, layout);
  }
  if (ext == ".stl") {
    char head[84] = {};
    in.read(head, 84);
    const bool solid = std::string(head, std::min<std::streamsize>(in.gcount(), 5)) == "solid";
    std::uint32_t n = 0;
    if (in.gcount() == 84) std::memcpy(&n, head + 80, 4);
    // Binary exactly when the size is that of the declared triangles (how OpenMesh tells
    // them apart too): binary files may begin with "solid" as well.
    const bool binary = in.gcount() == 84 && 84 + 50ull * n == size;
    if (!binary && solid) {
      in.clear();
      in.seekg(0);
      check_ascii_stl(path, in);
    } else if (!binary) {
      if (in.gcount() < 84) throw InputError(path, "truncated binary STL header");
      if (n > kMaxSceneTriangles)
        throw InputError(path, "binary STL declares " + std::to_string(n) + " triangles: more than the limit of " +
                                   std::to_string(kMaxSceneTriangles) + " (2^24)");
      throw InputError(path, "binary STL declares " + std::to_string(n) + " triangles (" +
                                 std::to_string(84 + 50ull * n) + " bytes) but the file has " + std::to_string(size) +
                                 (84 + 50ull * n > size ? " (truncated)" : ""));
    } else if (n > kMaxSceneTriangles) {
      throw InputError(path, "binary STL declares " + std::to_string(n) + " triangles: more than the limit of " +
                                 std::to_string(kMaxSceneTriangles) + " (2^24)");
    }
  }
  return {};
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
    // A stream stores +-FLT_MAX for a value past a float's range: overflow, as infinity is.
    constexpr float kMax = std::numeric_limits<float>::max();
    if (!(std::fabs(q.x) < kMax && std::fabs(q.y) < kMax && std::fabs(q.z) < kMax))
      throw InputError(path, "non-finite vertex " + std::to_string(vh.idx()) +
                                 " (a coordinate is NaN, infinite or overflows a float)");
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

// OFF through core/off_reader.h. OpenMesh's OFF reader trusts the corner count of every face
// and walks vertex values its own way (a fuzzed file made it append handles until memory ran
// out), so no guard in front of it could be proven to bound what it allocates; our reader
// checks every count against the bytes left before reserving anything.
void load_off_mesh(const std::string& path, std::uintmax_t size, TriangleMesh& mesh, LoadReport* report) {
  if (size > kMaxOffFileBytes) throw InputError(path, "file is too large (over 2 GiB)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open file");
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  OffMesh off = read_off(path, bytes);
  bytes = std::string();
  if (off.indices.empty())
    throw InputError(path, off.faces == 0 ? "contains no faces"
                                          : "contains no triangles (every face has fewer than 3 distinct corners)");
  if (report && off.short_faces)
    report->warn(std::to_string(off.short_faces) + " faces with fewer than 3 corners left out");
  if (report && off.degenerate_triangles)
    report->warn(std::to_string(off.degenerate_triangles) + " triangles repeating a corner left out");
  mesh.positions = std::move(off.positions);
  mesh.indices = std::move(off.indices);
  bool file_normals = !off.normals.empty();
  for (glm::vec3& n : off.normals) {
    const float len = glm::length(n);
    if (!(len > 1e-6f) || !std::isfinite(len)) {
      file_normals = false;
      if (report) report->warn("bad normals in file, recomputed");
      break;
    }
    n /= len;
  }
  mesh.normals = file_normals ? std::move(off.normals) : area_weighted_normals(mesh.positions, mesh.indices);
  if (off.uvs.empty()) {
    mesh.uvs.assign(mesh.positions.size(), glm::vec2(0.0f));
  } else {
    for (glm::vec2& uv : off.uvs)
      if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
    mesh.uvs = std::move(off.uvs);
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
  const std::uintmax_t size = checked_file_size(path);
  if (lower_ext(path) == ".off") {
    Scene scene;
    scene.name = path;
    load_off_mesh(path, size, scene.mesh, report);
    add_single_object(path, scene);
    finish_scene(scene);
    return scene;
  }
  static const SilenceOpenMesh silence;
  const PlyFaces ply = check_declared_counts(path, lower_ext(path), size);
  OmMesh om;
  OpenMesh::IO::Options opt;
  read_with_openmesh(path, om, opt);
  if (report && ply.short_faces)
    report->warn(std::to_string(ply.short_faces) + " faces with fewer than 3 corners left out");
  // OpenMesh refuses faces it cannot add to its half-edge mesh (a corner repeated, say):
  // say how many rather than render holes quietly.
  if (report && ply.triangles > om.n_faces())
    report->warn(std::to_string(ply.triangles - om.n_faces()) +
                 " triangles left out (degenerate faces OpenMesh refuses)");

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
