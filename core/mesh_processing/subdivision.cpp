// Subdivision (see subdivision.h).
#include "core/mesh_processing/subdivision.h"

#include <queue>
#include <utility>
#include <vector>

#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/Sqrt3T.hh>

namespace speculum::mesh {

void subdivide_uniform(HalfedgeMesh& m, Scheme scheme, int levels) {
  if (levels <= 0 || m.n_faces() == 0) return;
  if (scheme == Scheme::Loop) {
    OpenMesh::Subdivider::Uniform::LoopT<HalfedgeMesh, double> loop;
    loop.attach(m);
    loop(static_cast<std::size_t>(levels));
    loop.detach();
  } else {
    OpenMesh::Subdivider::Uniform::Sqrt3T<HalfedgeMesh, double> sqrt3;
    sqrt3.attach(m);
    sqrt3(static_cast<std::size_t>(levels));
    sqrt3.detach();
  }
  m.update_face_normals();
  m.update_vertex_normals();
}

SplitReport split_long_edges(HalfedgeMesh& m, double max_edge, std::size_t max_vertices) {
  SplitReport report;
  const double limit2 = max_edge * max_edge;
  // (squared length, edge index): the longest first, ties to the higher index, so the
  // order is a function of the mesh alone.
  std::priority_queue<std::pair<double, int>> queue;
  auto push = [&](OpenMesh::EdgeHandle e) {
    const double l2 = m.calc_edge_sqr_length(e);
    if (l2 > limit2) queue.emplace(l2, e.idx());
  };
  for (const auto e : m.edges()) push(e);
  while (!queue.empty()) {
    const auto [l2, index] = queue.top();
    queue.pop();
    const OpenMesh::EdgeHandle e(index);
    if (m.calc_edge_sqr_length(e) != l2) continue;  // stale: the edge was split already
    if (m.n_vertices() >= max_vertices) {
      report.vertex_budget_reached = true;
      break;
    }
    const auto h = m.halfedge_handle(e, 0);
    const auto a = m.from_vertex_handle(h), b = m.to_vertex_handle(h);
    const auto v = m.add_vertex((m.point(a) + m.point(b)) * 0.5);
    OpenMesh::Vec3d n = m.normal(a) + m.normal(b);
    const double nl = n.norm();
    m.set_normal(v, nl > 0.0 ? n / nl : m.normal(a));
    m.set_texcoord2D(v, (m.texcoord2D(a) + m.texcoord2D(b)) * 0.5f);
    m.split(e, v);
    ++report.splits;
    for (const auto ve : m.ve_range(v)) push(ve);
  }
  m.update_face_normals();
  return report;
}

}  // namespace speculum::mesh
