// Triangle groups for skipping what a view cannot see: see triangle_groups.h.
#include "raster/triangle_groups.h"

#include <algorithm>
#include <cmath>

namespace speculum::raster {

TriangleGroups triangle_groups(par::Executor& executor, const TriangleMesh& mesh) {
  TriangleGroups g;
  g.triangles = mesh.triangle_count();
  g.boxes.assign((g.triangles + TriangleGroups::kSize - 1) / TriangleGroups::kSize, Bounds{});
  executor.parallel_for("raster.triangle_groups", g.boxes.size(), 64, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t first = k * TriangleGroups::kSize;
      const std::size_t last = std::min(first + TriangleGroups::kSize, g.triangles);
      for (std::size_t t = first; t < last; ++t)
        for (int v = 0; v < 3; ++v) g.boxes[k].grow(mesh.positions[mesh.indices[3 * t + v]]);
    }
  });
  return g;
}

void groups_outside(const TriangleGroups& groups, const glm::mat4& view_projection,
                    std::vector<std::uint8_t>& outside) {
  outside.assign(groups.boxes.size(), 0);
  // Row r of the matrix (clip component r = row · (p, 1)) in double.
  double row[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) row[r][c] = double(view_projection[c][r]);
  // The six planes as rows: s = (a · clip) > 0 means outside (x > w: x − w, x < −w: −x − w, ...).
  const int axis[6] = {0, 0, 1, 1, 2, 2};
  const double sign[6] = {-1.0, 1.0, -1.0, 1.0, -1.0, 1.0};
  for (std::size_t k = 0; k < groups.boxes.size(); ++k) {
    const Bounds& b = groups.boxes[k];
    if (!b.valid()) continue;
    // A float clip coordinate of a point p in the box is off by a few ulps of Σ|row_c · p_c|:
    // bound that sum over the box, per row.
    const double m[3] = {std::max(std::abs(double(b.lo.x)), std::abs(double(b.hi.x))),
                         std::max(std::abs(double(b.lo.y)), std::abs(double(b.hi.y))),
                         std::max(std::abs(double(b.lo.z)), std::abs(double(b.hi.z)))};
    double magnitude[4];
    for (int r = 0; r < 4; ++r)
      magnitude[r] = std::abs(row[r][0]) * m[0] + std::abs(row[r][1]) * m[1] + std::abs(row[r][2]) * m[2] +
                     std::abs(row[r][3]);
    for (int plane = 0; plane < 6 && !outside[k]; ++plane) {
      const int a = axis[plane];
      const double margin = 1e-5 * (magnitude[a] + magnitude[3]);
      bool all = true;
      for (int corner = 0; corner < 8 && all; ++corner) {
        const double p[3] = {double(corner & 1 ? b.hi.x : b.lo.x), double(corner & 2 ? b.hi.y : b.lo.y),
                             double(corner & 4 ? b.hi.z : b.lo.z)};
        double clip[4];
        for (int r = 0; r < 4; ++r) clip[r] = row[r][0] * p[0] + row[r][1] * p[1] + row[r][2] * p[2] + row[r][3];
        all = sign[plane] * clip[a] - clip[3] > margin;
      }
      outside[k] = all ? 1 : 0;
    }
  }
}

}  // namespace speculum::raster
