// core/mesh_processing: welding and non-manifold reports, cotangent mean curvature against
// analytic surfaces (sphere 1/r, cylinder 1/(2r), plane 0, torus) with the error falling
// under refinement, star-shapedness, and subdivision properties that must hold.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "core/mesh_processing/halfedge_mesh.h"
#include "core/mesh_processing/mean_curvature.h"
#include "core/mesh_processing/star_shape.h"
#include "core/mesh_processing/subdivision.h"
#include "core/procedural_geometry.h"

namespace speculum {
namespace {

using namespace speculum::mesh;
using procedural::MeshData;

Scene one_object(MeshData m) {
  procedural::SceneBuilder b("test");
  const auto mat = b.add_material(procedural::mirror("m"));
  b.add_object("shape", mat, std::move(m));
  return b.take();
}

ObjectMesh welded(MeshData m) { return build_object_mesh(one_object(std::move(m)), 0); }

struct Errors {
  double max_rel = 0.0;
  double mean_rel = 0.0;
};

// Relative error of H against `exact(p)` over interior vertices.
template <class F>
Errors curvature_errors(const HalfedgeMesh& m, F&& exact) {
  const std::vector<double> h = mean_curvature(m);
  const std::vector<bool> boundary = boundary_vertices(m);
  Errors e;
  int n = 0;
  for (const auto vh : m.vertices()) {
    if (boundary[vh.idx()]) continue;
    const double want = exact(to_glm(m.point(vh)));
    const double rel = std::fabs(h[vh.idx()] - want) / std::fabs(want);
    e.max_rel = std::max(e.max_rel, rel);
    e.mean_rel += rel;
    ++n;
  }
  e.mean_rel /= std::max(n, 1);
  return e;
}

TEST(MeshProcessing, WeldingClosesTheSphereSeamAndPolesAndReportsDegenerateFaces) {
  const int rings = 12;
  const ObjectMesh om = welded(procedural::sphere({0, 0, 0}, 1.0f, rings));
  // The (2 rings + 1) × (rings + 1) grid: each pole row welds to one vertex, the seam column
  // onto the first: 2 rings (rings − 1) + 2 vertices, a closed manifold (Euler 2).
  EXPECT_EQ(om.mesh.n_vertices(), std::size_t(2 * rings * (rings - 1) + 2));
  EXPECT_EQ(om.report.non_manifold_faces, 0u);
  EXPECT_EQ(om.report.degenerate_faces, std::size_t(2 * 2 * rings));  // one per pole cell
  EXPECT_EQ(int(om.mesh.n_vertices()) - int(om.mesh.n_edges()) + int(om.mesh.n_faces()), 2);
  for (const auto vh : om.mesh.vertices()) EXPECT_FALSE(om.mesh.is_boundary(vh));
  // Every soup vertex maps to a mesh vertex at its own position.
  const Scene s = one_object(procedural::sphere({0, 0, 0}, 1.0f, rings));
  for (std::size_t v = 0; v < om.mesh_vertex.size(); ++v) {
    ASSERT_GE(om.mesh_vertex[v], 0);
    const glm::dvec3 p = to_glm(om.mesh.point(OpenMesh::VertexHandle(om.mesh_vertex[v])));
    EXPECT_LT(glm::length(p - glm::dvec3(s.mesh.positions[om.first_vertex + v])), 1e-5);
  }
  // Unwelded, the seam and poles stay open.
  const ObjectMesh open = build_object_mesh(s, 0, Weld::Indices);
  EXPECT_EQ(open.mesh.n_vertices(), std::size_t((2 * rings + 1) * (rings + 1)));
}

TEST(MeshProcessing, NonManifoldInputIsReportedNotACrash) {
  // Three triangles sharing one edge: the third cannot be added to a manifold mesh.
  MeshData m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  const ObjectMesh om = welded(m);
  EXPECT_EQ(om.report.non_manifold_faces, 1u);
  EXPECT_FALSE(om.report.manifold());
  EXPECT_EQ(om.mesh.n_faces(), 2u);
  EXPECT_NE(om.report.describe("shape").find("1 non-manifold faces left out"), std::string::npos);
}

TEST(MeshProcessing, SphereMeanCurvatureIsOneOverRadiusAndConverges) {
  const double r = 1.7;
  double previous = 1e9;
  for (int rings : {8, 16, 32, 64}) {
    const ObjectMesh om = welded(procedural::sphere({0.3f, -0.2f, 0.1f}, float(r), rings));
    const Errors e = curvature_errors(om.mesh, [&](const glm::dvec3&) { return 1.0 / r; });
    EXPECT_LT(e.mean_rel, previous) << rings;
    previous = e.mean_rel;
    if (rings == 64) {
      EXPECT_LT(e.mean_rel, 2e-3);
      EXPECT_LT(e.max_rel, 2e-2);
    }
  }
}

TEST(MeshProcessing, CylinderMeanCurvatureIsOneOverTwoRadii) {
  // On the regular cylinder grid the cotangent operator is exact at every tessellation
  // (each ring's Laplacian is the circle's); what remains is the float rounding of the
  // procedural points, so the bound is absolute rather than falling.
  const double r = 0.8;
  for (int n : {8, 16, 32, 64}) {
    const MeshData grid = procedural::parametric_grid(n, 4, [&](float u, float v) {
      const float a = float(2.0 * std::numbers::pi) * u;
      return glm::vec3(float(r) * std::sin(a), 2.0f * v, float(r) * std::cos(a));
    });
    const ObjectMesh om = welded(grid);
    const Errors e = curvature_errors(om.mesh, [&](const glm::dvec3&) { return 1.0 / (2.0 * r); });
    EXPECT_LT(e.max_rel, 1e-4) << n;
  }
}

TEST(MeshProcessing, PlaneMeanCurvatureIsZero) {
  const ObjectMesh om = welded(procedural::quad({-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, 9, 7));
  const std::vector<double> h = mean_curvature(om.mesh);
  for (double v : h) EXPECT_NEAR(v, 0.0, 1e-9);
}

TEST(MeshProcessing, TorusMeanCurvatureMatchesTheAnalyticFormula) {
  const double R = 1.0, m = 0.35;
  // H = (R + 2 m cos ψ) / (2 m (R + m cos ψ)), ψ the angle around the tube (0 outside).
  auto exact = [&](const glm::dvec3& p) {
    const double c = (std::sqrt(p.x * p.x + p.z * p.z) - R) / m;
    return (R + 2.0 * m * c) / (2.0 * m * (R + m * c));
  };
  double previous = 1e9;
  for (int rings : {12, 24, 48, 96}) {
    const ObjectMesh om = welded(procedural::torus({0, 0, 0}, float(R), float(m), rings));
    EXPECT_EQ(om.report.non_manifold_faces, 0u);
    const Errors e = curvature_errors(om.mesh, exact);
    EXPECT_LT(e.mean_rel, previous) << rings;
    previous = e.mean_rel;
    if (rings == 96) {
      EXPECT_LT(e.mean_rel, 1e-2);
    }
  }
}

TEST(MeshProcessing, SceneMeanCurvatureIsPerSoupVertex) {
  procedural::SceneBuilder b("two");
  const auto mat = b.add_material(procedural::mirror("m"));
  b.add_object("big", mat, procedural::sphere({0, 0, 0}, 2.0f, 32));
  b.add_object("small", mat, procedural::sphere({5, 0, 0}, 0.5f, 32));
  const Scene s = b.take();
  const std::vector<float> h = scene_mean_curvature(s);
  ASSERT_EQ(h.size(), s.mesh.vertex_count());
  for (std::size_t v = 0; v < h.size(); ++v) {
    const double want = s.mesh.positions[v].x > 2.5f ? 2.0 : 0.5;
    EXPECT_NEAR(h[v], want, 0.05 * want) << v;
  }
  // Per pixel: the triangle's barycentric blend, as a G-buffer reads it.
  for (std::uint32_t t = 0; t < s.mesh.triangle_count(); t += 97) {
    const std::uint32_t* i = &s.mesh.indices[3 * t];
    EXPECT_FLOAT_EQ(interpolate_at(s.mesh, h, t, 0.0f, 0.0f), h[i[0]]);
    EXPECT_FLOAT_EQ(interpolate_at(s.mesh, h, t, 1.0f, 0.0f), h[i[1]]);
    EXPECT_NEAR(interpolate_at(s.mesh, h, t, 0.25f, 0.5f), 0.25f * h[i[0]] + 0.25f * h[i[1]] + 0.5f * h[i[2]], 1e-6);
  }
}

TEST(MeshProcessing, StarShapedAboutTheChosenCentre) {
  const ObjectMesh ball = welded(procedural::sphere({1, 2, 3}, 1.0f, 16));
  const StarShape s = choose_star_centre(ball.mesh);
  EXPECT_TRUE(s.star_shaped);
  EXPECT_EQ(s.orientation, 1);
  EXPECT_LT(glm::length(s.centre - glm::dvec3(1, 2, 3)), 1e-6);
  EXPECT_EQ(s.failing_faces, 0u);

  // A bumpy sphere stays star-shaped (a radius function of the direction).
  const ObjectMesh bumpy = welded(procedural::bumpy_sphere({0, 0, 0}, 1.0f, 0.1f, 8.0f, 32));
  EXPECT_TRUE(choose_star_centre(bumpy.mesh).star_shaped);

  // The bowl: star-shaped about a point on its reflecting side (faces face O).
  const ObjectMesh bowl = welded(procedural::bowl({0, 2, 0}, 2.0f, 75.0f, 24));
  const StarShape b = choose_star_centre(bowl.mesh);
  EXPECT_TRUE(b.star_shaped);
  EXPECT_EQ(b.orientation, -1);
  const StarShape about_focus = star_shape_about(bowl.mesh, normal_focus(bowl.mesh));
  EXPECT_TRUE(about_focus.star_shaped);
  // Face normals through face centroids (not circumcentres) miss the centre slightly.
  EXPECT_LT(glm::length(normal_focus(bowl.mesh) - glm::dvec3(0, 2, 0)), 1e-2);

  // A torus is star-shaped about no point: both candidates fail, and the count says how badly.
  const ObjectMesh torus = welded(procedural::torus({0, 0, 0}, 1.0f, 0.3f, 24));
  const StarShape t = choose_star_centre(torus.mesh);
  EXPECT_FALSE(t.star_shaped);
  EXPECT_GT(t.failing_faces, t.faces / 10);
  // Not about a point outside the ball either.
  EXPECT_FALSE(star_shape_about(ball.mesh, glm::dvec3(1, 2, 5)).star_shaped);
}

// The largest angle between the normals of two faces sharing an edge.
double max_dihedral(const HalfedgeMesh& m) {
  double worst = 0.0;
  for (const auto e : m.edges()) {
    if (m.is_boundary(e)) continue;
    const auto a = m.normal(m.face_handle(m.halfedge_handle(e, 0)));
    const auto b = m.normal(m.face_handle(m.halfedge_handle(e, 1)));
    worst = std::max(worst, std::acos(std::clamp(OpenMesh::dot(a, b) / (a.norm() * b.norm()), -1.0, 1.0)));
  }
  return worst;
}

double mesh_area(const HalfedgeMesh& m) {
  double a = 0.0;
  for (const auto fh : m.faces()) a += m.calc_face_area(fh);
  return a;
}

TEST(MeshProcessing, LoopAndSqrt3KeepTheSurfaceInsideTheControlHull) {
  for (Scheme scheme : {Scheme::Loop, Scheme::Sqrt3}) {
    ObjectMesh om = welded(procedural::sphere({0, 0, 0}, 1.0f, 8));
    const std::size_t faces = om.mesh.n_faces();
    const double kink = max_dihedral(om.mesh);
    subdivide_uniform(om.mesh, scheme, 2);
    EXPECT_EQ(om.mesh.n_faces(), faces * (scheme == Scheme::Loop ? 16u : 9u));
    EXPECT_EQ(int(om.mesh.n_vertices()) - int(om.mesh.n_edges()) + int(om.mesh.n_faces()), 2);
    // Both schemes place every vertex at a convex combination of control points, all on
    // the unit sphere: nothing leaves the ball, and smoothing pulls vertices inside it.
    double max_r = 0.0, min_r = 2.0;
    for (const auto vh : om.mesh.vertices()) {
      const double r = om.mesh.point(vh).norm();
      max_r = std::max(max_r, r);
      min_r = std::min(min_r, r);
    }
    EXPECT_LE(max_r, 1.0 + 1e-6);
    EXPECT_GT(min_r, 0.9);
    // Smoothing: the finer mesh bends less between neighbouring faces than the control mesh.
    EXPECT_LT(max_dihedral(om.mesh), 0.5 * kink);
  }
}

TEST(MeshProcessing, SplittingLongEdgesKeepsTheSurfaceAndInterpolatesUv) {
  // A planar quad whose uv is an affine function of position: midpoints keep it exact.
  ObjectMesh quad = build_object_mesh(one_object(procedural::quad({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 2, 2, 1.0f)),
                                      0, Weld::Indices);
  const double area = mesh_area(quad.mesh);
  const HalfedgeMesh before = quad.mesh;
  const SplitReport r = split_long_edges(quad.mesh, 0.3, 1 << 20);
  EXPECT_GT(r.splits, 100u);
  EXPECT_FALSE(r.vertex_budget_reached);
  for (const auto e : quad.mesh.edges()) EXPECT_LE(quad.mesh.calc_edge_length(e), 0.3 + 1e-12);
  EXPECT_NEAR(mesh_area(quad.mesh), area, 1e-9 * area);
  for (const auto vh : quad.mesh.vertices()) EXPECT_EQ(quad.mesh.point(vh)[1], 1.0);
  // uv at every vertex equals the bilinear (here affine) interpolation of the corners.
  auto corner = [&](double x, double z) {
    for (const auto vh : before.vertices())
      if (before.point(vh)[0] == x && before.point(vh)[2] == z) return before.texcoord2D(vh);
    ADD_FAILURE() << "no corner " << x << " " << z;
    return OpenMesh::Vec2f(0, 0);
  };
  const auto c00 = corner(-2, 2), c10 = corner(2, 2), c01 = corner(-2, -2);
  for (const auto vh : quad.mesh.vertices()) {
    const auto p = quad.mesh.point(vh);
    const double s = (p[0] + 2) / 4, t = (2 - p[2]) / 4;
    for (int k = 0; k < 2; ++k)
      EXPECT_NEAR(quad.mesh.texcoord2D(vh)[k], c00[k] + s * (c10[k] - c00[k]) + t * (c01[k] - c00[k]), 1e-5);
  }

  // On a sphere mesh the split keeps the area (new vertices lie on the old faces) and the
  // vertex budget is a hard stop.
  ObjectMesh ball = welded(procedural::sphere({0, 0, 0}, 1.0f, 8));
  const double ball_area = mesh_area(ball.mesh);
  const SplitReport rb = split_long_edges(ball.mesh, 0.05, 2000);
  EXPECT_TRUE(rb.vertex_budget_reached);
  EXPECT_EQ(ball.mesh.n_vertices(), 2000u);
  EXPECT_NEAR(mesh_area(ball.mesh), ball_area, 1e-9 * ball_area);
}

}  // namespace
}  // namespace speculum
