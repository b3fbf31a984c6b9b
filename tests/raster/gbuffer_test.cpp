// Tests of the `gbuffer` node: world position, uv and normal-mapped shading normal of a
// textured quad against the analytic ray–plane intersection; every byte of the block-wise,
// streamed resolve (mesh arrays or per-triangle records) against a per-sample oracle.
#include "raster/gbuffer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "core/camera_rays.h"
#include "core/error.h"
#include "raster/gbuffer_stream.h"
#include "raster_test_scenes.h"

namespace speculum::raster {
namespace {

TEST(GBuffer, PositionUvAndNormalMapOnAQuad) {
  Scene scene;
  scene.name = "quad";
  Material m;
  m.base_color = glm::vec4(0.5f, 0.25f, 1.0f, 1.0f);
  m.metallic = 0.0f;
  m.roughness = 0.8f;
  m.normal_texture.texture = 0;
  scene.materials.push_back(m);
  // A constant tangent-space normal (0.6, 0, 0.8), stored as (n + 1) / 2.
  scene.textures.push_back(ImageRGBA(2, 2, glm::vec4(0.8f, 0.5f, 0.9f, 1.0f)));
  testing::add_triangles(scene, {{-2, -1, 0}, {2, -1, 0}, {2, 1, 0}, {-2, 1, 0}}, {0, 1, 2, 0, 2, 3},
                         {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  scene.mesh.tangents.assign(scene.mesh.positions.size(), glm::vec4(1, 0, 0, 1));
  Camera cam;
  cam.eye = {0.7f, -0.4f, 3.0f};
  cam.target = {0.2f, 0.1f, 0.0f};
  const int w = 96, h = 64;
  par::Executor ex(2);
  const auto vis = render_visibility(ex, scene, cam, w, h);
  const GBuffer g = resolve_gbuffer(ex, scene, vis, cam.eye);
  const glm::vec3 mapped = glm::normalize(glm::vec3(0.6f, 0.0f, 0.8f));
  std::size_t checked = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      if (!g.covered(i)) continue;
      const Ray r = primary_ray(cam, w, h, x + 0.5f, y + 0.5f);
      const float t = -r.origin.z / r.direction.z;
      const glm::vec3 p = r.origin + t * r.direction;
      EXPECT_LT(glm::length(g.position.pixels[i] - p), 2e-3f);
      EXPECT_NEAR(g.uv.pixels[i].x, (p.x + 2) / 4, 1e-3f);
      EXPECT_NEAR(g.uv.pixels[i].y, (p.y + 1) / 2, 1e-3f);
      EXPECT_LT(glm::length(g.normal.pixels[i] - mapped), 1e-5f);
      EXPECT_EQ(g.surface[i].base_color, glm::vec3(0.5f, 0.25f, 1.0f));
      EXPECT_EQ(g.reflector.pixels[i], kNoId);  // rough dielectric: not a reflector
      ++checked;
    }
  EXPECT_GT(checked, std::size_t(w * h / 3));
}

// A scene with every material path of the resolve: normal-mapped, textured, mirror,
// refractor, triangles whose vertex normals are all zero (face-normal fallback, on a
// textured and on a constant material, facing away from and towards the eye), a closed
// torus (back faces visible through nothing, front faces flipped towards the eye) and
// background around it.
Scene mixed_material_scene() {
  Scene scene;
  scene.name = "mixed";
  Material bumpy;
  bumpy.metallic = 0.0f;
  bumpy.roughness = 0.7f;
  bumpy.normal_texture.texture = 0;
  bumpy.normal_scale = 0.8f;
  Material textured;
  textured.metallic = 0.0f;
  textured.base_color_texture.texture = 1;
  Material mirror;
  mirror.roughness = 0.0f;
  Material glass;
  glass.metallic = 0.0f;
  glass.roughness = 0.0f;
  glass.transmission = 1.0f;
  scene.materials = {bumpy, textured, mirror, glass};
  ImageRGBA normal_map(4, 4);
  ImageRGBA checker(4, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      normal_map.at(x, y) = glm::vec4(0.3f + 0.1f * x, 0.45f + 0.05f * y, 0.9f, 1.0f);
      checker.at(x, y) = glm::vec4(0.2f * x, 0.9f - 0.2f * y, (x + y) % 2 ? 1.0f : 0.1f, 1.0f);
    }
  scene.textures = {normal_map, checker};
  testing::add_triangles(scene, {{-2, -1, 0}, {0, -1, 0}, {0, 1, 0}, {-2, 1, 0}}, {0, 1, 2, 0, 2, 3},
                         {{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0);
  testing::add_triangles(scene, {{0, -1, 0}, {2, -1, 0}, {2, 1, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 3},
                         {{0, 0}, {1.5f, 0}, {1.5f, 2}, {0, 2}}, 1);
  const std::size_t torus_first = scene.mesh.triangle_count();
  testing::add_torus(scene, {0.3f, 0.1f, 0.6f}, 0.5f, 0.2f, 24, 12);
  for (std::size_t t = torus_first; t < scene.mesh.triangle_count(); ++t)
    scene.mesh.triangle_material[t] = 2;
  testing::add_triangles(scene, {{-1.5f, -0.8f, 0.4f}, {-0.5f, -0.9f, 0.5f}, {-1.0f, 0.2f, 0.45f}},
                         {0, 1, 2}, {}, 3);
  const std::size_t flat_vertex = scene.mesh.positions.size();
  testing::add_triangles(scene, {{1.0f, -0.9f, 0.3f}, {1.8f, -0.8f, 0.3f}, {1.4f, -0.3f, 0.35f}},
                         {0, 1, 2}, {}, 1);
  testing::add_triangles(scene, {{-1.9f, 0.3f, 0.3f}, {-1.5f, 0.9f, 0.35f}, {-1.1f, 0.3f, 0.3f}},
                         {0, 1, 2}, {}, 2);
  for (std::size_t v = flat_vertex; v < scene.mesh.positions.size(); ++v)
    scene.mesh.normals[v] = glm::vec3(0.0f);
  scene.mesh.tangents.assign(scene.mesh.positions.size(), glm::vec4(1, 0, 0, -1));
  return scene;
}

// The G-buffer sample i as the node's contract defines it, computed the plain way (index
// gathers, one sample at a time), as the reference for the optimized resolve.
struct OracleSample {
  glm::vec3 position{0.0f}, normal{0.0f};
  glm::vec2 uv{0.0f};
  SurfaceParams surface;
  std::uint32_t object = kNoId, reflector = kNoId;
};

OracleSample oracle_sample(const Scene& scene, const VisibilityBuffer& vis, glm::vec3 eye,
                           std::size_t i) {
  OracleSample o;
  o.object = vis.object.pixels[i];
  const std::uint32_t t = vis.triangle.pixels[i];
  if (t == kNoId) return o;
  const TriangleMesh& m = scene.mesh;
  const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
  const glm::vec2 b = vis.bary.pixels[i];
  const float b0 = 1.0f - b.x - b.y;
  auto lerp3 = [&](const auto& a) { return b0 * a[i0] + b.x * a[i1] + b.y * a[i2]; };
  o.position = lerp3(m.positions);
  glm::vec3 n = lerp3(m.normals);
  const float nl = glm::length(n);
  n = nl > 1e-12f ? n / nl
                  : glm::normalize(glm::cross(m.positions[i1] - m.positions[i0],
                                              m.positions[i2] - m.positions[i0]));
  o.uv = lerp3(m.uvs);
  const glm::vec3 unmapped = n;  // the side is decided before the normal map
  const Material& mat = scene.materials[m.triangle_material[t]];
  if (mat.normal_texture.valid()) {  // glTF tangent-space normal mapping
    const glm::vec4 texel = sample_bilinear_repeat(
        scene.textures[mat.normal_texture.texture],
        glm::vec2(mat.normal_texture.uv_transform * glm::vec3(o.uv, 1.0f)));
    glm::vec3 nt = glm::vec3(texel) * 2.0f - 1.0f;
    nt.x *= mat.normal_scale;
    nt.y *= mat.normal_scale;
    const glm::vec4 tangent = lerp3(m.tangents);
    glm::vec3 tv = glm::vec3(tangent);
    tv = tv - glm::dot(tv, n) * n;
    tv /= glm::length(tv);
    const glm::vec3 bv = (tangent.w < 0.0f ? -1.0f : 1.0f) * glm::cross(n, tv);
    const glm::vec3 mapped = tv * nt.x + bv * nt.y + n * nt.z;
    n = mapped / glm::length(mapped);
  }
  o.surface = surface_params(scene, m.triangle_material[t], o.uv, glm::vec2(0.0f));
  if (!o.surface.is_refractor() && glm::dot(unmapped, eye - o.position) < 0.0f) n = -n;
  o.normal = n;
  o.reflector = is_specular(o.surface) ? o.object : kNoId;
  return o;
}

template <class T>
bool same_object_bytes(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Counts the samples of g whose bytes differ from the oracle (background included).
std::size_t mismatches(const Scene& scene, const VisibilityBuffer& vis, glm::vec3 eye,
                       const GBuffer& g) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < vis.triangle.size(); ++i) {
    const OracleSample o = oracle_sample(scene, vis, eye, i);
    bad += !(same_object_bytes(g.object.pixels[i], o.object) && same_object_bytes(g.position.pixels[i], o.position) &&
             same_object_bytes(g.normal.pixels[i], o.normal) && same_object_bytes(g.uv.pixels[i], o.uv) &&
             same_object_bytes(g.surface[i], o.surface) &&
             same_object_bytes(g.reflector.pixels[i], o.reflector));
  }
  return bad;
}

// Fills every plane with a byte pattern, as a buffer reused from another frame would be.
void scribble(GBuffer& g) {
  auto fill = [](auto& plane) {
    std::memset(static_cast<void*>(plane.pixels.data()), 0x5a, plane.size() * sizeof(plane.pixels[0]));
  };
  fill(g.object), fill(g.position), fill(g.normal), fill(g.uv), fill(g.reflector);
  fill(g.surface.slot), fill(g.surface.own);
}

// Both triangle sources, at a size below and one above the streaming-store threshold, any
// thread count, into fresh and reused (scribbled) buffers: every byte equals the oracle.
TEST(GBuffer, EveryByteMatchesAPerSampleOracle) {
  const Scene scene = mixed_material_scene();
  Camera cam;
  cam.eye = {0.4f, -0.6f, 3.2f};
  cam.target = {0.0f, 0.0f, 0.3f};
  par::Executor ex2(2);
  const GBufferTriangles records(ex2, scene);
  for (const auto& [w, h] : {std::pair{96, 64}, std::pair{640, 420}}) {
    const auto vis = render_visibility(ex2, scene, cam, w, h);
    std::size_t materials_seen[4] = {}, background = 0;
    for (std::size_t i = 0; i < vis.triangle.size(); ++i) {
      const std::uint32_t t = vis.triangle.pixels[i];
      if (t == kNoId) ++background;
      else ++materials_seen[scene.mesh.triangle_material[t]];
    }
    for (std::size_t k = 0; k < 4; ++k) EXPECT_GT(materials_seen[k], 10u) << "material " << k;
    std::size_t flat = 0;  // samples on the two zero-normal triangles (the last two)
    for (std::size_t i = 0; i < vis.triangle.size(); ++i)
      flat += vis.triangle.pixels[i] + 2 >= scene.mesh.triangle_count() &&
              vis.triangle.pixels[i] != kNoId;
    EXPECT_GT(flat, 10u);
    EXPECT_GT(background, 10u);
    const GBuffer fresh = resolve_gbuffer(ex2, scene, vis, cam.eye);
    EXPECT_EQ(mismatches(scene, vis, cam.eye, fresh), 0u) << w << "x" << h << " mesh, fresh";
    for (const int threads : {1, 2, 8}) {
      par::Executor ex(threads);
      GBuffer g = fresh;
      scribble(g);
      resolve_gbuffer(ex, scene, &records, vis, cam.eye, g);
      EXPECT_EQ(mismatches(scene, vis, cam.eye, g), 0u) << w << "x" << h << " records, " << threads;
      scribble(g);
      resolve_gbuffer(ex, scene, vis, cam.eye, g);
      EXPECT_EQ(mismatches(scene, vis, cam.eye, g), 0u) << w << "x" << h << " mesh, " << threads;
    }
  }
}

// The distances distance-only maps store: every covered sample's entry has the bits of the
// per-sample expression, every uncovered one keeps what it held, for ranges starting and
// ending anywhere (runs of eight on one triangle, mixed runs, background, tails).
TEST(GBuffer, VisibleDistancesHaveTheBitsOfTheScalarExpression) {
  const Scene scene = mixed_material_scene();
  Camera cam;
  cam.eye = {0.4f, -0.6f, 3.2f};
  cam.target = {0.0f, 0.0f, 0.3f};
  par::Executor ex(2);
  const auto vis = render_visibility(ex, scene, cam, 97, 61);
  const glm::vec3 from(0.3f, -1.7f, 2.9f);
  std::size_t one_triangle_runs = 0, mixed_runs = 0;
  for (std::size_t i = 0; i + 8 <= vis.triangle.size(); i += 8) {
    const auto* t = &vis.triangle.pixels[i];
    const bool same = std::all_of(t, t + 8, [&](std::uint32_t x) { return x == t[0]; });
    (same && t[0] != kNoId ? one_triangle_runs : mixed_runs) += 1;
  }
  EXPECT_GT(one_triangle_runs, 50u);
  EXPECT_GT(mixed_runs, 50u);
  for (const auto& [begin, end] : {std::pair<std::size_t, std::size_t>{0, vis.triangle.size()},
                                   {3, vis.triangle.size() - 5}, {1000, 1013}, {77, 77}}) {
    std::vector<float> out(end - begin, -7.0f);
    visible_distances(scene.mesh, vis, from, begin, end, out.data());
    std::size_t bad = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const float expected = vis.triangle.pixels[i] == kNoId
                                 ? -7.0f
                                 : glm::length(visible_position(scene.mesh, vis, i) - from);
      bad += std::memcmp(&expected, &out[i - begin], sizeof(float)) != 0;
    }
    EXPECT_EQ(bad, 0u) << "range " << begin << ".." << end;
  }
}

// The line-phase staging writer: for every 4-byte phase of the run's start, run lengths that
// end inside and on line boundaries, and blocks of uneven sizes, with and without streaming,
// the run's bytes arrive in order and not one byte outside the run changes.
TEST(GBuffer, LineWriterWritesExactlyTheRun) {
  constexpr std::size_t kBlockBytes = 176;
  std::vector<unsigned char> dst(2048 + 128);
  auto* base = reinterpret_cast<unsigned char*>(
      (reinterpret_cast<std::uintptr_t>(dst.data()) + 63) & ~std::uintptr_t(63));
  for (const bool stream : {false, true}) {
    for (std::size_t phase = 0; phase < 64; phase += 4) {
      for (const std::size_t run : {std::size_t(0), std::size_t(4), std::size_t(60), std::size_t(64),
                                    64 - phase, 128 - phase, std::size_t(1000), 1536 - phase}) {
        std::fill(dst.begin(), dst.end(), 0xa5);
        detail::LineWriter<kBlockBytes> w(base + phase, stream);
        std::size_t written = 0, step = 0;
        while (written < run) {
          const std::size_t n = std::min(run - written, std::size_t(4) * (1 + (step++ * 13) % 44));
          unsigned char* slot = w.next();
          for (std::size_t k = 0; k < n; ++k) slot[k] = static_cast<unsigned char>(written + k);
          w.commit(n);
          written += n;
        }
        w.finish();
        detail::end_stores(stream);
        std::size_t bad = 0;
        for (std::size_t k = 0; k < dst.size(); ++k) {
          const auto* at = dst.data() + k;
          const bool inside = at >= base + phase && at < base + phase + run;
          const unsigned char want = inside ? static_cast<unsigned char>(at - base - phase) : 0xa5;
          bad += dst[k] != want;
        }
        EXPECT_EQ(bad, 0u) << "stream " << stream << " phase " << phase << " run " << run;
      }
    }
  }
}

TEST(GBuffer, TriangleRecordsCopyTheMeshCorners) {
  const Scene scene = mixed_material_scene();
  par::Executor ex(2);
  const GBufferTriangles records(ex, scene);
  ASSERT_EQ(records.size(), scene.mesh.triangle_count());
  const TriangleMesh& m = scene.mesh;
  for (std::size_t t = 0; t < records.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.indices[3 * t + k];
      EXPECT_TRUE(same_object_bytes(records[t].corner[k].position, m.positions[v]));
      EXPECT_TRUE(same_object_bytes(records[t].corner[k].normal, m.normals[v]));
      EXPECT_TRUE(same_object_bytes(records[t].corner[k].uv, m.uvs[v]));
    }
    EXPECT_EQ(records.materials()[t], m.triangle_material[t]);
  }
}

TEST(GBuffer, RecordsOfAnotherMeshAreRejected) {
  const Scene scene = mixed_material_scene();
  Scene other;
  testing::add_triangles(other, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  par::Executor ex(1);
  const GBufferTriangles records(ex, other);
  Camera cam;
  const auto vis = render_visibility(ex, scene, cam, 16, 16);
  GBuffer g;
  EXPECT_THROW(resolve_gbuffer(ex, scene, &records, vis, cam.eye, g), InputError);
  Scene broken = other;
  broken.mesh.normals.pop_back();
  EXPECT_THROW(GBufferTriangles(ex, broken), InputError);
}

}  // namespace
}  // namespace speculum::raster
