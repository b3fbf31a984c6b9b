// A scene object as an OpenMesh halfedge mesh: the connectivity the mesh-processing passes
// (curvature, star-shapedness, subdivision) need and the triangle soup lacks. Coincident
// vertices are welded (the soup splits them at uv and normal seams); faces OpenMesh cannot
// add without breaking manifoldness are reported and left out, never a crash.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "core/scene.h"

namespace speculum::mesh {

// Double-precision points (the cotangent weights of thin triangles lose digits in float);
// per-vertex normal and uv travel with the vertices through subdivision.
struct SpeculumMeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  using TexCoord2D = OpenMesh::Vec2f;
  VertexAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::TexCoord2D |
                   OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Normal | OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};
using HalfedgeMesh = OpenMesh::TriMesh_ArrayKernelT<SpeculumMeshTraits>;

enum class Weld : std::uint8_t {
  Positions,  // vertices closer than the tolerance become one (closes uv and normal seams)
  Indices,    // only the soup's own shared indices (keeps seams: uv stays single-valued)
};

struct MeshBuildReport {
  std::size_t soup_vertices = 0;       // distinct soup vertices the object's faces use
  std::size_t welded_vertices = 0;     // soup vertices merged into another one
  std::size_t degenerate_faces = 0;    // two corners welded together: left out
  std::size_t non_manifold_faces = 0;  // rejected by OpenMesh (complex edge/vertex): left out
  bool manifold() const { return non_manifold_faces == 0; }
  // One line: "object 'x': 1240 vertices (380 welded), 2 non-manifold faces left out".
  std::string describe(const std::string& object) const;
};

struct ObjectMesh {
  HalfedgeMesh mesh;
  std::uint32_t object = 0;
  // For mesh vertex i, the soup vertex it was first built from; and for every soup vertex
  // of the object (indexed from `first_vertex`), its mesh vertex (-1: not used by a face).
  std::vector<std::uint32_t> soup_vertex;
  std::uint32_t first_vertex = 0;
  std::vector<int> mesh_vertex;
  // For mesh face f, the soup triangle it came from.
  std::vector<std::uint32_t> soup_triangle;
  MeshBuildReport report;
};

// The soup vertices object `object` uses (its triangles' index range) as an OpenMesh mesh
// with vertex normals (area-weighted from the faces), uvs and face normals. `tolerance` is
// relative to the object's bounding-box diagonal (Weld::Positions only).
ObjectMesh build_object_mesh(const Scene& scene, std::uint32_t object, Weld weld = Weld::Positions,
                             double tolerance = 1e-6);

inline glm::dvec3 to_glm(const OpenMesh::Vec3d& p) { return {p[0], p[1], p[2]}; }

}  // namespace speculum::mesh
