// Building blocks of the built-in procedural scenes: parametric meshes (grids, boxes,
// spheres, displaced spheres, bowls, tori, lathes), procedural textures and sky, and a
// SceneBuilder that appends them to a Scene as objects.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"

namespace speculum::procedural {

// An indexed triangle mesh in world space (normals may be left empty: computed).
struct MeshData {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
  std::size_t triangle_count() const { return indices.size() / 3; }
};

// A surface p(u, v) over [0,1]^2 sampled on an (nu+1) x (nv+1) vertex grid: 2*nu*nv
// triangles, counter-clockwise when du x dv points outward.
MeshData parametric_grid(int nu, int nv, const std::function<glm::vec3(float, float)>& p);

// Planar rectangle origin + s*edge_u + t*edge_v; faces cross(edge_u, edge_v); uvs scaled.
MeshData quad(const glm::vec3& origin, const glm::vec3& edge_u, const glm::vec3& edge_v,
              int nu, int nv, float uv_scale = 1.0f);
// Axis-aligned box; `inward` flips it for rooms. About 12*n*n triangles.
MeshData box(const glm::vec3& lo, const glm::vec3& hi, int n, bool inward, float uv_scale = 1.0f);
// UV sphere with `rings` latitude bands and 2*rings longitude segments (~4 rings^2 tris).
MeshData sphere(const glm::vec3& center, float radius, int rings);
// Axis-aligned ellipsoid centre + radii · (unit direction), with its analytic normals.
MeshData ellipsoid(const glm::vec3& center, const glm::vec3& radii, int rings);
// Sphere displaced radially by amplitude*cos(n x)cos(n y) of the unit direction (x, y).
MeshData bumpy_sphere(const glm::vec3& center, float radius, float amplitude, float n, int rings);
// Spherical cap below the centre, opening upward: a concave reflector (~4 rings^2 tris).
MeshData bowl(const glm::vec3& center, float radius, float opening_degrees, int rings);
MeshData torus(const glm::vec3& center, float major, float minor, int rings);
// Surface of revolution about +Y of profile (radius, height) pairs, t in [0,1].
MeshData lathe(const glm::vec3& base, const std::function<glm::vec2(float)>& profile, int rings);

// Rings for about `triangles` triangles on a sphere-like grid (2*rings x rings cells).
int rings_for(std::uint64_t triangles);
// Cells per side for about `triangles` triangles on a square grid.
int cells_for(std::uint64_t triangles);

// Two-colour checker, `cells` per side, linear colours.
ImageRGBA checker_texture(int size, int cells, const glm::vec3& a, const glm::vec3& b);
// Deterministic equirectangular sky: blue gradient above, dim ground below, a small sun
// disc toward `sun_dir` (HDR). Linear radiance.
ImageRGBA sky_equirect(int width, int height, const glm::vec3& sun_dir);

// Material shorthands with the roughness/metal settings the techniques care about.
Material diffuse(const std::string& name, const glm::vec3& color);
Material glossy(const std::string& name, const glm::vec3& color, float roughness);
Material mirror(const std::string& name, const glm::vec3& color = glm::vec3(0.95f));
Material glass(const std::string& name, float ior = 1.5f);

class SceneBuilder {
 public:
  explicit SceneBuilder(std::string name);
  std::uint32_t add_material(Material m);
  int add_texture(ImageRGBA image, std::string source);
  void add_object(const std::string& name, std::uint32_t material, MeshData mesh);
  Scene& scene() { return scene_; }
  Scene take() { return std::move(scene_); }

 private:
  Scene scene_;
};

}  // namespace speculum::procedural
