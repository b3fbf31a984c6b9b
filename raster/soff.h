// Second-order feed-forward reflections (SOFF): the non-diffuse G-buffer samples are binned
// into clusters by normal direction and reflector (SOFF §3.2), each cluster gets a planar
// pinhole camera that approximates its reflected rays (§3.3), the scene is rasterized from
// every cluster camera into a colour + depth image (§3.1 step 3b), and each sample's
// reflected ray is walked one pixel at a time through its cluster's depth image (§3.4);
// glossy samples walk several rays of their lobe (§3.5). First-order only: the colour at a
// reflected hit is that surface's direct shading, as SOFF §4.4 states.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

// ---------------------------------------------------------------------------------------
// Clustering (SOFF §3.2)

struct SoffBinSettings {
  int theta_bins = 13;  // MAXTHETABINS: normal azimuth bins over 360°
  int phi_bins = 8;     // MAXPHIBINS: normal polar bins over 180°
  float share_gain = 1.0f;  // the screen share a_R (percent) is multiplied by this (calibration)
};

// The samples SOFF reflects: mirror and glossy lobes (refractors are not SOFF's; the
// technique gives them the environment lookup).
inline bool soff_reflects(const SurfaceParams& s) { return !s.is_refractor() && is_specular(s); }

struct SoffClusters {
  int width = 0, height = 0;
  std::vector<std::uint32_t> cluster;  // per sample; kNoId: not clustered
  // Per cluster c: its samples are samples[offsets[c] .. offsets[c+1]), in increasing order.
  std::vector<std::uint32_t> offsets;
  std::vector<std::uint32_t> samples;
  std::vector<std::uint32_t> reflector;   // object id per cluster
  std::vector<glm::dvec3> sum_position;   // Σ P_i per cluster
  std::vector<glm::dvec3> sum_normal;     // Σ n_i per cluster
  int visible_reflectors = 0;             // n_v of §3.2
  std::size_t count() const { return reflector.size(); }
  std::uint32_t size_of(std::size_t c) const { return offsets[c + 1] - offsets[c]; }
};

// The bin (i, j) of a unit normal for a reflector whose bin scale is `scale` (≤ 1): i from
// the azimuth θ = atan2(n.z, n.x) in [0°, 360°), j from the polar angle φ = acos(n.y) in
// [0°, 180°], i = floor(T θ/360° scale) clamped to [0, T−1], likewise j with P and 180°.
void soff_bin(const glm::vec3& n, float scale, const SoffBinSettings& bins, int& i, int& j);

// The bin scale of a reflector covering `percent` of the frame among `visible` reflectors.
// SOFF §3.2 prints a_R/n_v with a_R a fraction, which gives about one bin per object; read
// with a_R in percent and clamped to 1 it reproduces SOFF Table 7's 100–200 clusters per
// frame (a calibration of the printed formula, not a correction) and still the ≤ 52 bins of
// the paper's full-screen sphere example.
float soff_bin_scale(double percent, int visible, double gain = 1.0);

SoffClusters soff_cluster(par::Executor& executor, const GBuffer& g, const SoffBinSettings& bins);

// ---------------------------------------------------------------------------------------
// Cluster cameras (SOFF §3.3)

struct SoffCameraSettings {
  float scene_diameter = 1.0f;  // D: the far plane's distance from the image plane (mirrors)
  float image_scale = 1.0f;     // depth-image resolution × this (SOFF Table 5's ½, 1, 2)
  int max_image_side = 1024;    // a bound on each depth image's side (counted when hit)
  float glossy_far = 1.0f;      // glossy clusters: far plane at D × this (§3.5; 1: not pulled in),
                                // the reflection fading over the last quarter before it
};

struct SoffCamera {
  bool valid = false;    // false: the cluster's samples get the environment lookup
  bool concave = false;  // SOFF §4.4's test: the cluster centre lies behind its image plane
  bool clamped = false;  // the resolution hit max_image_side
  bool glossy = false;   // some sample is a glossy lobe: frame widened by the cone
  float f = 1.0f;        // eq.1's displacement factor
  float d_n = 0.0f, d_f = 0.0f, d_F = 0.0f;  // eq.1's diagonals, eye at e0
  glm::vec3 centre{0.0f}, normal{0.0f, 0.0f, 1.0f};  // P_c and n_c
  glm::vec3 mirrored_eye{0.0f};                      // e0
  glm::vec3 eye{0.0f};                               // e_c
  glm::vec3 u{1, 0, 0}, v{0, 1, 0}, w{0, 0, 1};      // right, up, view axis (= n_c)
  float near_dist = 0.0f, far_dist = 0.0f;           // along w from e_c
  float l = 0, r = 0, b = 0, t = 0;                  // frame on the near plane (u, v units)
  int width = 0, height = 0;
  float cone = 0.0f;  // glossy widening, radians

  glm::mat4 view_projection() const;
  // (x, y) in depth-image pixels (pixel centres at +0.5) and 1/z of world point p.
  glm::vec3 project(const glm::vec3& p) const;
  // The unit direction of the camera ray through depth-image point (sx, sy).
  glm::vec3 pixel_direction(float sx, float sy) const;
};

// Two samples of a cluster that are neighbours in the output image, in a row (vertical =
// false) or a column.
struct SoffPair {
  std::uint32_t a = 0, b = 0;
  bool vertical = false;
};

// Builds the camera of one cluster from its samples (positions, normals, reflected
// directions, all of the cluster): steps 1–5 of SOFF §3.3 with eq.1 in its corrected form
// (below). `adjacent` holds pairs of indices into the arrays of samples that are neighbours
// in the output image (step 5's pixel size: the finer of the mean row and the mean column
// spacing, so a reflector seen at a grazing angle is not undersampled across it); `cone`
// widens the frame for glossy lobes.
SoffCamera soff_camera(const glm::vec3& eye, const std::vector<glm::vec3>& positions,
                       const std::vector<glm::vec3>& normals, const std::vector<glm::vec3>& reflected,
                       const std::vector<SoffPair>& adjacent,
                       float cone, float far_distance, const SoffCameraSettings& settings);

// SOFF §3.3 eq.1, f = d_n (d_F − d_f) / (d_f (d_F − d_n)), with the eye placed at
// e_c = P_c + (e0 − P_c) f: the printed e_c = e0 + (P_c − e0) f contradicts the text (it
// would put a planar cluster's eye, f = 1, on the cluster instead of at e0). The corrected
// form makes the far endpoints' frame diagonal equal d_n for a cluster viewed head-on.
float soff_eq1(float d_n, float d_f, float d_F);

using SoffCameras = std::vector<SoffCamera>;

SoffCameras soff_cameras(par::Executor& executor, const GBuffer& g, const SoffClusters& clusters,
                         const SoffCameraSettings& settings);

// ---------------------------------------------------------------------------------------
// Depth images (SOFF §3.1 step 3b)

struct SoffDepthImages {
  // Cluster c's image is width × height pixels at offsets[c] in the arrays below.
  std::vector<std::size_t> offsets;
  std::vector<float> inv_z;         // 1/z along the camera axis; 0: empty (nothing seen)
  std::vector<glm::vec3> colour;    // direct shading of the surface seen, or the environment
  // The surface seen (material at the pixel and its shading normal), so that a hit can be
  // re-shaded for its own ray direction (SoffIntersectSettings::reshade).
  std::vector<SurfaceParams> surface;
  std::vector<glm::vec3> normal;
  std::uint64_t pixels = 0;
};

struct SoffDepthStats {
  std::uint64_t images = 0;
  std::uint64_t triangles_set_up = 0;  // triangles that survived the per-cluster frustum cull
  std::uint64_t triangles_culled = 0;
};

SoffDepthImages soff_depth_images(par::Executor& executor, const Scene& scene, const SoffClusters& clusters,
                                  const SoffCameras& cameras, const std::vector<ShadowMap>& shadows,
                                  const EnvironmentMap& env, SoffDepthStats* stats = nullptr);

// ---------------------------------------------------------------------------------------
// Ray / depth-image intersection (SOFF §3.4)

struct SoffWalkResult {
  enum Kind : std::uint8_t { Hit, Miss, Disoccluded, Unrepresentable } kind = Miss;
  float sx = 0.0f, sy = 0.0f;  // the hit in depth-image pixels
  float inv_z = 0.0f;          // the ray's 1/z at the hit
  std::uint32_t steps = 0;
};

// Walks the ray p + t d (d unit) through the depth image (inv_z, width × height) of
// `camera`, one pixel at a time from its near endpoint to its far endpoint: a hit where the
// ray's 1/z segment crosses the stored 1/z segment between consecutive steps from in front
// to behind; first hit wins. A crossing where the stored depth jumps in front of the ray
// (the ray passes behind a silhouette) is a disocclusion: the walk goes on, and ends
// Disoccluded if nothing is hit later. A ray whose direction leaves the frustum backwards is
// Unrepresentable. A Disoccluded result's (sx, sy) is the last step before the first
// silhouette.
SoffWalkResult soff_walk(const SoffCamera& camera, const float* inv_z, const glm::vec3& p, const glm::vec3& d);

struct SoffIntersectSettings {
  int glossy_rays = 8;
  bool glossy_fade = false;  // glossy clusters' far plane is pulled in: fade before it (§3.5)
  // A disoccluded ray takes the environment (SOFF §4.1.1), or with this the depth image's
  // sample just before the silhouette it passed behind (the nearest captured surface).
  bool fill_disocclusions = false;
  std::uint32_t seed = 0;
  // The depth image's colour was shaded for the cluster camera's view; the terms of the
  // shading that depend on the view (light highlights of glossy surfaces, the Fresnel
  // coupling of the diffuse layer) are re-evaluated at the hit for the reflected ray itself
  // (from the nearest depth-image pixel's surface), so a hit is shaded as a ray tracer
  // shades it. Off: the depth image's colour as it is (SOFF §3.4).
  bool reshade = true;
  // Concave clusters (SOFF §4.4's second option): before the depth image, the reflected ray
  // is intersected with the reflector's own samples in the frame (the cluster and its
  // sibling clusters), walking the output image one sample at a time; a second
  // intersection takes the diffuse shading of the sample hit.
  bool concave_self = false;
  Camera camera;  // the output camera (the G-buffer's projection), for concave_self
};

struct SoffIntersectStats {
  std::uint64_t rays = 0;
  std::uint64_t steps = 0;
  std::uint64_t hits = 0;
  std::uint64_t env_fallback = 0;       // rays that got the environment map (any reason)
  std::uint64_t disoccluded_rays = 0;
  std::uint64_t disoccluded_samples = 0;  // samples most of whose rays were disoccluded
  std::uint64_t unclustered_samples = 0;  // specular samples without a valid camera
  std::uint64_t planar_lookups = 0;       // rays that projected to a point (one lookup)
  std::uint64_t concave_rays = 0;         // rays of concave clusters tested against their reflector
  std::uint64_t self_hits = 0;            // of those, rays that hit the reflector itself
  std::uint64_t self_steps = 0;           // output-image steps of those walks
};

// Walks the segment p → p + d·length through the output image (the G-buffer of `camera`),
// one sample at a time while inside `box` (x0, y0, x1, y1: the reflector's samples' box,
// inclusive), against the depth of the samples of object `reflector`: the first
// sample where the segment passes from in front of that surface to behind it (within the
// depth change of one step) is a hit; its index, or kNoId. The start's own footprint (the
// first sample and its neighbours) is skipped. SOFF §4.4: intersecting a concave cluster
// with itself.
std::uint32_t soff_self_walk(const GBuffer& g, const glm::mat4& view_projection, const glm::vec3& forward,
                             std::uint32_t reflector, const glm::ivec4& box, const glm::vec3& p, const glm::vec3& d,
                             float length, std::uint32_t* steps = nullptr);

ImageRGBA soff_intersect(par::Executor& executor, const Scene& scene, const GBuffer& g,
                         const SoffClusters& clusters, const SoffCameras& cameras, const SoffDepthImages& images,
                         const std::vector<ShadowMap>& shadows, const EnvironmentMap& env,
                         const SoffIntersectSettings& settings, SoffIntersectStats* stats = nullptr);

// The clusters in false colour (grey: diffuse and background), for inspect.
ImageRGBA soff_cluster_image(const SoffClusters& clusters);

// ---------------------------------------------------------------------------------------
// Passes

struct SoffClustersPass {
  static constexpr const char* description =
      "Bins the non-diffuse G-buffer samples by (normal azimuth bin, normal polar bin, reflector "
      "id) in a fixed bin array, bins scaled by each reflector's screen share over the visible "
      "reflectors; non-empty bins are the clusters (SOFF §3.2).";
  SoffBinSettings bins;
  void parameters(par::Params& p) const { p.set("theta_bins", bins.theta_bins).set("phi_bins", bins.phi_bins); }
  SoffClusters operator()(par::NodeContext& c, const GBuffer& gbuffer) const;
};

struct SoffCamerasPass {
  static constexpr const char* description =
      "Per cluster a planar pinhole camera: image plane through the mean point and normal, eye "
      "reflected and moved by eq.1 (corrected form), frame from the projected near and far "
      "endpoints, resolution from the projected pixel spacing (SOFF §3.3); concave clusters "
      "detected (§4.4).";
  const Scene* scene = nullptr;
  SoffCameraSettings settings;
  void parameters(par::Params& p) const {
    p.set("image_scale", settings.image_scale).set("max_image_side", settings.max_image_side);
  }
  SoffCameras operator()(par::NodeContext& c, const GBuffer& gbuffer, const SoffClusters& clusters) const;
};

struct SoffDepthImagesPass {
  static constexpr const char* description =
      "Rasterizes the scene from every cluster camera with the tile rasterizer (objects, then "
      "triangles, culled to the cluster frustum before setup; the cluster's own reflector left "
      "out) into 1/z and direct shading: the cluster depth images (SOFF §3.1 step 3b).";
  const Scene* scene = nullptr;
  SoffDepthImages operator()(par::NodeContext& c, const SoffClusters& clusters, const SoffCameras& cameras,
                             const ShadowMaps& shadows, const EnvironmentMap& environment) const;
};

struct SoffIntersectPass {
  static constexpr const char* description =
      "Walks each reflected ray through its cluster's depth image one pixel at a time, hit where "
      "the 1/z segments cross, bilinear colour; glossy samples average several lobe rays; misses "
      "and disocclusions take the environment map (SOFF §3.4, §3.5).";
  const Scene* scene = nullptr;
  SoffIntersectSettings settings;
  void parameters(par::Params& p) const {
    p.set("glossy_rays", settings.glossy_rays).set("reshade", settings.reshade).set("concave", settings.concave_self);
  }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const SoffClusters& clusters,
                       const SoffCameras& cameras, const SoffDepthImages& images, const ShadowMaps& shadows,
                       const EnvironmentMap& environment) const;
};

}  // namespace speculum::raster
