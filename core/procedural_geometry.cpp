// Parametric meshes, procedural textures and the scene builder (see procedural_geometry.h).
#include "core/procedural_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include "core/mesh_normals.h"

namespace speculum::procedural {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Flips the winding (and given normals) when the area-weighted face normals point, on
// the whole, toward `center` rather than away from it.
void orient_outward(MeshData& m, const glm::vec3& center) {
  double sum = 0.0;
  for (std::size_t i = 0; i < m.indices.size(); i += 3) {
    const glm::vec3& a = m.positions[m.indices[i]];
    const glm::vec3& b = m.positions[m.indices[i + 1]];
    const glm::vec3& c = m.positions[m.indices[i + 2]];
    sum += glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0f - center);
  }
  if (sum >= 0.0) return;
  for (std::size_t i = 0; i < m.indices.size(); i += 3) std::swap(m.indices[i + 1], m.indices[i + 2]);
  for (auto& n : m.normals) n = -n;
}

// Direction on the unit sphere for grid coordinates (u: longitude, v: 0 south to 1 north
// pole). The poles are exact: float sin(pi) is not 0, which would leave the pole triangles
// as slivers with random orientation instead of exactly degenerate.
glm::vec3 unit_direction(float u, float v) {
  const float phi = 2.0f * kPi * u, theta = kPi * (1.0f - v);
  if (v <= 0.0f) return {0.0f, -1.0f, 0.0f};
  if (v >= 1.0f) return {0.0f, 1.0f, 0.0f};
  return {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
}

}  // namespace

MeshData parametric_grid(int nu, int nv, const std::function<glm::vec3(float, float)>& p) {
  MeshData m;
  const std::size_t row = static_cast<std::size_t>(nu) + 1;
  m.positions.reserve(row * (static_cast<std::size_t>(nv) + 1));
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const float u = static_cast<float>(i) / static_cast<float>(nu);
      const float v = static_cast<float>(j) / static_cast<float>(nv);
      m.positions.push_back(p(u, v));
      m.uvs.emplace_back(u, 1.0f - v);  // image rows run downward (glTF uv convention)
    }
  m.indices.reserve(static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv) * 6);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const auto a = static_cast<std::uint32_t>(static_cast<std::size_t>(j) * row + static_cast<std::size_t>(i));
      const auto b = a + 1;
      const auto c = static_cast<std::uint32_t>(a + row + 1);
      const auto d = static_cast<std::uint32_t>(a + row);
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  return m;
}

MeshData quad(const glm::vec3& origin, const glm::vec3& edge_u, const glm::vec3& edge_v, int nu,
              int nv, float uv_scale) {
  MeshData m = parametric_grid(std::max(nu, 1), std::max(nv, 1),
                               [&](float u, float v) { return origin + u * edge_u + v * edge_v; });
  for (auto& uv : m.uvs) uv *= uv_scale;
  m.normals.assign(m.positions.size(), glm::normalize(glm::cross(edge_u, edge_v)));
  return m;
}

MeshData box(const glm::vec3& lo, const glm::vec3& hi, int n, bool inward, float uv_scale) {
  MeshData out;
  const glm::vec3 size = hi - lo;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      glm::vec3 normal(0.0f);
      normal[axis] = side ? 1.0f : -1.0f;
      if (inward) normal = -normal;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      glm::vec3 origin = lo;
      origin[axis] = side ? hi[axis] : lo[axis];
      glm::vec3 eu(0.0f), ev(0.0f);
      eu[a1] = size[a1];
      ev[a2] = size[a2];
      if (glm::dot(glm::cross(eu, ev), normal) < 0.0f) std::swap(eu, ev);
      MeshData face = quad(origin, eu, ev, n, n, uv_scale);
      const auto base = static_cast<std::uint32_t>(out.positions.size());
      out.positions.insert(out.positions.end(), face.positions.begin(), face.positions.end());
      out.normals.insert(out.normals.end(), face.normals.begin(), face.normals.end());
      out.uvs.insert(out.uvs.end(), face.uvs.begin(), face.uvs.end());
      for (auto i : face.indices) out.indices.push_back(base + i);
    }
  return out;
}

MeshData sphere(const glm::vec3& center, float radius, int rings) {
  MeshData m = parametric_grid(2 * rings, rings, [&](float u, float v) {
    return center + radius * unit_direction(u, v);
  });
  m.normals.reserve(m.positions.size());
  for (const auto& p : m.positions) m.normals.push_back(glm::normalize(p - center));
  return m;
}

MeshData ellipsoid(const glm::vec3& center, const glm::vec3& radii, int rings) {
  MeshData m = parametric_grid(2 * rings, rings, [&](float u, float v) {
    return center + radii * unit_direction(u, v);
  });
  m.normals.reserve(m.positions.size());
  // ∇ of Σ (x_i/a_i)²: the normal of the implicit surface.
  for (const auto& p : m.positions) m.normals.push_back(glm::normalize((p - center) / (radii * radii)));
  return m;
}

MeshData bumpy_sphere(const glm::vec3& center, float radius, float amplitude, float n, int rings) {
  MeshData m = parametric_grid(2 * rings, rings, [&](float u, float v) {
    const glm::vec3 d = unit_direction(u, v);
    // Displacement as a function of the direction itself: continuous at poles and seam.
    const float r = radius * (1.0f + amplitude * std::cos(n * d.x) * std::cos(n * d.y));
    return center + r * d;
  });
  orient_outward(m, center);
  m.normals = area_weighted_normals(m.positions, m.indices);
  return m;
}

MeshData bowl(const glm::vec3& center, float radius, float opening_degrees, int rings) {
  const float open = opening_degrees * kPi / 180.0f;
  MeshData m = parametric_grid(2 * rings, rings, [&](float u, float v) {
    const float phi = 2.0f * kPi * u, theta = open * v;  // theta from the bottom pole
    return center + radius * glm::vec3(std::sin(theta) * std::cos(phi), -std::cos(theta),
                                       std::sin(theta) * std::sin(phi));
  });
  orient_outward(m, center);
  // The reflecting side is the inside: face the centre.
  for (std::size_t i = 0; i < m.indices.size(); i += 3) std::swap(m.indices[i + 1], m.indices[i + 2]);
  m.normals.reserve(m.positions.size());
  for (const auto& p : m.positions) m.normals.push_back(glm::normalize(center - p));
  return m;
}

MeshData torus(const glm::vec3& center, float major, float minor, int rings) {
  MeshData m = parametric_grid(2 * rings, std::max(rings / 2, 3), [&](float u, float v) {
    const float phi = 2.0f * kPi * u, psi = 2.0f * kPi * v;
    const float r = major + minor * std::cos(psi);
    return center + glm::vec3(r * std::cos(phi), minor * std::sin(psi), r * std::sin(phi));
  });
  orient_outward(m, center);
  m.normals.reserve(m.positions.size());
  for (const auto& p : m.positions) {
    const glm::vec3 q = p - center;
    const glm::vec3 ring = glm::normalize(glm::vec3(q.x, 0.0f, q.z)) * major;
    m.normals.push_back(glm::normalize(q - ring));
  }
  return m;
}

MeshData lathe(const glm::vec3& base, const std::function<glm::vec2(float)>& profile, int rings) {
  MeshData m = parametric_grid(2 * rings, rings, [&](float u, float v) {
    const float phi = 2.0f * kPi * u;
    const glm::vec2 rh = profile(v);
    return base + glm::vec3(rh.x * std::cos(phi), rh.y, rh.x * std::sin(phi));
  });
  orient_outward(m, base + glm::vec3(0.0f, profile(0.5f).y, 0.0f));
  m.normals = area_weighted_normals(m.positions, m.indices);
  return m;
}

int rings_for(std::uint64_t triangles) {
  return std::max(3, static_cast<int>(std::lround(std::sqrt(static_cast<double>(triangles) / 4.0))));
}

int cells_for(std::uint64_t triangles) {
  return std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(triangles) / 2.0))));
}

ImageRGBA checker_texture(int size, int cells, const glm::vec3& a, const glm::vec3& b) {
  ImageRGBA img(size, size);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const bool odd = ((x * cells / size) + (y * cells / size)) % 2 != 0;
      img.at(x, y) = glm::vec4(odd ? b : a, 1.0f);
    }
  return img;
}

ImageRGBA sky_equirect(int width, int height, const glm::vec3& sun_dir) {
  ImageRGBA img(width, height);
  const glm::vec3 sun = glm::normalize(sun_dir);
  const float sun_cos = std::cos(2.5f * kPi / 180.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float phi = 2.0f * kPi * (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
      const float theta = kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
      const glm::vec3 d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      glm::vec3 c;
      if (d.y >= 0.0f) {
        const float t = std::sqrt(d.y);
        c = glm::mix(glm::vec3(0.85f, 0.9f, 1.0f), glm::vec3(0.2f, 0.4f, 0.85f), t);
      } else {
        c = glm::mix(glm::vec3(0.35f, 0.32f, 0.3f), glm::vec3(0.15f, 0.13f, 0.12f), std::sqrt(-d.y));
      }
      if (glm::dot(d, sun) > sun_cos) c += glm::vec3(60.0f, 55.0f, 48.0f);
      img.at(x, y) = glm::vec4(c, 1.0f);
    }
  return img;
}

Material diffuse(const std::string& name, const glm::vec3& color) {
  Material m;
  m.name = name;
  m.base_color = glm::vec4(color, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 1.0f;
  return m;
}

Material glossy(const std::string& name, const glm::vec3& color, float roughness) {
  Material m;
  m.name = name;
  m.base_color = glm::vec4(color, 1.0f);
  m.metallic = 1.0f;
  m.roughness = roughness;
  return m;
}

Material mirror(const std::string& name, const glm::vec3& color) { return glossy(name, color, 0.0f); }

Material glass(const std::string& name, float ior) {
  Material m;
  m.name = name;
  m.base_color = glm::vec4(1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.0f;
  m.transmission = 1.0f;
  m.ior = ior;
  return m;
}

SceneBuilder::SceneBuilder(std::string name) { scene_.name = std::move(name); }

std::uint32_t SceneBuilder::add_material(Material m) {
  scene_.materials.push_back(std::move(m));
  return static_cast<std::uint32_t>(scene_.materials.size() - 1);
}

int SceneBuilder::add_texture(ImageRGBA image, std::string source) {
  scene_.textures.push_back(std::move(image));
  scene_.texture_sources.push_back(std::move(source));
  return static_cast<int>(scene_.textures.size() - 1);
}

void SceneBuilder::add_object(const std::string& name, std::uint32_t material, MeshData m) {
  if (m.normals.empty()) m.normals = area_weighted_normals(m.positions, m.indices);
  if (m.uvs.empty()) m.uvs.assign(m.positions.size(), glm::vec2(0.0f));
  auto& mesh = scene_.mesh;
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  const auto object = static_cast<std::uint32_t>(scene_.objects.size());
  Object obj;
  obj.name = name;
  obj.first_triangle = static_cast<std::uint32_t>(mesh.triangle_count());
  obj.triangle_count = static_cast<std::uint32_t>(m.triangle_count());
  obj.material = material;
  scene_.objects.push_back(obj);
  mesh.positions.insert(mesh.positions.end(), m.positions.begin(), m.positions.end());
  mesh.normals.insert(mesh.normals.end(), m.normals.begin(), m.normals.end());
  mesh.uvs.insert(mesh.uvs.end(), m.uvs.begin(), m.uvs.end());
  mesh.indices.reserve(mesh.indices.size() + m.indices.size());
  for (auto i : m.indices) mesh.indices.push_back(base + i);
  mesh.triangle_material.insert(mesh.triangle_material.end(), m.triangle_count(), material);
  mesh.triangle_object.insert(mesh.triangle_object.end(), m.triangle_count(), object);
}

}  // namespace speculum::procedural
