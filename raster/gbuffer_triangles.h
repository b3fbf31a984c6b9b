// The scene-static input of the `gbuffer` node: one interleaved 96-byte record per triangle
// (corner positions, normals, uvs) and its material index built once per static scene, like a
// GPU's vertex-buffer upload.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/page_buffer.h"

namespace speculum::raster {

// One corner of a triangle: its vertex's position, normal and uv, eight floats, the order of
// the G-buffer's interpolated attributes (so one 8-wide register interpolates a sample).
struct TriangleCorner {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};
static_assert(sizeof(TriangleCorner) == 32);

// The three corners of one triangle, copied bit for bit from the mesh arrays, so the resolve
// reads 96 contiguous bytes (two cache lines, one prefetchable unit, shared with the
// neighbouring records) instead of chasing indices → vertex arrays through five separate
// allocations. The material index sits in a separate array: in the record it would pad it to
// 128 bytes, a third more memory traffic for the resolve.
struct alignas(32) TriangleRecord {
  TriangleCorner corner[3];
  // b0·a0 + b1·a1 + b2·a2 of a corner attribute (b = barycentrics (b1, b2), b0 = 1 − b1 − b2).
  template <class T>
  T lerp(T TriangleCorner::*attribute, float b0, glm::vec2 b) const {
    return b0 * (corner[0].*attribute) + b.x * (corner[1].*attribute) + b.y * (corner[2].*attribute);
  }
};
static_assert(sizeof(TriangleRecord) == 96);

// Triangle t's record, read from the mesh arrays (indices → corners).
inline TriangleRecord triangle_record(const TriangleMesh& m, std::uint32_t t) {
  TriangleRecord r;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t v = m.indices[3 * std::size_t(t) + k];
    r.corner[k] = {m.positions[v], m.normals[v], m.uvs[v]};
  }
  return r;
}


// The records of one mesh in huge-page-backed memory (random gathers over 100+ MB would
// otherwise miss the TLB on nearly every sample). Valid only while the mesh is unchanged:
// rebuild it after editing the scene.
class GBufferTriangles {
 public:
  GBufferTriangles() = default;
  // Builds the records of scene.mesh (named launch "gbuffer.prepare").
  GBufferTriangles(par::Executor& executor, const Scene& scene);

  std::size_t size() const { return count_; }
  const TriangleRecord* data() const { return records_; }
  const TriangleRecord& operator[](std::size_t t) const { return records_[t]; }
  // Triangle t's material index (the mesh's triangle_material, copied).
  const std::uint32_t* materials() const { return materials_.data(); }
  // True if built from a mesh with this many triangles and vertices (a cheap guard against
  // passing the records of another scene).
  bool matches(const TriangleMesh& mesh) const {
    return count_ == mesh.triangle_count() && vertices_ == mesh.vertex_count();
  }

 private:
  par::PageBuffer memory_;
  const TriangleRecord* records_ = nullptr;
  std::vector<std::uint32_t> materials_;
  std::size_t count_ = 0;
  std::size_t vertices_ = 0;
};

// A frame builds records (96 bytes a triangle) for meshes of at most this many triangles
// (384 MiB of records); larger meshes resolve from the mesh arrays.
constexpr std::size_t kMaxFrameRecordTriangles = std::size_t(1) << 22;

// The records a frame's resolves read: built by the first call for a mesh and kept for the
// calls after it on that mesh (so a pass resolving many images pays the build once); none
// (null) for a mesh over kMaxFrameRecordTriangles.
class FrameRecords {
 public:
  const GBufferTriangles* of(par::Executor& executor, const Scene& scene);

 private:
  GBufferTriangles records_;
  const TriangleMesh* mesh_ = nullptr;
};

}  // namespace speculum::raster
