// Groups of consecutive triangles with their world-space boxes, so that a view renders only
// the groups that can reach it: a group whose box lies wholly outside one plane of the view's
// clip volume holds only triangles that triangle setup would drop (every vertex outside that
// plane), so skipping it before setup changes no output byte. Procedural and loaded meshes
// store neighbouring triangles together, so the boxes are tight.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>

#include "core/scene.h"
#include "parallel/executor.h"

namespace speculum::raster {

struct TriangleGroups {
  // Triangles per group; divides the rasterizer's setup chunk, so a chunk holds whole groups.
  static constexpr std::uint32_t kSize = 64;
  std::vector<Bounds> boxes;  // group g: triangles [g·kSize, min((g + 1)·kSize, count))
  std::size_t triangles = 0;  // of the mesh they were built from
};

// The groups of `mesh`, built in parallel (one pass over its triangles).
TriangleGroups triangle_groups(par::Executor& executor, const TriangleMesh& mesh);

// outside[g] = 1 for each group whose box lies wholly outside one plane of the clip volume of
// `view_projection` (the planes of ScreenVertex::outcode, x, y, z against ±w), by a margin
// that covers the float rounding of any vertex's clip coordinates inside the box; 0 otherwise.
void groups_outside(const TriangleGroups& groups, const glm::mat4& view_projection,
                    std::vector<std::uint8_t>& outside);

}  // namespace speculum::raster
