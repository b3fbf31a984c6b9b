// Scene object → OpenMesh mesh with welding (see halfedge_mesh.h).
#include "core/mesh_processing/halfedge_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>

#include <glm/geometric.hpp>

#include <OpenMesh/Core/System/omstream.hh>

namespace speculum::mesh {

std::string MeshBuildReport::describe(const std::string& object) const {
  std::string s = "object '" + object + "': " + std::to_string(soup_vertices - welded_vertices) + " vertices (" +
                  std::to_string(welded_vertices) + " welded)";
  if (degenerate_faces) s += ", " + std::to_string(degenerate_faces) + " degenerate faces left out";
  if (non_manifold_faces) s += ", " + std::to_string(non_manifold_faces) + " non-manifold faces left out";
  return s;
}

namespace {

using Cell = std::array<std::int64_t, 3>;

// OpenMesh prints "complex edge" for every face it rejects; the report counts them instead
// (the CLI prints one line).
void silence_openmesh() {
  static const bool once = [] {
    omerr().disable();
    omlog().disable();
    return true;
  }();
  (void)once;
}

}  // namespace

ObjectMesh build_object_mesh(const Scene& scene, std::uint32_t object, Weld weld, double tolerance) {
  const TriangleMesh& soup = scene.mesh;
  const Object& o = scene.objects.at(object);
  silence_openmesh();
  ObjectMesh out;
  out.object = object;
  // The object's soup vertex range (procedural objects and loaders store them contiguously,
  // but nothing requires it: take the min and max index its triangles use).
  std::uint32_t lo = ~0u, hi = 0;
  for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      lo = std::min(lo, soup.indices[3 * t + k]);
      hi = std::max(hi, soup.indices[3 * t + k]);
    }
  if (o.triangle_count == 0) return out;
  out.first_vertex = lo;
  out.mesh_vertex.assign(hi - lo + 1, -1);
  std::vector<std::uint8_t> used(hi - lo + 1, 0);
  for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) used[soup.indices[3 * t + k] - lo] = 1;

  Bounds b;
  for (std::uint32_t v = lo; v <= hi; ++v)
    if (used[v - lo]) b.grow(soup.positions[v]);
  const double cell = std::max(1e-30, tolerance * static_cast<double>(glm::length(b.extent())));
  // Grid cells of size `cell`; a vertex welds to the first earlier vertex within `cell` in
  // its own or a neighbouring cell, so the result depends only on the soup's vertex order.
  std::map<Cell, std::vector<int>> grid;
  auto cell_of = [&](const glm::dvec3& p) {
    return Cell{static_cast<std::int64_t>(std::floor(p.x / cell)), static_cast<std::int64_t>(std::floor(p.y / cell)),
                static_cast<std::int64_t>(std::floor(p.z / cell))};
  };
  for (std::uint32_t v = lo; v <= hi; ++v) {
    if (!used[v - lo]) continue;
    ++out.report.soup_vertices;
    const glm::dvec3 p(soup.positions[v]);
    int found = -1;
    if (weld == Weld::Positions) {
      const Cell c = cell_of(p);
      for (int dx = -1; dx <= 1 && found < 0; ++dx)
        for (int dy = -1; dy <= 1 && found < 0; ++dy)
          for (int dz = -1; dz <= 1 && found < 0; ++dz) {
            auto it = grid.find({c[0] + dx, c[1] + dy, c[2] + dz});
            if (it == grid.end()) continue;
            for (int m : it->second)
              if (glm::length(to_glm(out.mesh.point(OpenMesh::VertexHandle(m))) - p) <= cell) {
                found = m;
                break;
              }
          }
    }
    if (found >= 0) {
      out.mesh_vertex[v - lo] = found;
      ++out.report.welded_vertices;
      continue;
    }
    const auto vh = out.mesh.add_vertex(OpenMesh::Vec3d(p.x, p.y, p.z));
    const glm::vec2 uv = v < soup.uvs.size() ? soup.uvs[v] : glm::vec2(0.0f);
    out.mesh.set_texcoord2D(vh, OpenMesh::Vec2f(uv.x, uv.y));
    out.mesh_vertex[v - lo] = vh.idx();
    out.soup_vertex.push_back(v);
    if (weld == Weld::Positions) grid[cell_of(p)].push_back(vh.idx());
  }

  for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t) {
    const int a = out.mesh_vertex[soup.indices[3 * t] - lo];
    const int b2 = out.mesh_vertex[soup.indices[3 * t + 1] - lo];
    const int c = out.mesh_vertex[soup.indices[3 * t + 2] - lo];
    if (a == b2 || b2 == c || a == c) {
      ++out.report.degenerate_faces;
      continue;
    }
    // OpenMesh prints "complex edge/vertex" to its error stream and returns an invalid
    // handle; the count is what the report gives instead.
    const auto fh = out.mesh.add_face(OpenMesh::VertexHandle(a), OpenMesh::VertexHandle(b2), OpenMesh::VertexHandle(c));
    if (!fh.is_valid()) {
      ++out.report.non_manifold_faces;
      continue;
    }
    out.soup_triangle.push_back(t);
  }
  out.mesh.update_face_normals();
  out.mesh.update_vertex_normals();
  // Unwelded meshes keep the soup's own (authored or smooth) normals; welded ones use
  // OpenMesh's, since a welded vertex stands for several soup normals.
  if (weld == Weld::Indices)
    for (const auto vh : out.mesh.vertices()) {
      const glm::vec3 n = soup.normals[out.soup_vertex[vh.idx()]];
      out.mesh.set_normal(vh, OpenMesh::Vec3d(n.x, n.y, n.z));
    }
  return out;
}

}  // namespace speculum::mesh
