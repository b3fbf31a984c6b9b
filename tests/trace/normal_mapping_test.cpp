// Normal mapping in the reference tracer, against analytic shading and against the
// rasterizer's G-buffer: both take the perturbation from core/normal_mapping.h, in glTF's
// tangent-space convention (glTF 2.0 spec §3.9.3: +X along +u, +Y up the image, i.e.
// against v; B = cross(N, T) · w).
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "core/mesh_normals.h"
#include "core/normal_mapping.h"
#include "core/sampling.h"
#include "core/shading.h"
#include "raster/gbuffer.h"
#include "raster/visibility.h"
#include "trace/bvh.h"
#include "trace/hit_surface.h"
#include "trace/reference_tracer.h"
#include "trace/traversal.h"

namespace speculum::trace {
namespace {

constexpr float kDeg = kPi / 180.0f;

// The texel encoding unit tangent-space normal nt: (nt + 1) / 2.
glm::vec4 encode(const glm::vec3& nt) { return glm::vec4((nt + 1.0f) * 0.5f, 1.0f); }

// Appends a grid of (cols × rows) quads: vertex (i, j) at `position(i / cols, j / rows)` with
// unit normal `normal(...)` and uv `uv(...)`, tangents derived from the uvs as the glTF loader
// derives them. One object, material 0.
template <class Position, class Normal, class Uv>
void add_grid(Scene& scene, int cols, int rows, Position position, Normal normal, Uv uv) {
  TriangleMesh& m = scene.mesh;
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i <= cols; ++i) {
      const float a = static_cast<float>(i) / cols, b = static_cast<float>(j) / rows;
      m.positions.push_back(position(a, b));
      m.normals.push_back(normal(a, b));
      m.uvs.push_back(uv(a, b));
    }
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < cols; ++i) {
      const std::uint32_t v00 = j * (cols + 1) + i, v10 = v00 + 1, v01 = v00 + cols + 1, v11 = v01 + 1;
      m.indices.insert(m.indices.end(), {v00, v10, v11, v00, v11, v01});
      m.triangle_material.insert(m.triangle_material.end(), 2, 0u);
      m.triangle_object.insert(m.triangle_object.end(), 2, 0u);
    }
  m.tangents = uv_tangents(m.positions, m.normals, m.uvs, m.indices);
  scene.objects.push_back({"grid", 0, static_cast<std::uint32_t>(m.triangle_count()), 0});
}

// A 4 × 4 plane in z = 0 facing +z, its normal texture upright on it: u runs along +x and v
// down the image while y goes up (`mirrored`: v runs up with y, the map flipped vertically).
Scene normal_mapped_plane(const ImageRGBA& normal_map, float scale, bool mirrored) {
  Scene scene;
  scene.name = "normal-mapped plane";
  Material m;
  m.base_color = glm::vec4(0.8f, 0.6f, 0.4f, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.7f;
  m.normal_texture.texture = 0;
  m.normal_scale = scale;
  scene.materials.push_back(m);
  scene.textures.push_back(normal_map);
  add_grid(
      scene, 2, 2, [](float a, float b) { return glm::vec3(4 * a - 2, 4 * b - 2, 0); },
      [](float, float) { return glm::vec3(0, 0, 1); },
      [mirrored](float a, float b) { return glm::vec2(a, mirrored ? b : 1 - b); });
  return scene;
}

Camera looking_down(glm::vec3 eye) {
  Camera cam;
  cam.eye = eye;
  cam.target = {0.0f, 0.0f, 0.0f};
  return cam;
}

// The reference tracer's shading normal through the centre of pixel (x, y): the surface its
// radiance estimate is shaded with (hit_surface). Zero where the ray misses.
glm::vec3 reference_normal(const Scene& scene, const Bvh& bvh, const Camera& cam, int w, int h,
                           int x, int y) {
  const Ray r = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
  const Hit hit = closest_hit(bvh, r);
  return hit.hit() ? hit_surface(scene, hit, r.direction).n : glm::vec3(0.0f);
}

// A constant texel tilting the normal 30° towards +u (tangent space (sin 30°, 0, cos 30°)),
// one directional light grazing the plane at 80° from the normal from the +u side: every
// pixel of the reference is core's shade_light of the tilted normal, not of the plane's.
TEST(NormalMapping, ReferenceShadesThePerturbedNormal) {
  const glm::vec3 tilted(std::sin(30 * kDeg), 0.0f, std::cos(30 * kDeg));  // in world: T = +x
  Scene scene = normal_mapped_plane(ImageRGBA(2, 2, encode(tilted)), 1.0f, false);
  Light sun;
  sun.type = LightType::Directional;
  sun.intensity = 3.0f;
  sun.direction = -glm::vec3(std::sin(80 * kDeg), 0.0f, std::cos(80 * kDeg));  // travels to −x, −z
  scene.lights.push_back(sun);
  const Camera cam = looking_down({0.3f, -0.2f, 3.0f});
  ReferenceOptions opt;
  opt.width = 24;
  opt.height = 16;
  opt.spp = 1;
  opt.environment_lighting = false;
  par::Executor ex(2);
  const ImageRGBA image = render_reference(scene, cam, opt, ex);
  const SurfaceParams s = surface_params(scene.materials[0]);
  for (int y = 0; y < opt.height; ++y)
    for (int x = 0; x < opt.width; ++x) {
      const Ray r = primary_ray(cam, opt.width, opt.height, x + 0.5f, y + 0.5f);
      const glm::vec3 p = r.origin + (-r.origin.z / r.direction.z) * r.direction;
      ASSERT_LT(std::fabs(p.x), 2.0f);
      ASSERT_LT(std::fabs(p.y), 2.0f);
      const glm::vec3 v = -glm::normalize(r.direction);
      const LightSample ls = sample_light(sun, p);
      const glm::vec3 expected = shade_light(s, tilted, v, ls);
      const glm::vec3 flat = shade_light(s, glm::vec3(0, 0, 1), v, ls);
      const glm::vec3 got = glm::vec3(image.at(x, y));
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(got[c], expected[c], 2e-5f * expected[c] + 1e-7f) << x << "," << y << " channel " << c;
        // N·L is cos 50° against cos 80°: the flat plane would be far darker.
        EXPECT_GT(got[c], 2.0f * flat[c]) << x << "," << y;
      }
    }
}

// A smoothly varying map (bilinear between 4 × 4 texels, scale 0.8) on a curved, vertex-
// normal-shaded cylinder patch with derived tangents: at every pixel the G-buffer's shading
// normal and the reference's hit normal through the pixel centre agree, and both differ
// clearly from the unmapped normal.
TEST(NormalMapping, GBufferAndReferenceAgreeOnTheShadingNormal) {
  ImageRGBA normal_map(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const float ax = 0.35f + (x - 1.5f) * 0.2f, ay = 0.3f + (1.5f - y) * 0.15f;  // never 0
      normal_map.at(x, y) = encode(glm::normalize(glm::vec3(std::sin(ax), std::sin(ay), 1.0f)));
    }
  Scene scene;
  scene.name = "normal-mapped cylinder";
  Material m;
  m.metallic = 0.0f;
  m.roughness = 0.7f;
  m.normal_texture.texture = 0;
  m.normal_scale = 0.8f;
  scene.materials.push_back(m);
  scene.textures.push_back(normal_map);
  const float radius = 1.5f;
  add_grid(
      scene, 24, 4,
      [&](float a, float b) {
        const float phi = (a - 0.5f) * 120 * kDeg;
        return glm::vec3(radius * std::sin(phi), 2 * b - 1, radius * std::cos(phi) - radius);
      },
      [](float a, float) {
        const float phi = (a - 0.5f) * 120 * kDeg;
        return glm::vec3(std::sin(phi), 0.0f, std::cos(phi));
      },
      [](float a, float b) { return glm::vec2(a, 1 - b); });
  const Camera cam = looking_down({0.4f, 0.3f, 3.5f});
  const int w = 64, h = 48;
  par::Executor ex(2);
  const raster::VisibilityBuffer vis = raster::render_visibility(ex, scene, cam, w, h);
  const raster::GBuffer g = raster::resolve_gbuffer(ex, scene, vis, cam.eye);
  const Bvh bvh = Bvh::build(scene.mesh, ex);
  std::size_t compared = 0;
  float worst = 0.0f, mapped_min = 1.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const glm::vec3 traced = reference_normal(scene, bvh, cam, w, h, x, y);
      if (!g.covered(i) || traced == glm::vec3(0.0f)) continue;
      worst = std::max(worst, glm::length(g.normal.pixels[i] - traced));
      // The unmapped normal at the hit: radial, from the hit's position.
      const glm::vec3 p = g.position.pixels[i];
      const glm::vec3 radial = glm::normalize(glm::vec3(p.x, 0.0f, p.z + radius));
      mapped_min = std::min(mapped_min, glm::length(traced - radial));
      ++compared;
    }
  EXPECT_GT(compared, std::size_t(w * h / 4));
  EXPECT_LT(worst, 1e-3f);  // measured 2.2e-4: raster vs ray barycentrics
  EXPECT_GT(mapped_min, 0.05f);  // the map tilts every visible normal by about 3° or more
}

// The map's +Y is up the image (glTF): with the map upright on the plane (y up, v down) a
// texel tilted towards +Y tilts the normal towards +y, and the derived tangent has w = +1.
// Mirroring the map vertically (v up) makes the derived w = −1, which flips the bitangent:
// the same texel now tilts the normal towards −y, in the reference and the G-buffer alike.
TEST(NormalMapping, NegativeTangentWFlipsTheBitangent) {
  const glm::vec3 up_tilt(0.0f, std::sin(30 * kDeg), std::cos(30 * kDeg));
  // perturb_normal alone: w = −1 mirrors the result across the T–N plane.
  const glm::vec3 n(0, 0, 1);
  const glm::vec3 plus = perturb_normal(n, glm::vec4(1, 0, 0, 1), encode(up_tilt), 1.0f);
  const glm::vec3 minus = perturb_normal(n, glm::vec4(1, 0, 0, -1), encode(up_tilt), 1.0f);
  EXPECT_LT(glm::length(plus - up_tilt), 1e-6f);
  EXPECT_LT(glm::length(minus - glm::vec3(up_tilt.x, -up_tilt.y, up_tilt.z)), 1e-6f);

  const Camera cam = looking_down({0.2f, 0.1f, 3.0f});
  const int w = 20, h = 16;
  par::Executor ex(2);
  for (const bool mirrored : {false, true}) {
    SCOPED_TRACE(mirrored ? "mirrored map" : "upright map");
    const Scene scene = normal_mapped_plane(ImageRGBA(2, 2, encode(up_tilt)), 1.0f, mirrored);
    for (const glm::vec4& t : scene.mesh.tangents) {
      EXPECT_LT(glm::length(glm::vec3(t) - glm::vec3(1, 0, 0)), 1e-6f);
      EXPECT_EQ(t.w, mirrored ? -1.0f : 1.0f);
    }
    const glm::vec3 expected(0.0f, (mirrored ? -1.0f : 1.0f) * up_tilt.y, up_tilt.z);
    const raster::VisibilityBuffer vis = raster::render_visibility(ex, scene, cam, w, h);
    const raster::GBuffer g = raster::resolve_gbuffer(ex, scene, vis, cam.eye);
    const Bvh bvh = Bvh::build(scene.mesh, ex);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = std::size_t(y) * w + x;
        ASSERT_TRUE(g.covered(i));
        EXPECT_LT(glm::length(reference_normal(scene, bvh, cam, w, h, x, y) - expected), 1e-6f);
        EXPECT_LT(glm::length(g.normal.pixels[i] - expected), 1e-6f);
      }
  }
}

// Without vertex tangents both sides derive the tangent from the hit triangle's own uv
// gradients (surface_tangent), mirrored maps included.
TEST(NormalMapping, TangentFromTheTriangleWhenTheMeshHasNone) {
  const glm::vec3 up_tilt(0.0f, std::sin(20 * kDeg), std::cos(20 * kDeg));
  const Camera cam = looking_down({0.2f, 0.1f, 3.0f});
  const int w = 12, h = 10;
  par::Executor ex(2);
  for (const bool mirrored : {false, true}) {
    SCOPED_TRACE(mirrored ? "mirrored map" : "upright map");
    Scene scene = normal_mapped_plane(ImageRGBA(2, 2, encode(up_tilt)), 1.0f, mirrored);
    scene.mesh.tangents.clear();
    const glm::vec4 t = surface_tangent(scene.mesh, 0, 0.2f, 0.3f, glm::vec3(0, 0, 1), 0);
    EXPECT_LT(glm::length(glm::vec3(t) - glm::vec3(1, 0, 0)), 1e-6f);
    EXPECT_EQ(t.w, mirrored ? -1.0f : 1.0f);
    const glm::vec3 expected(0.0f, (mirrored ? -1.0f : 1.0f) * up_tilt.y, up_tilt.z);
    const raster::VisibilityBuffer vis = raster::render_visibility(ex, scene, cam, w, h);
    const raster::GBuffer g = raster::resolve_gbuffer(ex, scene, vis, cam.eye);
    const Bvh bvh = Bvh::build(scene.mesh, ex);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        EXPECT_LT(glm::length(reference_normal(scene, bvh, cam, w, h, x, y) - expected), 1e-6f);
        EXPECT_LT(glm::length(g.normal.pixels[std::size_t(y) * w + x] - expected), 1e-6f);
      }
  }
}

}  // namespace
}  // namespace speculum::trace
