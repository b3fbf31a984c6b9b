// Mirrored camera and half-space clipping: see mirrored_camera.h.
#include "raster/mirrored_camera.h"

#include <array>

namespace speculum::raster {

Camera mirrored_camera(const Camera& camera, const Plane& plane) {
  Camera c = camera;
  c.name = camera.name + " mirrored";
  c.eye = plane.reflect_point(camera.eye);
  c.target = plane.reflect_point(camera.target);
  c.up = plane.reflect_direction(camera.up);
  return c;
}

namespace {

// The mesh being built: attributes copied or interpolated per vertex.
struct MeshWriter {
  const TriangleMesh& in;
  TriangleMesh& out;

  std::uint32_t lerp_vertex(std::uint32_t a, std::uint32_t b, float t) {
    const auto id = static_cast<std::uint32_t>(out.positions.size());
    const auto mix = [t](const auto& x, const auto& y) { return x + (y - x) * t; };
    out.positions.push_back(mix(in.positions[a], in.positions[b]));
    if (!in.normals.empty()) {
      const glm::vec3 n = mix(in.normals[a], in.normals[b]);
      const float l = glm::length(n);
      out.normals.push_back(l > 0.0f ? n / l : in.normals[a]);
    }
    if (!in.tangents.empty()) {
      glm::vec4 tg = mix(in.tangents[a], in.tangents[b]);
      const float l = glm::length(glm::vec3(tg));
      tg = l > 0.0f ? glm::vec4(glm::vec3(tg) / l, in.tangents[a].w) : in.tangents[a];
      out.tangents.push_back(tg);
    }
    if (!in.uvs.empty()) out.uvs.push_back(mix(in.uvs[a], in.uvs[b]));
    if (!in.uvs1.empty()) out.uvs1.push_back(mix(in.uvs1[a], in.uvs1[b]));
    return id;
  }
};

}  // namespace

Scene clip_scene_to_half_space(const Scene& scene, const Plane& plane, float side,
                               std::uint32_t skip) {
  Scene out;
  out.name = scene.name + " (clipped)";
  out.materials = scene.materials;
  out.textures = scene.textures;
  out.texture_sources = scene.texture_sources;
  out.cameras = scene.cameras;
  out.lights = scene.lights;
  out.environment = scene.environment;
  const TriangleMesh& in = scene.mesh;
  TriangleMesh& m = out.mesh;
  m.positions = in.positions;
  m.normals = in.normals;
  m.tangents = in.tangents;
  m.uvs = in.uvs;
  m.uvs1 = in.uvs1;
  MeshWriter writer{in, m};
  const std::vector<float> dist = [&] {
    std::vector<float> d(in.positions.size());
    for (std::size_t v = 0; v < d.size(); ++v) d[v] = side * plane.signed_distance(in.positions[v]);
    return d;
  }();
  const auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::size_t t) {
    m.indices.insert(m.indices.end(), {a, b, c});
    m.triangle_material.push_back(in.triangle_material[t]);
    m.triangle_object.push_back(in.triangle_object[t]);
  };
  // Objects keep their contiguous ranges because clipped triangles are emitted in place.
  std::vector<Object> objects = scene.objects;
  std::vector<std::uint32_t> first(objects.size(), 0), count(objects.size(), 0);
  for (std::size_t o = 0; o < objects.size(); ++o) first[o] = kNoId;
  for (std::size_t t = 0; t < in.triangle_count(); ++t) {
    const std::uint32_t object = in.triangle_object[t];
    if (object == skip) continue;
    const std::size_t before = m.triangle_count();
    const std::array<std::uint32_t, 3> v = {in.indices[3 * t], in.indices[3 * t + 1],
                                            in.indices[3 * t + 2]};
    const int inside = (dist[v[0]] > 0.0f) + (dist[v[1]] > 0.0f) + (dist[v[2]] > 0.0f);
    if (inside == 3) {
      emit(v[0], v[1], v[2], t);
    } else if (inside > 0) {
      // Sutherland–Hodgman against one plane: at most four vertices, fanned in order so
      // the winding is kept.
      std::array<std::uint32_t, 4> poly{};
      int n = 0;
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = v[k], b = v[(k + 1) % 3];
        const bool ina = dist[a] > 0.0f, inb = dist[b] > 0.0f;
        if (ina) poly[n++] = a;
        if (ina != inb) poly[n++] = writer.lerp_vertex(a, b, dist[a] / (dist[a] - dist[b]));
      }
      for (int k = 1; k + 1 < n; ++k) emit(poly[0], poly[k], poly[k + 1], t);
    }
    if (object < objects.size() && m.triangle_count() > before) {
      if (first[object] == kNoId) first[object] = static_cast<std::uint32_t>(before);
      count[object] += static_cast<std::uint32_t>(m.triangle_count() - before);
    }
  }
  for (std::size_t o = 0; o < objects.size(); ++o) {
    objects[o].first_triangle = first[o] == kNoId ? 0 : first[o];
    objects[o].triangle_count = count[o];
  }
  out.objects = std::move(objects);
  return out;
}

}  // namespace speculum::raster
