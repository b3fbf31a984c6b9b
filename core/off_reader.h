// Geomview's OFF format ("Object File Format", Geomview manual, OOGL file formats: OFF and
// Binary format), read by our own parser rather than OpenMesh's: every count is checked
// against the bytes the file still holds before anything is reserved, so no input can make the
// reader allocate more than a small multiple of the file's size.
//
// Read: the header keyword [ST][C][N][4][n]OFF (optional, as the manual allows), with BINARY
// after it for the big-endian binary form; Ndim for nOFF (3 only, or 4nOFF's homogeneous 3+1);
// vertex positions, normals (N), colours (C, skipped) and texture coordinates (ST), in that
// order; faces "Nv v0 .. v(Nv-1) [colour]" fan-triangulated, the colour running to the end of
// the line (ASCII) or given by its own count (binary).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace speculum {

struct OffMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;    // one per vertex with N, else empty (not normalised)
  std::vector<glm::vec2> uvs;        // one per vertex with ST, else empty
  std::vector<std::uint32_t> indices;  // 3 per triangle, faces fan-triangulated from corner 0
  std::uint64_t faces = 0;              // as declared (and read)
  std::uint64_t short_faces = 0;       // faces with fewer than 3 corners (left out)
  std::uint64_t degenerate_triangles = 0;  // fan triangles repeating a corner (left out)
};

// Parses `bytes` (the whole file). Throws InputError(path, problem) naming the first problem:
// a count that the file cannot hold or past kMaxSceneVertices / kMaxSceneTriangles, a value that is not a number, a non-finite vertex, an
// index out of range, truncated data, an unsupported dimension.
OffMesh read_off(const std::string& path, std::string_view bytes);

}  // namespace speculum
