#include "core/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.h"

namespace speculum {

const char* to_string(MaterialKind kind) {
  switch (kind) {
    case MaterialKind::Diffuse: return "diffuse";
    case MaterialKind::Glossy: return "glossy";
    case MaterialKind::Mirror: return "mirror";
    case MaterialKind::Refractor: return "refractor";
  }
  return "?";
}

const char* to_string(LightType type) {
  switch (type) {
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
  }
  return "?";
}

MaterialKind Material::kind() const {
  if (transmission > 0.5f) return MaterialKind::Refractor;
  if (roughness <= kMirrorRoughness && metallic >= 0.5f) return MaterialKind::Mirror;
  if (roughness < kGlossyRoughness && metallic >= 0.5f) return MaterialKind::Glossy;
  return MaterialKind::Diffuse;
}

Material default_material() {
  Material m;
  m.name = "default";
  m.metallic = 0.0f;
  m.roughness = 0.8f;
  return m;
}

float Material::phong_exponent() const {
  const float alpha = roughness * roughness;
  if (!(alpha > 1e-3f)) return 1e6f;  // a mirror: the exponent's cap exactly
  return std::clamp(1.0f / (alpha * alpha) - 1.0f, 0.0f, 1e6f);
}

void Bounds::grow(const glm::vec3& p) {
  lo = glm::min(lo, p);
  hi = glm::max(hi, p);
}

Bounds Scene::bounds() const {
  Bounds b;
  for (const auto& p : mesh.positions) b.grow(p);
  return b;
}

void Scene::validate() const {
  const auto& m = mesh;
  const std::size_t nv = m.positions.size();
  const std::size_t nt = m.triangle_count();
  if (m.indices.size() % 3 != 0) throw InputError(name, "index count is not a multiple of 3");
  if (m.normals.size() != nv) throw InputError(name, "normal count differs from vertex count");
  if (m.uvs.size() != nv) throw InputError(name, "uv count differs from vertex count");
  if (!m.tangents.empty() && m.tangents.size() != nv)
    throw InputError(name, "tangent count differs from vertex count");
  if (m.triangle_material.size() != nt || m.triangle_object.size() != nt)
    throw InputError(name, "per-triangle id streams have the wrong length");
  if (materials.empty()) throw InputError(name, "no materials");
  for (std::size_t i = 0; i < nv; ++i) {
    const glm::vec3& p = m.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(name, "non-finite vertex " + std::to_string(i) + " (NaN or infinite position)");
    const glm::vec3& n = m.normals[i];
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
      throw InputError(name, "vertex " + std::to_string(i) + " has a NaN or infinite normal");
  }
  for (std::size_t i = 0; i < m.indices.size(); ++i)
    if (m.indices[i] >= nv)
      throw InputError(name, "triangle " + std::to_string(i / 3) + " indexes vertex " +
                                 std::to_string(m.indices[i]) + " of " + std::to_string(nv));
  for (std::size_t t = 0; t < nt; ++t) {
    if (m.triangle_material[t] >= materials.size())
      throw InputError(name, "triangle " + std::to_string(t) + " has material id out of range");
    if (m.triangle_object[t] >= objects.size())
      throw InputError(name, "triangle " + std::to_string(t) + " has object id out of range");
  }
  for (const auto& mat : materials) {
    for (const TextureRef* t : {&mat.base_color_texture, &mat.metallic_roughness_texture,
                                &mat.normal_texture, &mat.emissive_texture,
                                &mat.transmission_texture})
      if (t->texture >= static_cast<int>(textures.size()))
        throw InputError(name, "material '" + mat.name + "' names a missing texture");
  }
}

const char* to_string(View view) {
  switch (view) {
    case View::Front: return "front";
    case View::Back: return "back";
    case View::Left: return "left";
    case View::Right: return "right";
    case View::Top: return "top";
    case View::ThreeQuarter: return "three-quarter";
  }
  return "?";
}

namespace {

// Distance from the centre at which a sphere of `radius` fills the narrower of the two
// fields of view: the cone of half-angle h holds the sphere iff distance · sin h >= r.
float fitting_distance(float radius, float vfov_degrees, float aspect) {
  const float half_v = glm::radians(vfov_degrees) * 0.5f;
  const float half_h = std::atan(std::max(aspect, 1e-6f) * std::tan(half_v));
  return radius / std::sin(std::min(half_v, half_h));
}

}  // namespace

Camera framing_camera(const Bounds& bounds, View view, float aspect, float vfov_degrees) {
  Camera cam;
  cam.framed = true;
  cam.vfov_degrees = vfov_degrees;
  glm::vec3 from(0, 0, 1);
  switch (view) {
    case View::Front: from = {0, 0, 1}; break;
    case View::Back: from = {0, 0, -1}; break;
    case View::Left: from = {-1, 0, 0}; break;
    case View::Right: from = {1, 0, 0}; break;
    case View::Top: from = {0, 1, 0}, cam.up = {0, 0, -1}; break;
    case View::ThreeQuarter: {
      const float e = glm::radians(30.0f);
      from = {std::cos(e) * std::sqrt(0.5f), std::sin(e), std::cos(e) * std::sqrt(0.5f)};
      break;
    }
  }
  cam.target = glm::vec3(0.0f);
  cam.eye = from * 5.0f;
  if (!bounds.valid()) return cam;
  return fit_camera(cam, bounds, aspect);
}

Camera fit_camera(Camera cam, const Bounds& bounds, float aspect) {
  if (!bounds.valid() || cam.eye == cam.target) return cam;
  const glm::vec3 back = glm::normalize(cam.eye - cam.target);
  const glm::vec3 c = bounds.center();
  const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
  const float dist = fitting_distance(radius, cam.vfov_degrees, aspect);
  cam.target = c;
  cam.eye = c + back * dist;
  const ClipPlanes planes = sphere_clip_planes(dist, radius);
  cam.znear = planes.znear;
  cam.zfar = planes.zfar;
  return cam;
}

ClipPlanes sphere_clip_planes(float centre_depth, float radius) {
  ClipPlanes p;
  // A sphere wholly behind the eye is invisible: any valid pair will do.
  p.zfar = std::max(centre_depth + radius * 2.0f, radius);
  p.znear = std::max(centre_depth - radius * 1.5f, std::max(centre_depth * 1e-3f, p.zfar * 1e-4f));
  return p;
}

Camera fit_clip_planes(Camera camera, const Bounds& bounds) {
  if (!bounds.valid() || camera.eye == camera.target) return camera;  // validate_camera reports it
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const float radius = std::max(0.5f * glm::length(bounds.extent()), 1e-3f);
  ClipPlanes planes = sphere_clip_planes(glm::dot(bounds.center() - camera.eye, forward), radius);
  // The sphere around a long thin box can be much larger than the box: its nearest corner
  // (a linear function is smallest over a box at a corner) gives a tighter near plane.
  float nearest = std::numeric_limits<float>::infinity();
  for (int k = 0; k < 8; ++k) {
    const glm::vec3 corner(k & 1 ? bounds.hi.x : bounds.lo.x, k & 2 ? bounds.hi.y : bounds.lo.y,
                           k & 4 ? bounds.hi.z : bounds.lo.z);
    nearest = std::min(nearest, glm::dot(corner - camera.eye, forward));
  }
  planes.znear = std::max(planes.znear, 0.9f * nearest);
  camera.znear = planes.znear;
  camera.zfar = planes.zfar;
  return camera;
}

}  // namespace speculum
