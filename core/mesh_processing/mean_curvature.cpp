// Cotangent mean curvature (see mean_curvature.h).
#include "core/mesh_processing/mean_curvature.h"

#include <cmath>

namespace speculum::mesh {

namespace {

double cot(const OpenMesh::Vec3d& a, const OpenMesh::Vec3d& b) {
  const double s = OpenMesh::cross(a, b).norm();
  return s > 0.0 ? OpenMesh::dot(a, b) / s : 0.0;
}

}  // namespace

std::vector<bool> boundary_vertices(const HalfedgeMesh& m) {
  std::vector<bool> out(m.n_vertices(), false);
  for (const auto vh : m.vertices()) out[vh.idx()] = m.is_boundary(vh);
  return out;
}

std::vector<double> mean_curvature(const HalfedgeMesh& m) {
  const std::size_t n = m.n_vertices();
  std::vector<OpenMesh::Vec3d> laplace(n, OpenMesh::Vec3d(0, 0, 0));
  std::vector<double> area(n, 0.0);
  // Per face: cotangent edge weights and the mixed area of each corner (Meyer et al. §3.3:
  // the Voronoi area for non-obtuse triangles, else half or a quarter of the triangle).
  for (const auto fh : m.faces()) {
    OpenMesh::VertexHandle v[3];
    int k = 0;
    for (const auto vh : m.fv_range(fh)) v[k++] = vh;
    const OpenMesh::Vec3d p[3] = {m.point(v[0]), m.point(v[1]), m.point(v[2])};
    const double face_area = 0.5 * OpenMesh::cross(p[1] - p[0], p[2] - p[0]).norm();
    if (!(face_area > 0.0)) continue;
    double cots[3];
    for (int i = 0; i < 3; ++i) {  // angle at corner i, opposite the edge (i+1, i+2)
      const auto& a = p[i];
      cots[i] = cot(p[(i + 1) % 3] - a, p[(i + 2) % 3] - a);
    }
    for (int i = 0; i < 3; ++i) {
      const int j = (i + 1) % 3, l = (i + 2) % 3;
      // Edge (j, l) is opposite corner i.
      const OpenMesh::Vec3d e = p[l] - p[j];
      laplace[v[j].idx()] += cots[i] * e;
      laplace[v[l].idx()] -= cots[i] * e;
    }
    const bool obtuse[3] = {OpenMesh::dot(p[1] - p[0], p[2] - p[0]) < 0.0,
                            OpenMesh::dot(p[0] - p[1], p[2] - p[1]) < 0.0,
                            OpenMesh::dot(p[0] - p[2], p[1] - p[2]) < 0.0};
    const bool any_obtuse = obtuse[0] || obtuse[1] || obtuse[2];
    for (int i = 0; i < 3; ++i) {
      if (any_obtuse) {
        area[v[i].idx()] += obtuse[i] ? face_area / 2.0 : face_area / 4.0;
      } else {
        const int j = (i + 1) % 3, l = (i + 2) % 3;
        area[v[i].idx()] += ((p[j] - p[i]).sqrnorm() * cots[l] + (p[l] - p[i]).sqrnorm() * cots[j]) / 8.0;
      }
    }
  }
  std::vector<double> h(n, 0.0);
  const std::vector<bool> boundary = boundary_vertices(m);
  for (const auto vh : m.vertices()) {
    const int i = vh.idx();
    if (boundary[i] || !(area[i] > 0.0)) continue;
    const OpenMesh::Vec3d lb = laplace[i] / (2.0 * area[i]);  // Δx = −2 H n
    OpenMesh::Vec3d normal = m.normal(vh);
    const double nl = normal.norm();
    if (!(nl > 0.0)) continue;
    normal /= nl;
    // |Δx|/2 is |H|; the sign from the normal side (projecting would add the tangential
    // part a coarse mesh leaves in Δx, magnitude is the estimator Meyer et al. give).
    h[i] = (OpenMesh::dot(lb, normal) > 0.0 ? -0.5 : 0.5) * lb.norm();
  }
  for (const auto vh : m.vertices()) {
    if (!boundary[vh.idx()]) continue;
    double sum = 0.0;
    int count = 0;
    for (const auto w : m.vv_range(vh))
      if (!boundary[w.idx()]) {
        sum += h[w.idx()];
        ++count;
      }
    h[vh.idx()] = count ? sum / count : 0.0;
  }
  return h;
}

std::vector<float> scene_mean_curvature(const Scene& scene) {
  std::vector<float> out(scene.mesh.vertex_count(), 0.0f);
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const ObjectMesh om = build_object_mesh(scene, o, Weld::Positions);
    if (om.mesh.n_vertices() == 0) continue;
    const std::vector<double> h = mean_curvature(om.mesh);
    for (std::size_t v = 0; v < om.mesh_vertex.size(); ++v)
      if (om.mesh_vertex[v] >= 0) out[om.first_vertex + v] = static_cast<float>(h[om.mesh_vertex[v]]);
  }
  return out;
}

}  // namespace speculum::mesh
