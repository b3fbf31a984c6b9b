// The `shadow_map` node: see shadow_map.h. Directional lights use a perspective camera far
// away with a narrow field of view (the rasterizer only has perspective cameras); at 50
// scene radii its rays are parallel to within about one degree.
#include "raster/shadow_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/camera_rays.h"
#include "parallel/lanes.h"
#include "raster/cube_coord_lanes.h"

namespace speculum::raster {
namespace {

constexpr float kDirectionalDistance = 50.0f;  // in scene radii

// Self-shadowing bias, in receiver footprints (the world width of one map texel at the
// receiver, across the light's rays). The 3×3 PCF compares the receiver's distance with
// texels up to 1.5 texels away along each map axis, ≈ 2.1 footprints along the diagonal.
// Across that offset s a planar receiver at angle θ between n and l comes s·tan θ nearer
// the light: the slope term that makes acne, unbounded at grazing incidence. Moving the
// lookup point off the surface by δ = k·footprint·sin θ along n puts it δ/cos θ =
// k·footprint·tan θ in front of the plane along the light ray, so it cancels the slope
// term at every angle; what the offset leaves, (2.1 − k)·tan θ, the depth bias below
// covers up to θ ≈ 83° (cos θ ≈ 0.12, where the light is dim). The shadow-test point moves
// by at most k footprints, which is also how far shadow edges can shift.
constexpr float kNormalOffset = 2.0f;
// Slope-independent: curvature of the receiver across the kernel and the map's float
// distances. One footprint along the ray bounds the light that can leak under an occluder
// touching the receiver (a slope-scaled term would grow without bound at grazing incidence
// and light the plane behind thin occluders).
constexpr float kDepthBias = 1.0f;

float normal_offset(float footprint, const glm::vec3& n, const glm::vec3& l) {
  const float c = std::clamp(glm::dot(n, l), 0.0f, 1.0f);
  return kNormalOffset * footprint * std::sqrt(1.0f - c * c);
}

// The faces of a spot light's shadow cube that a shadow test can read: visibility runs only
// where sample_light gives the light (every caller skips a zero irradiance), i.e. at points
// within the outer cone, and it looks up p + q n with q at most kNormalOffset footprints
// (2 kNormalOffset |p − light| / size), at most asin(2 kNormalOffset / size) off p's
// direction; its 3×3 taps stay on the face that lookup lands on. The cone is widened by that
// and 1e-3 rad for the rounding of the cone test.
unsigned spot_cone_faces(const Light& light, int size) {
  const float shift = 2.0f * kNormalOffset / static_cast<float>(size);
  if (!(shift < 0.5f) || !(light.outer_cone < 1.5f)) return 0x3fu;
  return cube_faces_near(glm::normalize(light.direction), light.outer_cone + std::asin(shift) + 1e-3f);
}

}  // namespace

std::vector<ShadowMap> render_shadow_maps(par::Executor& executor, const Scene& scene, int size) {
  std::vector<ShadowMap> maps;
  const Bounds b = scene.bounds();
  const glm::vec3 centre = b.valid() ? b.center() : glm::vec3(0.0f);
  const float radius = b.valid() ? std::max(0.5f * glm::length(b.extent()), 1e-3f) : 1.0f;
  CubeMapScratch scratch;  // shared by the lights' cube maps
  for (const Light& light : scene.lights) {
    ShadowMap m;
    m.type = light.type;
    m.size = size;
    if (light.type == LightType::Directional) {
      const glm::vec3 dir = glm::normalize(light.direction);
      const float dist = kDirectionalDistance * radius;
      m.camera.name = "shadow " + light.name;
      m.camera.eye = centre - dir * dist;
      m.camera.target = centre;
      m.camera.up = std::abs(dir.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      m.camera.vfov_degrees = 2.0f * glm::degrees(std::asin(std::min(1.0f, radius / dist))) * 1.02f;
      m.camera.znear = std::max(dist - 1.5f * radius, 1e-3f);
      m.camera.zfar = dist + 1.5f * radius;
      m.view_projection = projection_matrix(m.camera, size, size) * view_matrix(m.camera);
      const VisibilityBuffer vis = render_visibility(executor, scene, m.camera, size, size);
      m.distance = ImageF(size, size, std::numeric_limits<float>::infinity());
      executor.parallel_for("shadow_map.distance", m.distance.size(), 4096,
                            [&](std::size_t begin, std::size_t end) {
                              visible_distances(scene.mesh, vis, m.camera.eye, begin, end,
                                                m.distance.pixels.data() + begin);
                            });
    } else {
      CubeMapOptions opt;
      opt.size = size;
      opt.znear = 1e-3f * radius;
      opt.zfar = 4.0f * radius + glm::length(light.position - centre);
      if (light.type == LightType::Spot) opt.face_mask = spot_cone_faces(light, size);
      m.faces = opt.face_mask;
      m.cube = render_cube_map(executor, scene, light.position, opt, {}, &scratch);
    }
    maps.push_back(std::move(m));
  }
  return maps;
}

float ShadowMap::visibility(const glm::vec3& p, const glm::vec3& n, const glm::vec3& l) const {
  return filtered(taps(p, n, l));
}

ShadowMap::Taps ShadowMap::taps(const glm::vec3& p, const glm::vec3& n, const glm::vec3& l) const {
  // The receiver's footprint: world width of one map texel at p, across the light's rays.
  // A cube texel subtends at most 2/size radians (its width on the unit-distance face
  // plane, at the face centre); a directional texel is one slice of the far camera's frustum.
  const glm::vec3 eye = type == LightType::Directional ? camera.eye : cube.centre;
  const float texel_angle =
      type == LightType::Directional
          ? 2.0f * std::tan(glm::radians(camera.vfov_degrees) * 0.5f) / static_cast<float>(size)
          : 2.0f / static_cast<float>(cube.size);
  const float footprint = glm::length(p - eye) * texel_angle;
  const float q = normal_offset(footprint, n, l);
  const glm::vec3 lookup = p + n * q;
  const glm::vec3 d = lookup - eye;
  const float dist = glm::length(d);
  if (dist <= 0.0f) return {};

  const ImageF* img;
  glm::vec2 pixel;
  if (type == LightType::Directional) {
    const glm::vec4 clip = view_projection * glm::vec4(lookup, 1.0f);
    if (clip.w <= 0.0f) return {};
    pixel = {(clip.x / clip.w * 0.5f + 0.5f) * size, (0.5f - clip.y / clip.w * 0.5f) * size};
    if (pixel.x < 0 || pixel.y < 0 || pixel.x >= size || pixel.y >= size) return {};
    img = &distance;
  } else {
    const CubeCoord c = cube_coord(d, cube.size);
    img = &cube.distance[c.face];
    pixel = c.pixel;
  }
  const float biased = dist - kDepthBias * footprint;
  const int cx = std::min(static_cast<int>(pixel.x), size - 1);
  const int cy = std::min(static_cast<int>(pixel.y), size - 1);
  return {img, cx, cy, biased};
}

float ShadowMap::filtered(const Taps& t) const {
  if (!t.img) return 1.0f;
  const ImageF* img = t.img;
  const int cx = t.cx, cy = t.cy;
  const float biased = t.biased;
  int lit = 0;
  if (cx >= 1 && cy >= 1 && cx + 1 < size && cy + 1 < size) {  // no tap clamped: three rows
    for (int dy = -1; dy <= 1; ++dy) {
      const float* row = &img->at(cx - 1, cy + dy);
      lit += (row[0] >= biased) + (row[1] >= biased) + (row[2] >= biased);
    }
    return lit / 9.0f;
  }
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = std::clamp(cx + dx, 0, size - 1), y = std::clamp(cy + dy, 0, size - 1);
      lit += img->at(x, y) >= biased;
    }
  return lit / 9.0f;
}

void ShadowMap::visibility_lanes(const Vec3Lanes<8>& p, const Vec3Lanes<8>& n, const Vec3Lanes<8>& l, unsigned lanes,
                                 float* out) const {
  Taps t[8];
  taps_lanes(p, n, l, lanes, t);
  for (unsigned m = lanes; m; m &= m - 1) {
    const int j = std::countr_zero(m);
    out[j] = filtered(t[j]);
  }
}

void ShadowMap::taps_lanes(const Vec3Lanes<8>& p, const Vec3Lanes<8>& n, const Vec3Lanes<8>& l, unsigned lanes,
                           Taps* out) const {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using i32 = L::i32;
  if (type == LightType::Directional) {
    glm::vec3 ps[8], ns[8], ls[8];
    p.store(ps, 8), n.store(ns, 8), l.store(ls, 8);
    for (unsigned m = lanes; m; m &= m - 1) {
      const int j = std::countr_zero(m);
      out[j] = taps(ps[j], ns[j], ls[j]);
    }
    return;
  }
  const f32 pv[3] = {p.x, p.y, p.z}, nv[3] = {n.x, n.y, n.z}, lv[3] = {l.x, l.y, l.z};
  // glm's dot of two vec3 is (x·x' + y·y') + z·z', and length is the root of the dot.
  const auto dot = [](const f32* a, const f32* b) { return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2]; };
  const glm::vec3 eye = cube.centre;
  const float texel_angle = 2.0f / static_cast<float>(cube.size);
  f32 from_eye[3];
  for (int c = 0; c < 3; ++c) from_eye[c] = pv[c] - eye[c];
  const f32 footprint = L::sqrt(dot(from_eye, from_eye)) * texel_angle;
  // normal_offset
  const f32 cos_nl = L::clamp(dot(nv, lv), f32(0.0f), f32(1.0f));
  const f32 q = kNormalOffset * footprint * L::sqrt(1.0f - cos_nl * cos_nl);
  f32 d[3];
  for (int c = 0; c < 3; ++c) d[c] = (pv[c] + nv[c] * q) - eye[c];
  const f32 dist = L::sqrt(dot(d, d));
  const CubeCoordLanes c = cube_coord8(d, cube.size);
  const f32 biased = dist - kDepthBias * footprint;
  const i32 cx = L::min(L::to_int(c.x), i32(size - 1)), cy = L::min(L::to_int(c.y), i32(size - 1));
  alignas(32) float dist_at[8], biased_at[8];
  alignas(32) std::int32_t face_at[8], cx_at[8], cy_at[8];
  L::store_aligned(dist, dist_at), L::store_aligned(biased, biased_at);
  L::store_aligned(c.face, face_at), L::store_aligned(cx, cx_at), L::store_aligned(cy, cy_at);
  for (unsigned m = lanes; m; m &= m - 1) {
    const int j = std::countr_zero(m);
    out[j] = dist_at[j] <= 0.0f ? Taps{} : Taps{&cube.distance[face_at[j]], cx_at[j], cy_at[j], biased_at[j]};
  }
}

ShadowMaps ShadowMapPass::operator()(par::NodeContext& c) const {
  return render_shadow_maps(c.executor(), *scene, size);
}

}  // namespace speculum::raster
