// Second-order feed-forward reflections: see soff.h.
#include "raster/soff.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/optics.h"
#include "core/shading.h"
#include "core/sampling.h"
#include "parallel/lanes.h"
#include "raster/direct_light.h"
#include "raster/specular_radiance.h"
#include "raster/tile_binning.h"
#include "raster/triangle_setup.h"
#include "raster/visibility.h"

namespace speculum::raster {

namespace {
constexpr float kRadToDeg = 57.29577951308232f;
// Reflected rays this close to parallel with the image plane (|r·n_c|) cannot be framed by
// a camera behind the plane: they are left out of the frame and take the environment.
constexpr float kMinAxisCos = 0.02f;
// The glossy frame widening stops short of a hemisphere (tan grows without bound).
constexpr float kMaxCone = 1.3f;
// Triangles are culled per cluster frustum in groups of this many consecutive triangles of
// one object (procedural and loaded meshes store neighbours together, so the groups' boxes
// are tight): a box test per group, then only the kept groups' vertices are transformed.
constexpr std::uint32_t kCullGroup = 128;
// Depth-image pixels per cluster sample at image_scale 1 (see soff_camera's step 5).
constexpr double kMaxPixelsPerSample = 4.0;
}  // namespace

// ---------------------------------------------------------------------------------------
// Clustering

void soff_bin(const glm::vec3& n, float scale, const SoffBinSettings& bins, int& i, int& j) {
  float theta = std::atan2(n.z, n.x) * kRadToDeg;
  if (theta < 0.0f) theta += 360.0f;
  const float phi = std::acos(std::clamp(n.y, -1.0f, 1.0f)) * kRadToDeg;
  i = std::clamp(static_cast<int>(std::floor(float(bins.theta_bins) * theta / 360.0f * scale)), 0,
                 bins.theta_bins - 1);
  j = std::clamp(static_cast<int>(std::floor(float(bins.phi_bins) * phi / 180.0f * scale)), 0,
                 bins.phi_bins - 1);
}

float soff_bin_scale(double percent, int visible, double gain) {
  if (visible < 1) return 1.0f;
  return static_cast<float>(std::min(1.0, gain * percent / double(visible)));
}

SoffClusters soff_cluster(par::Executor& executor, const GBuffer& g, const SoffBinSettings& bins) {
  SoffClusters out;
  out.width = g.width;
  out.height = g.height;
  const std::size_t n = g.object.size();
  // a_R: samples per reflector (the screen share), serially: one pass of integer adds.
  std::uint32_t max_object = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (g.covered(i)) max_object = std::max(max_object, g.object.pixels[i]);
  std::vector<std::uint64_t> per_object(n ? std::size_t(max_object) + 1 : 0, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (g.covered(i) && soff_reflects(g.surface[i])) ++per_object[g.object.pixels[i]];
  std::vector<std::uint32_t> visible_index(per_object.size(), kNoId);
  std::vector<std::uint32_t> visible_object;
  for (std::size_t o = 0; o < per_object.size(); ++o)
    if (per_object[o] > 0) {
      visible_index[o] = static_cast<std::uint32_t>(visible_object.size());
      visible_object.push_back(static_cast<std::uint32_t>(o));
    }
  out.visible_reflectors = static_cast<int>(visible_object.size());
  std::vector<float> scale(visible_object.size());
  for (std::size_t k = 0; k < visible_object.size(); ++k)
    scale[k] = soff_bin_scale(100.0 * double(per_object[visible_object[k]]) / double(n),
                              out.visible_reflectors, bins.share_gain);
  const std::uint32_t per_reflector = std::uint32_t(bins.theta_bins) * std::uint32_t(bins.phi_bins);
  // The fixed bin array: visible reflectors × θ bins × φ bins; each sample's bin is a pure
  // function of its own normal and reflector (SOFF §4.3: no neighbour information).
  std::vector<std::uint32_t> bin(n, kNoId);
  executor.parallel_for("soff_clusters.bin", n, 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i) || !soff_reflects(g.surface[i])) continue;
      const std::uint32_t k = visible_index[g.object.pixels[i]];
      int ti = 0, pj = 0;
      soff_bin(g.normal.pixels[i], scale[k], bins, ti, pj);
      bin[i] = k * per_reflector + std::uint32_t(ti) * std::uint32_t(bins.phi_bins) + std::uint32_t(pj);
    }
  });
  // Non-empty bins, in bin order, are the clusters.
  std::vector<std::uint32_t> histogram(visible_object.size() * per_reflector, 0);
  for (std::size_t i = 0; i < n; ++i)
    if (bin[i] != kNoId) ++histogram[bin[i]];
  std::vector<std::uint32_t> cluster_of_bin(histogram.size(), kNoId);
  out.offsets.push_back(0);
  for (std::size_t b = 0; b < histogram.size(); ++b) {
    if (histogram[b] == 0) continue;
    cluster_of_bin[b] = static_cast<std::uint32_t>(out.reflector.size());
    out.reflector.push_back(visible_object[b / per_reflector]);
    out.offsets.push_back(out.offsets.back() + histogram[b]);
  }
  const std::size_t clusters = out.reflector.size();
  out.cluster.assign(n, kNoId);
  out.samples.resize(out.offsets.back());
  out.sum_position.assign(clusters, glm::dvec3(0.0));
  out.sum_normal.assign(clusters, glm::dvec3(0.0));
  std::vector<std::uint32_t> fill(out.offsets.begin(), out.offsets.end() - 1);
  // A stable counting sort and the per-cluster sums in sample order: the same bits for
  // every thread count.
  for (std::size_t i = 0; i < n; ++i) {
    if (bin[i] == kNoId) continue;
    const std::uint32_t c = cluster_of_bin[bin[i]];
    out.cluster[i] = c;
    out.samples[fill[c]++] = static_cast<std::uint32_t>(i);
    out.sum_position[c] += glm::dvec3(g.position.pixels[i]);
    out.sum_normal[c] += glm::dvec3(g.normal.pixels[i]);
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Cameras

float soff_eq1(float d_n, float d_f, float d_F) {
  const float den = d_f * (d_F - d_n);
  if (!(std::abs(den) > 1e-12f) || !(d_n > 0.0f)) return 1.0f;
  const float f = d_n * (d_F - d_f) / den;
  return std::isfinite(f) ? f : 1.0f;
}

glm::mat4 SoffCamera::view_projection() const {
  glm::mat4 view(1.0f);
  view[0][0] = u.x, view[1][0] = u.y, view[2][0] = u.z;
  view[0][1] = v.x, view[1][1] = v.y, view[2][1] = v.z;
  view[0][2] = -w.x, view[1][2] = -w.y, view[2][2] = -w.z;
  view[3][0] = -glm::dot(u, eye);
  view[3][1] = -glm::dot(v, eye);
  view[3][2] = glm::dot(w, eye);
  // glm::frustum(l, r, b, t, near, far) written out (OpenGL clip space).
  glm::mat4 p(0.0f);
  p[0][0] = 2.0f * near_dist / (r - l);
  p[1][1] = 2.0f * near_dist / (t - b);
  p[2][0] = (r + l) / (r - l);
  p[2][1] = (t + b) / (t - b);
  p[2][2] = -(far_dist + near_dist) / (far_dist - near_dist);
  p[2][3] = -1.0f;
  p[3][2] = -2.0f * far_dist * near_dist / (far_dist - near_dist);
  return p * view;
}

glm::vec3 SoffCamera::project(const glm::vec3& p) const {
  const glm::vec3 q = p - eye;
  const float z = glm::dot(q, w);
  const float x = glm::dot(q, u) * near_dist / z, y = glm::dot(q, v) * near_dist / z;
  return {(x - l) / (r - l) * float(width), (t - y) / (t - b) * float(height), 1.0f / z};
}

glm::vec3 SoffCamera::pixel_direction(float sx, float sy) const {
  const float x = l + sx / float(width) * (r - l), y = t - sy / float(height) * (t - b);
  return glm::normalize(x * u + y * v + near_dist * w);
}

namespace {

struct Box2 {
  glm::vec2 lo{3e38f}, hi{-3e38f};
  void grow(glm::vec2 p) { lo = glm::min(lo, p), hi = glm::max(hi, p); }
  float diagonal() const { return lo.x <= hi.x ? glm::length(hi - lo) : 0.0f; }
};

// In-plane coordinates (along u, v, on the plane at distance `near` from `eye` along w) of
// the central projection of x from eye.
glm::vec2 project_from(const glm::vec3& eye, float near, const glm::vec3& u, const glm::vec3& v,
                       const glm::vec3& w, const glm::vec3& x) {
  const glm::vec3 q = x - eye;
  const float z = glm::dot(q, w);
  return {glm::dot(q, u) * near / z, glm::dot(q, v) * near / z};
}

}  // namespace

SoffCamera soff_camera(const glm::vec3& eye, const std::vector<glm::vec3>& positions,
                       const std::vector<glm::vec3>& normals, const std::vector<glm::vec3>& reflected,
                       const std::vector<SoffPair>& adjacent,
                       float cone, float far_distance, const SoffCameraSettings& settings) {
  SoffCamera cam;
  const std::size_t n = positions.size();
  if (n == 0) return cam;
  // Step 1: image (and near) plane through the mean point with the mean normal.
  glm::dvec3 sp(0.0), sn(0.0);
  for (std::size_t i = 0; i < n; ++i) sp += glm::dvec3(positions[i]), sn += glm::dvec3(normals[i]);
  const glm::vec3 pc = glm::vec3(sp / double(n));
  const double sn_len = glm::length(sn);
  if (!(sn_len > 1e-6 * double(n))) return cam;  // normals cancel: no plane
  const glm::vec3 nc = glm::vec3(sn / sn_len);
  cam.centre = pc;
  cam.normal = nc;
  const float h = glm::dot(eye - pc, nc);
  if (!(h > 1e-6f)) return cam;  // the eye behind the mean plane (a grazing cluster)
  // Step 3a: the eye reflected about the plane.
  const glm::vec3 e0 = eye - 2.0f * h * nc;
  cam.mirrored_eye = e0;
  cam.w = nc;
  const glm::vec3 helper = std::abs(nc.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  cam.v = glm::normalize(helper - glm::dot(helper, nc) * nc);
  cam.u = glm::cross(cam.v, -nc);  // u × v = −w: right-handed view space looking down −z
  const float D = far_distance;
  // Near endpoints on or in front of the image plane (a sample behind it, at a convex
  // cluster's rim, starts where its ray crosses the plane) and far endpoints on the far plane.
  std::vector<glm::vec3> near_end, far_end;
  near_end.reserve(n), far_end.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float rn = glm::dot(reflected[i], nc);
    if (!(rn > kMinAxisCos)) continue;
    const float d = glm::dot(positions[i] - pc, nc);
    near_end.push_back(d < 0.0f ? positions[i] + reflected[i] * (-d / rn) : positions[i]);
    far_end.push_back(positions[i] + reflected[i] * ((D - d) / rn));
  }
  if (near_end.empty()) return cam;
  // Step 3b, eq.1: diagonals of the near and far endpoints' frames seen from e0, and of the
  // far endpoints on the far plane.
  Box2 bn, bf, bF;
  for (std::size_t i = 0; i < near_end.size(); ++i) {
    bn.grow(project_from(e0, h, cam.u, cam.v, nc, near_end[i]));
    bf.grow(project_from(e0, h, cam.u, cam.v, nc, far_end[i]));
    bF.grow({glm::dot(far_end[i] - pc, cam.u), glm::dot(far_end[i] - pc, cam.v)});
  }
  cam.d_n = bn.diagonal(), cam.d_f = bf.diagonal(), cam.d_F = bF.diagonal();
  // Bounded so that the eye stays at a sane distance for clusters whose diagonals are
  // degenerate (a single ray: d_n = 0) or whose rays converge (concave: d_F < d_n).
  cam.f = std::clamp(soff_eq1(cam.d_n, cam.d_f, cam.d_F), 0.02f, 50.0f);
  cam.eye = pc + (e0 - pc) * cam.f;  // corrected eq.1 (see soff_eq1)
  const float H = h * cam.f;
  cam.near_dist = H;
  cam.far_dist = H + D;
  // SOFF §4.4's concavity test: the cluster's centre sample (the one nearest the mean
  // point) behind the image plane; a planar cluster (within float noise) is not concave.
  {
    std::size_t best = 0;
    float best_d = 3e38f;
    float extent = 0.0f;
    for (std::size_t i = 0; i < n; ++i) {
      const float d2 = glm::dot(positions[i] - pc, positions[i] - pc);
      extent = std::max(extent, d2);
      if (d2 < best_d) best_d = d2, best = i;
    }
    cam.concave = glm::dot(positions[best] - pc, nc) < -1e-4f * std::sqrt(extent);
  }
  // Step 4: the frame, the box of both endpoints seen from e_c (widened for glossy cones).
  Box2 frame;
  for (std::size_t i = 0; i < near_end.size(); ++i) {
    frame.grow(project_from(cam.eye, H, cam.u, cam.v, nc, near_end[i]));
    frame.grow(project_from(cam.eye, H, cam.u, cam.v, nc, far_end[i]));
  }
  if (cone > 0.0f) {
    cam.glossy = true;
    cam.cone = std::min(cone, kMaxCone);
    const float widen = std::tan(cam.cone) * D * H / (H + D);
    frame.lo -= glm::vec2(widen), frame.hi += glm::vec2(widen);
  }
  // Step 5: the pixel size from the projected spacing of neighbouring cluster samples.
  // Pairs with a point nearer the eye than half the near distance (a convex cluster's rim
  // when the eye is close) would project with a blown-up spacing and are left out.
  double spacing[2] = {0.0, 0.0};
  std::size_t pairs[2] = {0, 0};
  for (const SoffPair& q : adjacent) {
    const glm::vec3 &pa = positions[q.a], &pb = positions[q.b];
    if (glm::dot(pa - cam.eye, nc) < 0.5f * H || glm::dot(pb - cam.eye, nc) < 0.5f * H) continue;
    spacing[q.vertical] += glm::length(project_from(cam.eye, H, cam.u, cam.v, nc, pa) -
                                       project_from(cam.eye, H, cam.u, cam.v, nc, pb));
    ++pairs[q.vertical];
  }
  glm::vec2 size = frame.hi - frame.lo;
  float p = 0.0f;
  for (int axis = 0; axis < 2; ++axis)
    if (pairs[axis] > 0) {
      const float mean = float(spacing[axis] / double(pairs[axis]));
      if (mean > 0.0f) p = p > 0.0f ? std::min(p, mean) : mean;
    }
  if (!(p > 0.0f)) p = std::max({size.x, size.y, 1e-4f * H}) / 2.0f;
  p /= settings.image_scale;
  // Bounded work: a depth image holds at most kMaxPixelsPerSample × image_scale² pixels per
  // cluster sample (a curved cluster's frame spans the whole solid angle its rays reach, and
  // its finest spacing would otherwise ask for far more pixels than it has rays).
  {
    const double cap = double(kMaxPixelsPerSample) * double(settings.image_scale) * double(settings.image_scale) *
                       double(std::max<std::size_t>(n, 4));
    const double pixels = double(size.x + 2.0f * p) * double(size.y + 2.0f * p) / (double(p) * double(p));
    if (pixels > cap) p *= float(std::sqrt(pixels / cap));
  }
  // One pixel of overlap on every side so that neighbouring clusters' images meet (SOFF
  // §4.1.1: clusters overlap slightly, so the reflection has no gaps).
  frame.lo -= glm::vec2(p), frame.hi += glm::vec2(p);
  size = frame.hi - frame.lo;
  const double wd = std::ceil(double(size.x) / p), hd = std::ceil(double(size.y) / p);
  const double side = double(settings.max_image_side);
  cam.clamped = wd > side || hd > side;
  cam.width = int(std::clamp(wd, 1.0, side));
  cam.height = int(std::clamp(hd, 1.0, side));
  cam.l = frame.lo.x, cam.r = frame.hi.x, cam.b = frame.lo.y, cam.t = frame.hi.y;
  cam.valid = std::isfinite(cam.l) && std::isfinite(cam.r) && std::isfinite(cam.b) && std::isfinite(cam.t) &&
              cam.r > cam.l && cam.t > cam.b && H > 0.0f;
  return cam;
}

SoffCameras soff_cameras(par::Executor& executor, const GBuffer& g, const SoffClusters& clusters,
                         const SoffCameraSettings& settings) {
  SoffCameras cameras(clusters.count());
  executor.parallel_for("soff_cameras.build", clusters.count(), 1, [&](std::size_t begin, std::size_t end) {
    std::vector<glm::vec3> positions, normals, reflected;
    std::vector<SoffPair> adjacent;
    for (std::size_t c = begin; c < end; ++c) {
      const std::uint32_t first = clusters.offsets[c], count = clusters.size_of(c);
      positions.resize(count), normals.resize(count), reflected.resize(count);
      adjacent.clear();
      float cone = 0.0f;
      // The first sample at or after the one below sample k: i + width grows with k, so it
      // only moves forward (a merge, not a binary search per sample).
      std::uint32_t below = 0;
      for (std::uint32_t k = 0; k < count; ++k) {
        const std::uint32_t i = clusters.samples[first + k];
        const glm::vec3 nrm = g.normal.pixels[i];
        positions[k] = g.position.pixels[i];
        normals[k] = nrm;
        reflected[k] = reflect(-g.view_direction(i), nrm);
        const SurfaceParams& s = g.surface[i];
        if (s.is_glossy_lobe()) {
          // The GGX lobe's reflected directions: P(tan θ_h > kα) = 1/(1 + k²), so 96% of the
          // half vectors lie within tan θ_h = 5α, and the reflected direction turns by 2θ_h.
          // (At 3α, 90%, more tail rays leave the frame and take the environment; at 10α the
          // wider frame spreads the depth image's pixels too thin on small glossy objects.)
          const float alpha = s.roughness * s.roughness;
          cone = std::max(cone, 2.0f * std::atan(5.0f * alpha));
        }
        // Step 5's pairs: the right and lower neighbours that belong to the same cluster.
        const std::uint32_t x = i % std::uint32_t(g.width), y = i / std::uint32_t(g.width);
        if (x + 1 < std::uint32_t(g.width) && clusters.cluster[i + 1] == c)
          adjacent.push_back({k, k + 1, false});  // samples are in increasing order: i + 1 is next
        if (y + 1 < std::uint32_t(g.height) && clusters.cluster[i + g.width] == c) {
          while (clusters.samples[first + below] < i + std::uint32_t(g.width)) ++below;
          adjacent.push_back({k, below, true});
        }
      }
      const float far = cone > 0.0f ? settings.scene_diameter * settings.glossy_far : settings.scene_diameter;
      cameras[c] = soff_camera(g.eye, positions, normals, reflected, adjacent, cone, far, settings);
    }
  });
  return cameras;
}

// ---------------------------------------------------------------------------------------
// Depth images

namespace {

struct FrustumPlanes {
  glm::vec3 n[6];
  float d[6];  // inside: dot(n, x) + d >= 0
};

FrustumPlanes frustum_planes(const SoffCamera& c) {
  FrustumPlanes f;
  const glm::vec3 normals[6] = {c.near_dist * c.u - c.l * c.w, c.r * c.w - c.near_dist * c.u,
                                c.near_dist * c.v - c.b * c.w, c.t * c.w - c.near_dist * c.v,
                                c.w, -c.w};
  for (int k = 0; k < 4; ++k) {
    f.n[k] = normals[k];
    f.d[k] = -glm::dot(normals[k], c.eye);
  }
  f.n[4] = c.w, f.d[4] = -glm::dot(c.w, c.eye) - c.near_dist;
  f.n[5] = -c.w, f.d[5] = glm::dot(c.w, c.eye) + c.far_dist;
  return f;
}

bool box_outside(const FrustumPlanes& f, const Bounds& b) {
  for (int k = 0; k < 6; ++k) {
    const glm::vec3 corner(f.n[k].x >= 0.0f ? b.hi.x : b.lo.x, f.n[k].y >= 0.0f ? b.hi.y : b.lo.y,
                           f.n[k].z >= 0.0f ? b.hi.z : b.lo.z);
    if (glm::dot(f.n[k], corner) + f.d[k] < 0.0f) return true;
  }
  return false;
}

struct CullGroup {
  std::uint32_t first = 0, count = 0, object = 0;
  Bounds box;
  std::uint32_t vertex_first = 0, vertex_last = 0;  // the range of vertex ids its triangles use
};

// What one depth image's rendering reuses from the one before it.
struct DepthImageScratch {
  std::vector<std::uint32_t> kept, indices, objects;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> vertex_ranges;  // [first, last] of the kept groups
  std::vector<ScreenVertex> vertices;  // by mesh vertex id; only the kept groups' ranges are written
  TileBins bins;
  VisibilityBuffer vis;
  GBuffer gb;
};

struct DepthImageCounts {
  std::uint64_t set_up = 0, culled = 0;
};

// Cluster camera `cam`'s depth image into out's pixels from `base` on. `records` (may be
// null: the mesh arrays) are the scene's G-buffer records.
DepthImageCounts render_depth_image(par::Executor& executor, const Scene& scene, const std::vector<CullGroup>& groups,
                                    std::uint32_t reflector, const SoffCamera& cam, const SurfaceShader& shade,
                                    const EnvironmentMap& env, std::size_t base, DepthImageScratch& s,
                                    SoffDepthImages& out, const GBufferTriangles* records) {
  const TriangleMesh& m = scene.mesh;
  DepthImageCounts counts;
  // Cull per cluster frustum before setup: whole groups outside one plane are dropped,
  // and the cluster's own reflector is left out (first-order: SOFF §4.4).
  const FrustumPlanes planes = frustum_planes(cam);
  s.kept.clear();
  s.vertex_ranges.clear();
  for (const CullGroup& grp : groups) {
    if (grp.object == reflector) continue;
    if (box_outside(planes, grp.box)) {
      counts.culled += grp.count;
      continue;
    }
    for (std::uint32_t t = grp.first; t < grp.first + grp.count; ++t) s.kept.push_back(t);
    s.vertex_ranges.emplace_back(grp.vertex_first, grp.vertex_last);
  }
  counts.set_up = s.kept.size();
  // The kept groups' vertices, each transformed once (about a sixth of three per kept
  // triangle), in disjoint ranges: the ranges sorted and merged where they touch.
  std::sort(s.vertex_ranges.begin(), s.vertex_ranges.end());
  std::size_t merged = 0;
  for (const auto& r : s.vertex_ranges) {
    if (merged > 0 && r.first <= s.vertex_ranges[merged - 1].second + 1)
      s.vertex_ranges[merged - 1].second = std::max(s.vertex_ranges[merged - 1].second, r.second);
    else
      s.vertex_ranges[merged++] = r;
  }
  s.vertex_ranges.resize(merged);
  // Vertices the kept triangles do not use keep whatever an earlier image left: none is read.
  if (s.vertices.size() < m.positions.size()) s.vertices.resize(m.positions.size());
  s.indices.resize(3 * s.kept.size());
  s.objects.resize(s.kept.size());
  const Viewport vp{cam.width, cam.height};
  const glm::mat4 vp_matrix = cam.view_projection();
  executor.parallel_for("soff_depth_images.vertices", s.vertex_ranges.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto [first, last] = s.vertex_ranges[k];
      make_screen_vertices(vp_matrix, &m.positions[first], std::size_t(last - first) + 1, vp, &s.vertices[first]);
    }
  });
  executor.parallel_for("soff_depth_images.triangles", s.kept.size(), 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t t = s.kept[k];
      for (int v = 0; v < 3; ++v) s.indices[3 * k + v] = m.indices[3 * std::size_t(t) + v];
      s.objects[k] = m.triangle_object[t];
    }
  });
  rasterize_screen_vertices(executor, s.vertices, s.indices, s.objects, cam.width, cam.height, {}, s.bins, s.vis);
  VisibilityBuffer& vis = s.vis;
  executor.parallel_for("soff_depth_images.ids", vis.triangle.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (vis.triangle.pixels[i] != kNoId) vis.triangle.pixels[i] = s.kept[vis.triangle.pixels[i]];
  });
  resolve_gbuffer(executor, scene, records, vis, cam.eye, s.gb);
  const GBuffer& gb = s.gb;
  executor.parallel_for("soff_depth_images.shade", gb.object.size(), 2048, [&](std::size_t begin, std::size_t end) {
    shade.shade_samples(
        gb, begin, end, [](std::size_t) { return true; },
        [&](std::size_t i, const glm::vec3& radiance) {
          out.inv_z[base + i] = 1.0f / vis.depth.pixels[i];
          out.colour[base + i] = radiance;
          out.surface[base + i] = gb.surface[i];
          out.normal[base + i] = gb.normal.pixels[i];
        },
        [&](std::size_t i) {
          const float sx = float(i % std::size_t(cam.width)) + 0.5f, sy = float(i / std::size_t(cam.width)) + 0.5f;
          out.colour[base + i] = env.radiance(cam.pixel_direction(sx, sy), 1e6f);
        });
  });
  return counts;
}

// Images of at least this many pixels are rendered one after another, each kernel's chunks
// across the threads; the smaller ones (most of a frame's: a few thousand pixels, one or two
// chunks per kernel) several at once, each image's kernels on one thread.
constexpr std::size_t kSharedImagePixels = 16384;
// Small images per task of that launch.
constexpr std::size_t kSmallImagesPerTask = 4;

}  // namespace

SoffDepthImages soff_depth_images(par::Executor& executor, const Scene& scene, const SoffClusters& clusters,
                                  const SoffCameras& cameras, const std::vector<ShadowMap>& shadows,
                                  const EnvironmentMap& env, SoffDepthStats* stats) {
  SoffDepthImages out;
  const TriangleMesh& m = scene.mesh;
  // Groups of consecutive triangles of one object and their boxes (the scene may move every
  // frame, so they are rebuilt here: one pass over the triangles).
  std::vector<CullGroup> groups;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    for (std::uint32_t t = 0; t < obj.triangle_count; t += kCullGroup)
      groups.push_back({obj.first_triangle + t, std::min(kCullGroup, obj.triangle_count - t), o, {}});
  }
  executor.parallel_for("soff_depth_images.group_bounds", groups.size(), 64,
                        [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      CullGroup& grp = groups[k];
      grp.vertex_first = m.indices[3 * std::size_t(grp.first)];
      grp.vertex_last = grp.vertex_first;
      for (std::uint32_t t = grp.first; t < grp.first + grp.count; ++t)
        for (int v = 0; v < 3; ++v) {
          const std::uint32_t i = m.indices[3 * std::size_t(t) + v];
          grp.box.grow(m.positions[i]);
          grp.vertex_first = std::min(grp.vertex_first, i), grp.vertex_last = std::max(grp.vertex_last, i);
        }
    }
  });
  out.offsets.assign(cameras.size() + 1, 0);
  for (std::size_t c = 0; c < cameras.size(); ++c)
    out.offsets[c + 1] =
        out.offsets[c] + (cameras[c].valid ? std::size_t(cameras[c].width) * std::size_t(cameras[c].height) : 0);
  out.pixels = out.offsets.back();
  out.inv_z.assign(out.pixels, 0.0f);
  out.colour.assign(out.pixels, glm::vec3(0.0f));
  out.surface.assign(out.pixels, SurfaceParams{});
  out.normal.assign(out.pixels, glm::vec3(0.0f));

  const SurfaceShader shade(scene, shadows, env);  // shade_surface's bits, eight at a time
  // The valid images, largest first: a scratch's planes are then sized once, by its first
  // image, and shrink for the others (growing them would value-initialize the growth on this
  // thread). Each image writes its own range of `out`, so neither the order nor which thread
  // renders an image changes a byte.
  std::vector<std::size_t> order;
  for (std::size_t c = 0; c < cameras.size(); ++c)
    if (cameras[c].valid) order.push_back(c);
  const auto pixels = [&](std::size_t c) { return out.offsets[c + 1] - out.offsets[c]; };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return pixels(a) > pixels(b); });
  std::vector<DepthImageCounts> counts(cameras.size());
  // The images' resolves read the scene's records (the same bytes, about half the time).
  FrameRecords frame_records;
  const GBufferTriangles* records = order.empty() ? nullptr : frame_records.of(executor, scene);
  const auto render = [&](par::Executor& on, std::size_t c, DepthImageScratch& scratch) {
    counts[c] = render_depth_image(on, scene, groups, clusters.reflector[c], cameras[c], shade, env, out.offsets[c],
                                   scratch, out, records);
  };
  std::size_t large = 0;
  DepthImageScratch scratch;
  for (; large < order.size() && pixels(order[large]) >= kSharedImagePixels; ++large)
    render(executor, order[large], scratch);
  executor.parallel_for("soff_depth_images.small_images", order.size() - large, kSmallImagesPerTask,
                        [&](std::size_t begin, std::size_t end) {
    par::Executor one_thread(1, executor.lanes());
    one_thread.set_recording(false);
    // Each thread keeps its scratch across tasks and frames (fresh planes per task cost
    // more than the small images' work). No task can interleave with another on one thread:
    // a one-thread executor runs its kernels inline and never waits for other tasks.
    thread_local DepthImageScratch own;
    for (std::size_t k = begin; k < end; ++k) render(one_thread, order[large + k], own);
  });
  SoffDepthStats st;
  st.images = order.size();
  for (const DepthImageCounts& n : counts) st.triangles_set_up += n.set_up, st.triangles_culled += n.culled;
  if (stats) *stats = st;
  return out;
}

// ---------------------------------------------------------------------------------------
// Intersection

namespace {

// What soff_walk's steps share: the segment's screen endpoints and the image.
struct WalkSegment {
  glm::vec3 a, b;  // projected near and far endpoints (x, y pixels; z = 1/z)
  float dx, dy;
  int steps, w, h;
  const float* inv_z;
};

// The stored 1/z at image point (sx, sy), 0 outside the image (inside says which).
float stored_at(const WalkSegment& g, float sx, float sy, bool& inside) {
  const int ix = int(std::floor(sx)), iy = int(std::floor(sy));
  inside = ix >= 0 && iy >= 0 && ix < g.w && iy < g.h;
  return inside ? g.inv_z[std::size_t(iy) * std::size_t(g.w) + std::size_t(ix)] : 0.0f;
}

// The ray's 1/z at step k of `steps` and the stored 1/z under it.
struct WalkStep {
  float ray, stored;
  bool inside;
};
WalkStep walk_step(const WalkSegment& g, int k) {
  const float s = float(k) / float(g.steps);
  WalkStep step;
  step.ray = g.a.z + (g.b.z - g.a.z) * s;  // 1/z is linear in screen space
  step.stored = stored_at(g, g.a.x + g.dx * s, g.a.y + g.dy * s, step.inside);
  return step;
}

// walk_step for steps k .. k + 7 in lanes: per lane walk_step's operations in its order
// (floor is exact, and so are the integer tests), so every lane has its bits.
void walk_steps8(const WalkSegment& g, int k, float* ray, float* stored, std::uint8_t* inside) {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using i32 = L::i32;
  const f32 s = L::to_float(L::iota(k)) / f32(float(g.steps));
  const f32 sx = g.a.x + g.dx * s, sy = g.a.y + g.dy * s;
  const i32 ix = L::to_int(L::floor(sx)), iy = L::to_int(L::floor(sy));
  const L::imask in = ix >= 0 && iy >= 0 && ix < i32(g.w) && iy < i32(g.h);
  L::store(g.a.z + (g.b.z - g.a.z) * s, ray);
  L::store(L::gather(g.inv_z, L::select(in, iy * g.w + ix, i32(0)), in, 0.0f), stored);
  for (int j = 0; j < 8; ++j) inside[j] = in[j];
}

}  // namespace

SoffWalkResult soff_walk(const SoffCamera& cam, const float* inv_z, const glm::vec3& p, const glm::vec3& d) {
  SoffWalkResult res;
  const float dz = glm::dot(d, cam.w);
  if (!(dz > 1e-4f)) {
    res.kind = SoffWalkResult::Unrepresentable;
    return res;
  }
  const float zp = glm::dot(p - cam.eye, cam.w);
  const glm::vec3 start = zp < cam.near_dist ? p + d * ((cam.near_dist - zp) / dz) : p;
  const glm::vec3 end = p + d * ((cam.far_dist - zp) / dz);
  WalkSegment g;
  g.a = cam.project(start), g.b = cam.project(end);
  g.dx = g.b.x - g.a.x, g.dy = g.b.y - g.a.y;
  g.w = cam.width, g.h = cam.height;
  g.inv_z = inv_z;
  g.steps = std::max(1, int(std::ceil(std::max(std::abs(g.dx), std::abs(g.dy)))));
  bool inside = true;
  float ray_a = g.a.z, di_a = stored_at(g, g.a.x, g.a.y, inside);
  if (!inside) return res;  // Miss: the ray starts outside the frame
  float prev_jump = 0.0f;
  bool hidden = false;
  for (int k = 1; k <= g.steps;) {
    // Eight steps at a time while none of them can end the walk or change its state (a
    // step outside the image, or a crossing from in front to behind): those only move the
    // ray on. The step that can is taken below, on its own, from the same values.
    if (g.steps - k >= 7) {
      alignas(32) float ray[9], stored[9];
      std::uint8_t in[8];
      ray[0] = ray_a, stored[0] = di_a;
      walk_steps8(g, k, ray + 1, stored + 1, in);
      int stop = 0;
      while (stop < 8 && in[stop] && !(ray[stop] - stored[stop] > 0.0f && ray[stop + 1] - stored[stop + 1] <= 0.0f))
        ++stop;
      res.steps += std::uint32_t(stop);
      k += stop;
      if (stop > 0) prev_jump = stored[stop] - stored[stop - 1], ray_a = ray[stop], di_a = stored[stop];
      if (stop == 8) continue;
    }
    const WalkStep step = walk_step(g, k);
    const float ray_b = step.ray, di_b = step.stored;
    ++res.steps;
    if (!step.inside) break;
    // In front: the ray is nearer than the stored surface (larger 1/z); empty pixels (0)
    // never stop it.
    const float da = ray_a - di_a, db = ray_b - di_b;
    const float jump = di_b - di_a;
    if (da > 0.0f && db <= 0.0f) {
      // A crossing. The stored segment continues a surface unless it jumps in front of where
      // the ray was, by more than the surface's own slope: then the ray passed behind a
      // silhouette into what the depth image does not hold.
      const bool silhouette = di_b > ray_a && jump > 2.0f * std::max(std::abs(prev_jump), ray_a - ray_b);
      if (!silhouette) {
        const float frac = da / (da - db);
        const float s_hit = (float(k - 1) + frac) / float(g.steps);
        res.kind = SoffWalkResult::Hit;
        res.sx = g.a.x + g.dx * s_hit;
        res.sy = g.a.y + g.dy * s_hit;
        res.inv_z = g.a.z + (g.b.z - g.a.z) * s_hit;
        return res;
      }
      if (!hidden)
        res.sx = g.a.x + g.dx * (float(k - 1) / float(g.steps)), res.sy = g.a.y + g.dy * (float(k - 1) / float(g.steps));
      hidden = true;
    }
    prev_jump = jump;
    ray_a = ray_b;
    di_a = di_b;
    ++k;
  }
  res.kind = hidden ? SoffWalkResult::Disoccluded : SoffWalkResult::Miss;
  return res;
}

namespace {

glm::vec3 bilinear(const glm::vec3* colour, int w, int h, float sx, float sy) {
  const float x = sx - 0.5f, y = sy - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - float(x0), fy = y - float(y0);
  auto at = [&](int xx, int yy) {
    xx = std::clamp(xx, 0, w - 1), yy = std::clamp(yy, 0, h - 1);
    return colour[std::size_t(yy) * std::size_t(w) + std::size_t(xx)];
  };
  return (at(x0, y0) * (1.0f - fx) + at(x0 + 1, y0) * fx) * (1.0f - fy) +
         (at(x0, y0 + 1) * (1.0f - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

// The change of shade_surface's value at (s, p, n) when the viewer moves from direction v0
// to v1: the terms that depend on the view (each light's BRDF, the coupled diffuse layer's
// Fresnel factor, the rough specular lobe), with one shadow lookup per light.
glm::vec3 view_dependent_change(const Scene& scene, const SurfaceParams& s, const glm::vec3& p, const glm::vec3& n,
                                const glm::vec3& v0, const glm::vec3& v1, const std::vector<ShadowMap>& shadows,
                                const EnvironmentMap& env) {
  // shade_surface lights the side the viewer is on.
  const glm::vec3 n0 = glm::dot(n, v0) < 0.0f ? -n : n, n1 = glm::dot(n, v1) < 0.0f ? -n : n;
  glm::vec3 change(0.0f);
  for (std::size_t k = 0; k < scene.lights.size(); ++k) {
    const LightSample ls = sample_light(scene.lights[k], p);
    if (ls.irradiance == glm::vec3(0.0f)) continue;
    const bool lit0 = glm::dot(n0, ls.direction) > 0.0f, lit1 = glm::dot(n1, ls.direction) > 0.0f;
    if (!lit0 && !lit1) continue;
    if (k < shadows.size()) {
      const float vis0 = lit0 ? shadows[k].visibility(p, n0, ls.direction) : 0.0f;
      const float vis1 = !lit1 ? 0.0f : n1 == n0 ? vis0 : shadows[k].visibility(p, n1, ls.direction);
      if (vis1 > 0.0f) change += vis1 * shade_light(s, n1, v1, ls);
      if (vis0 > 0.0f) change -= vis0 * shade_light(s, n0, v0, ls);
    } else {
      if (lit1) change += shade_light(s, n1, v1, ls);
      if (lit0) change -= shade_light(s, n0, v0, ls);
    }
  }
  change += diffuse_albedo_over_pi(s, glm::dot(n1, v1)) * env.irradiance(n1) -
            diffuse_albedo_over_pi(s, glm::dot(n0, v0)) * env.irradiance(n0);
  if (s.has_rough_specular_lobe())
    change += specular_reflectance(s, glm::dot(n1, v1)) * env.radiance(reflect(-v1, n1), s.phong_exponent) -
              specular_reflectance(s, glm::dot(n0, v0)) * env.radiance(reflect(-v0, n0), s.phong_exponent);
  return change;
}

}  // namespace

std::uint32_t soff_self_walk(const GBuffer& g, const glm::mat4& vp, const glm::vec3& forward, std::uint32_t reflector,
                             const glm::ivec4& box, const glm::vec3& p, const glm::vec3& d, float length,
                             std::uint32_t* steps_out) {
  // Clip space is linear along the segment; x/w, y/w and 1/w are linear in screen space.
  const glm::vec4 ca = vp * glm::vec4(p, 1.0f), cb = vp * glm::vec4(p + d * length, 1.0f);
  if (steps_out) *steps_out = 0;
  if (!(ca.w > 0.0f) || !(cb.w > 0.0f)) return kNoId;  // the segment leaves the view backwards
  const float W = float(g.width), H = float(g.height);
  if (box.z < box.x || box.w < box.y || box.x < 0 || box.y < 0 || box.z >= g.width || box.w >= g.height) return kNoId;
  const glm::vec2 a((ca.x / ca.w * 0.5f + 0.5f) * W, (0.5f - ca.y / ca.w * 0.5f) * H);
  const glm::vec2 b((cb.x / cb.w * 0.5f + 0.5f) * W, (0.5f - cb.y / cb.w * 0.5f) * H);
  const float ia = 1.0f / ca.w, ib = 1.0f / cb.w;
  const glm::vec2 delta = b - a;
  const int steps = std::min(int(std::ceil(std::max(std::abs(delta.x), std::abs(delta.y)))), g.width + g.height);
  if (steps < 2) return kNoId;
  const glm::vec3 eye = g.eye;
  // The depth (along the view axis) of the segment and of the surface at step k.
  float prev_gap = 0.0f, prev_surface = 0.0f, prev_ray = 0.0f;
  bool prev_valid = false;
  std::uint32_t taken = 0;
  for (int k = 2; k <= steps; ++k) {  // steps 0 and 1: the start's own sample and its neighbour
    const float s = float(k) / float(steps);
    const float x = a.x + delta.x * s, y = a.y + delta.y * s;
    if (x < float(box.x) || y < float(box.y) || x >= float(box.z + 1) || y >= float(box.w + 1)) break;
    ++taken;
    const std::size_t q = std::size_t(y) * std::size_t(g.width) + std::size_t(x);
    if (g.object.pixels[q] != reflector) {
      prev_valid = false;
      continue;
    }
    const float ray_depth = 1.0f / (ia + (ib - ia) * s);  // = clip w = view depth
    const float surface_depth = glm::dot(g.position.pixels[q] - eye, forward);
    const float gap = surface_depth - ray_depth;  // > 0: the segment is in front
    // A crossing from in front to behind, unless the segment dived behind the surface by
    // more than the step's depth changes allow (it passed behind a silhouette of the
    // reflector, where the surface jumps).
    if (prev_valid && prev_gap > 0.0f && gap <= 0.0f &&
        -gap <= 2.0f * (std::abs(ray_depth - prev_ray) + std::abs(surface_depth - prev_surface)) + 1e-3f * ray_depth) {
      if (steps_out) *steps_out = taken;
      return std::uint32_t(q);
    }
    prev_gap = gap, prev_surface = surface_depth, prev_ray = ray_depth;
    prev_valid = true;
  }
  if (steps_out) *steps_out = taken;
  return kNoId;
}

ImageRGBA soff_intersect(par::Executor& executor, const Scene& scene, const GBuffer& g,
                         const SoffClusters& clusters, const SoffCameras& cameras, const SoffDepthImages& images,
                         const std::vector<ShadowMap>& shadows, const EnvironmentMap& env,
                         const SoffIntersectSettings& settings, SoffIntersectStats* stats) {
  constexpr std::size_t kChunk = 1024;
  ImageRGBA out(g.width, g.height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  std::vector<SoffIntersectStats> per_chunk(par::Executor::chunk_count(out.size(), kChunk));
  // Concave clusters: the output camera's projection and each cluster's extent (the longest
  // segment a second intersection within the reflector can need: twice the largest
  // distance of a cluster sample from the cluster's mean point, over the reflector's clusters).
  const glm::mat4 vp = projection_matrix(settings.camera, g.width, g.height) * view_matrix(settings.camera);
  const glm::vec3 forward = glm::normalize(settings.camera.target - settings.camera.eye);
  // Per reflector with a concave cluster: the longest segment a second intersection can
  // need (the diagonal of its samples' box) and its samples' box in the output image, which
  // bounds the walk.
  std::vector<float> reach(cameras.size(), 0.0f);
  std::vector<glm::ivec4> screen_box(cameras.size(), glm::ivec4(0));
  if (settings.concave_self) {
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      if (!cameras[c].valid || !cameras[c].concave) continue;
      Bounds box;
      glm::ivec4 sb(g.width, g.height, -1, -1);
      for (std::size_t o = 0; o < cameras.size(); ++o) {
        if (clusters.reflector[o] != clusters.reflector[c]) continue;
        for (std::uint32_t k = clusters.offsets[o]; k < clusters.offsets[o + 1]; ++k) {
          const std::uint32_t q = clusters.samples[k];
          box.grow(g.position.pixels[q]);
          const int x = int(q % std::uint32_t(g.width)), y = int(q / std::uint32_t(g.width));
          sb = glm::ivec4(std::min(sb.x, x), std::min(sb.y, y), std::max(sb.z, x), std::max(sb.w, y));
        }
      }
      reach[c] = glm::length(box.extent());
      screen_box[c] = sb;
    }
  }
  executor.parallel_for("soff_intersect.walk", out.size(), kChunk, [&](std::size_t begin, std::size_t end) {
    SoffIntersectStats& st = per_chunk[begin / kChunk];
    for (std::size_t i = begin; i < end; ++i) {
      if (!g.covered(i)) continue;
      const SurfaceParams& s = g.surface[i];
      if (!is_specular(s)) continue;
      const glm::vec3 n = g.normal.pixels[i], v = g.view_direction(i);
      const auto env_lookup = [&](const glm::vec3& d, float exponent) { return env.radiance(d, exponent); };
      const std::uint32_t c = clusters.cluster[i];
      if (!soff_reflects(s) || c == kNoId || !cameras[c].valid) {
        if (soff_reflects(s)) ++st.unclustered_samples;
        out.pixels[i] = glm::vec4(specular_radiance(s, n, v, env_lookup), 1.0f);
        continue;
      }
      const SoffCamera& cam = cameras[c];
      const std::size_t base = images.offsets[c];
      const float* inv_z = images.inv_z.data() + base;
      const glm::vec3* colour = images.colour.data() + base;
      const glm::vec3 p = g.position.pixels[i];
      int disoccluded = 0, rays = 0;
      const bool fade = cam.glossy && settings.glossy_fade;
      const bool self = settings.concave_self && cam.concave && reach[c] > 0.0f;
      // The radiance a reflected ray from this sample finds in the depth image, or the
      // environment (a miss, a disocclusion, a direction the camera cannot frame).
      const auto trace = [&](const glm::vec3& d) {
        ++st.rays, ++rays;
        if (self) {
          ++st.concave_rays;
          std::uint32_t taken = 0;
          const std::uint32_t q =
              soff_self_walk(g, vp, forward, clusters.reflector[c], screen_box[c], p, d, reach[c], &taken);
          st.self_steps += taken;
          if (q != kNoId) {
            ++st.self_hits;
            // First order (SOFF §4.4): the diffuse shading of the reflector's sample hit.
            return shade_surface(scene, g.surface[q], g.position.pixels[q], g.normal.pixels[q], -d, shadows,
                                 env);
          }
        }
        const SoffWalkResult r = soff_walk(cam, inv_z, p, d);
        st.steps += r.steps;
        if (r.steps <= 1) ++st.planar_lookups;
        if (r.kind == SoffWalkResult::Hit) {
          ++st.hits;
          glm::vec3 hit = bilinear(colour, cam.width, cam.height, r.sx, r.sy);
          if (settings.reshade) {
            // The nearest pixel's surface, at the hit on the ray, seen along the ray instead
            // of from the cluster camera.
            const int x = std::clamp(int(r.sx), 0, cam.width - 1), y = std::clamp(int(r.sy), 0, cam.height - 1);
            const std::size_t k = base + std::size_t(y) * std::size_t(cam.width) + std::size_t(x);
            // Only glossy surfaces' shading changes much with the view (their light
            // highlights); mirrors reflect no point light and rough surfaces' lobes are broad.
            if (images.inv_z[k] > 0.0f && images.surface[k].is_glossy_lobe()) {
              const float dz = glm::dot(d, cam.w);
              const glm::vec3 at = p + d * ((1.0f / r.inv_z - glm::dot(p - cam.eye, cam.w)) / dz);
              const glm::vec3 v0 = glm::normalize(cam.eye - at);
              hit = glm::max(hit + view_dependent_change(scene, images.surface[k], at, images.normal[k], v0, -d,
                                                         shadows, env),
                             glm::vec3(0.0f));
            }
          }
          if (!fade) return hit;
          // SOFF §3.5: a glossy reflection fades as the reflected surface nears the pulled-in
          // far plane, here over the last quarter of the depth range, towards what a ray
          // beyond the far plane gets (the environment), so nothing pops at the plane.
          const float z = 1.0f / r.inv_z;
          const float weight = std::clamp((cam.far_dist - z) / (0.25f * (cam.far_dist - cam.near_dist)), 0.0f, 1.0f);
          return weight * hit + (1.0f - weight) * env.radiance(d, 1e6f);
        }
        ++st.env_fallback;
        if (r.kind == SoffWalkResult::Disoccluded) {
          ++st.disoccluded_rays, ++disoccluded;
          // The depth image's sample just before the silhouette the ray passed behind.
          if (settings.fill_disocclusions) return bilinear(colour, cam.width, cam.height, r.sx, r.sy);
        }
        return env.radiance(d, 1e6f);
      };
      glm::vec3 radiance(0.0f);
      if (s.is_glossy_lobe()) {
        // SOFF §3.5: several reflected rays per glossy sample, here drawn from the shared
        // GGX lobe (the application's BRDF of §3.1's G(d_i, g)) with its estimator weight
        // F G2/G1, from a per-pixel rotated Hammersley set; rays below the surface count 0.
        const int k_rays = settings.glossy_rays;
        const glm::vec2 offset = random_float2(std::uint32_t(i), 0, 0, settings.seed);
        const SpecularLobeSampler lobes(s, n, v);
        for (int k = 0; k < k_rays; ++k) {
          const glm::vec2 u = rotate_unit_square(hamersley(std::uint32_t(k), std::uint32_t(k_rays)), offset);
          const LobeSample lobe = lobes(u);
          if (lobe.weight == glm::vec3(0.0f)) continue;
          radiance += lobe.weight * trace(lobe.direction);
        }
        radiance /= float(k_rays);
      } else {
        radiance = specular_radiance(s, n, v, [&](const glm::vec3& d, float) { return trace(d); });
      }
      // A sample is disoccluded when most of its rays are (a mirror's one ray; a glossy
      // lobe's majority), so the count compares with SOFF's per-pixel figure.
      if (2 * disoccluded > rays) ++st.disoccluded_samples;
      out.pixels[i] = glm::vec4(radiance, 1.0f);
    }
  });
  if (stats)
    for (const SoffIntersectStats& c : per_chunk) {
      stats->rays += c.rays;
      stats->steps += c.steps;
      stats->hits += c.hits;
      stats->env_fallback += c.env_fallback;
      stats->disoccluded_rays += c.disoccluded_rays;
      stats->disoccluded_samples += c.disoccluded_samples;
      stats->unclustered_samples += c.unclustered_samples;
      stats->planar_lookups += c.planar_lookups;
      stats->concave_rays += c.concave_rays;
      stats->self_hits += c.self_hits;
      stats->self_steps += c.self_steps;
    }
  return out;
}

ImageRGBA soff_cluster_image(const SoffClusters& clusters) {
  ImageRGBA out(clusters.width, clusters.height, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  for (std::size_t i = 0; i < clusters.cluster.size(); ++i) {
    const std::uint32_t c = clusters.cluster[i];
    if (c == kNoId) continue;
    // A hash of the id to a saturated hue, so neighbouring clusters differ.
    const float hue = random_float(c, 0, 0, 0x50ffu) * 6.0f;
    const float x = 1.0f - std::abs(std::fmod(hue, 2.0f) - 1.0f);
    const int sector = int(hue);
    glm::vec3 rgb = sector == 0 ? glm::vec3(1, x, 0) : sector == 1 ? glm::vec3(x, 1, 0)
                  : sector == 2 ? glm::vec3(0, 1, x) : sector == 3 ? glm::vec3(0, x, 1)
                  : sector == 4 ? glm::vec3(x, 0, 1) : glm::vec3(1, 0, x);
    out.pixels[i] = glm::vec4(rgb * (0.35f + 0.65f * random_float(c, 1, 0, 0x50ffu)), 1.0f);
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Passes

SoffClusters SoffClustersPass::operator()(par::NodeContext& c, const GBuffer& gbuffer) const {
  SoffClusters clusters = soff_cluster(c.executor(), gbuffer, bins);
  c.count("clusters", double(clusters.count()));
  c.count("visible_reflectors", clusters.visible_reflectors);
  c.count("clustered_samples", double(clusters.samples.size()));
  if (clusters.count() > 0) {
    std::vector<std::uint32_t> sizes(clusters.count());
    for (std::size_t k = 0; k < sizes.size(); ++k) sizes[k] = clusters.size_of(k);
    std::sort(sizes.begin(), sizes.end());
    c.count("samples_per_cluster_min", sizes.front());
    c.count("samples_per_cluster_median", sizes[sizes.size() / 2]);
    c.count("samples_per_cluster_max", sizes.back());
  }
  return clusters;
}

SoffCameras SoffCamerasPass::operator()(par::NodeContext& c, const GBuffer& gbuffer,
                                        const SoffClusters& clusters) const {
  SoffCameraSettings s = settings;
  const Bounds b = scene->bounds();
  s.scene_diameter = b.valid() ? std::max(glm::length(b.extent()), 1e-3f) : 1.0f;
  SoffCameras cameras = soff_cameras(c.executor(), gbuffer, clusters, s);
  std::uint64_t valid = 0, concave = 0, clamped = 0, planar = 0, pixels = 0;
  for (const SoffCamera& cam : cameras) {
    if (!cam.valid) continue;
    ++valid;
    concave += cam.concave;
    clamped += cam.clamped;
    planar += std::abs(cam.f - 1.0f) < 1e-3f;
    pixels += std::uint64_t(cam.width) * std::uint64_t(cam.height);
  }
  c.count("cameras", double(valid));
  c.count("invalid_cameras", double(cameras.size() - valid));
  c.count("concave_clusters", double(concave));
  c.count("clamped_images", double(clamped));
  c.count("planar_clusters", double(planar));
  c.count("depth_image_pixels", double(pixels));
  return cameras;
}

SoffDepthImages SoffDepthImagesPass::operator()(par::NodeContext& c, const SoffClusters& clusters,
                                                const SoffCameras& cameras, const ShadowMaps& shadows,
                                                const EnvironmentMap& environment) const {
  SoffDepthStats st;
  SoffDepthImages images = soff_depth_images(c.executor(), *scene, clusters, cameras, shadows, environment, &st);
  c.count("images", double(st.images));
  c.count("triangles_set_up", double(st.triangles_set_up));
  c.count("triangles_culled", double(st.triangles_culled));
  c.count("pixels", double(images.pixels));
  return images;
}

ImageRGBA SoffIntersectPass::operator()(par::NodeContext& c, const GBuffer& gbuffer, const SoffClusters& clusters,
                                        const SoffCameras& cameras, const SoffDepthImages& images,
                                        const ShadowMaps& shadows, const EnvironmentMap& environment) const {
  SoffIntersectStats st;
  ImageRGBA specular = soff_intersect(c.executor(), *scene, gbuffer, clusters, cameras, images, shadows, environment,
                                      settings, &st);
  c.count("rays", double(st.rays));
  c.count("steps", double(st.steps));
  c.count("hits", double(st.hits));
  c.count("env_fallback", double(st.env_fallback));
  c.count("disoccluded_rays", double(st.disoccluded_rays));
  c.count("disoccluded_samples", double(st.disoccluded_samples));
  c.count("unclustered_samples", double(st.unclustered_samples));
  c.count("planar_lookups", double(st.planar_lookups));
  c.count("concave_rays", double(st.concave_rays));
  c.count("self_hits", double(st.self_hits));
  c.count("self_steps", double(st.self_steps));
  return specular;
}

}  // namespace speculum::raster
