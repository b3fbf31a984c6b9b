// The per-triangle records of the `gbuffer` node: see gbuffer_triangles.h.
#include "raster/gbuffer_triangles.h"

#include "core/error.h"

namespace speculum::raster {
namespace {
constexpr std::size_t kTriangleChunk = 4096;
}  // namespace

GBufferTriangles::GBufferTriangles(par::Executor& executor, const Scene& scene) {
  const TriangleMesh& m = scene.mesh;
  const std::size_t n = m.triangle_count();
  if (m.normals.size() != m.positions.size() || m.uvs.size() != m.positions.size() ||
      m.triangle_material.size() != n)
    throw InputError(scene.name, "mesh attribute arrays do not match its vertex/triangle counts");
  TriangleRecord* out = memory_.reserve<TriangleRecord>(n > 0 ? n : 1);
  executor.parallel_for("gbuffer.prepare", n, kTriangleChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) out[t] = triangle_record(m, std::uint32_t(t));
  });
  materials_ = m.triangle_material;
  records_ = out;
  count_ = n;
  vertices_ = m.vertex_count();
}

const GBufferTriangles* FrameRecords::of(par::Executor& executor, const Scene& scene) {
  if (scene.mesh.triangle_count() > kMaxFrameRecordTriangles) return nullptr;
  if (mesh_ != &scene.mesh) {
    records_ = GBufferTriangles(executor, scene);
    mesh_ = &scene.mesh;
  }
  return &records_;
}

}  // namespace speculum::raster
