// Per-sample mean curvature (see pixel_curvature.h; ROGER §5.2.2).
#include "raster/pixel_curvature.h"

#include <glm/geometric.hpp>

#include "core/mesh_processing/mean_curvature.h"

namespace speculum::raster {

ImageF pixel_mean_curvature(par::Executor& ex, const Scene& scene, const std::vector<float>& per_vertex,
                            const VisibilityBuffer& vis, const glm::vec3& eye) {
  ImageF out(vis.width, vis.height, 0.0f);
  const TriangleMesh& m = scene.mesh;
  ex.parallel_for("pixel_curvature", out.pixels.size(), 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t t = vis.triangle.pixels[i];
      if (t == kNoId || 3 * std::size_t(t) + 2 >= m.indices.size()) continue;
      const glm::vec2 bc = vis.bary.pixels[i];
      const float h = mesh::interpolate_at(m, per_vertex, t, bc.x, bc.y);
      // The per-vertex sign follows the winding's normal; seen from its back side the same
      // surface bends the other way.
      const std::uint32_t* idx = &m.indices[3 * std::size_t(t)];
      const glm::vec3 a = m.positions[idx[0]];
      const glm::vec3 n = glm::cross(m.positions[idx[1]] - a, m.positions[idx[2]] - a);
      out.pixels[i] = glm::dot(n, eye - a) >= 0.0f ? h : -h;
    }
  });
  return out;
}

ImageF PixelCurvaturePass::operator()(par::NodeContext& c, const VisibilityBuffer& visibility) const {
  const std::vector<float> per_vertex = mesh::scene_mean_curvature(*scene);
  c.count("vertices", double(per_vertex.size()));
  return pixel_mean_curvature(c.executor(), *scene, per_vertex, visibility, eye);
}

}  // namespace speculum::raster
