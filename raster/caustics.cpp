// Caustics through distance maps (see caustics.h).
#include "raster/caustics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/error.h"
#include "core/optics.h"
#include "core/shading.h"
#include "core/shading_lanes.h"
#include "parallel/lanes.h"
#include "raster/cube_bilinear_lanes.h"
#include "raster/cube_coord_lanes.h"
#include "raster/refraction_path.h"
#include "raster/visibility.h"

namespace speculum::raster {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kMaxSplatRadius = 8;  // texels: bounds a splat's work ((2r+1)² texels)

bool generator_material(const SurfaceParams& s) { return s.is_refractor() || s.is_mirror_lobe(); }

struct Sphere {
  glm::vec3 centre{0.0f};
  float radius = 0.0f;
};

// The object's bounding sphere: its box centre and farthest vertex.
Sphere bounding_sphere(const Scene& scene, const Object& obj) {
  Bounds b;
  for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) b.grow(scene.mesh.positions[scene.mesh.indices[3 * t + k]]);
  float r2 = 0.0f;
  for (std::uint32_t t = obj.first_triangle; t < obj.first_triangle + obj.triangle_count; ++t)
    for (int k = 0; k < 3; ++k) {
      const glm::vec3 d = scene.mesh.positions[scene.mesh.indices[3 * t + k]] - b.center();
      r2 = std::max(r2, glm::dot(d, d));
    }
  return {b.center(), std::sqrt(r2) * 1.01f + 1e-6f};
}

// A face's plane in a size² cube: its centre direction f and the offsets r, u to the centres
// of its right and top edges.
struct FacePlane {
  glm::vec3 f, r, u;
  FacePlane() = default;
  FacePlane(int face, int size) {
    const float s = static_cast<float>(size);
    f = cube_direction(face, {0.5f * s, 0.5f * s}, size);
    r = cube_direction(face, {s, 0.5f * s}, size) * std::sqrt(2.0f) - f;
    u = cube_direction(face, {0.5f * s, 0.0f}, size) * std::sqrt(2.0f) - f;
  }
};

// The six faces' planes of a size² cube.
std::array<FacePlane, kCubeFaces> face_planes(int size) {
  std::array<FacePlane, kCubeFaces> planes;
  for (int face = 0; face < kCubeFaces; ++face) planes[face] = FacePlane(face, size);
  return planes;
}

// Continuous pixel coordinates of direction d projected on `plane` (a face of a size² cube),
// unclamped (beyond [0, size] off the face): so caustic triangles and photon spacings that
// straddle a face edge are measured in one face's texels. False when d points away from the
// face.
bool face_pixel(const glm::vec3& d, const FacePlane& plane, int size, glm::vec2& out) {
  const float s = static_cast<float>(size);
  const float depth = glm::dot(d, plane.f);
  if (depth <= 0.0f) return false;
  out = {(glm::dot(d, plane.r) / depth + 1.0f) * 0.5f * s, (1.0f - glm::dot(d, plane.u) / depth) * 0.5f * s};
  return true;
}

// A texel and its share of a caustic triangle.
struct TexelShare {
  int x, y;
  float w;
};

// A caustic map being built: flux, weight and Σ weight·distance in the cube, Σ weight·wi
// beside it.
struct MapTarget {
  CubeMap& m;
  CubeDirections& incident;
};

// Adds `share` of a photon's flux, arriving from distance `dist` along direction `wi`, to a
// texel's sums: flux and weight, weighted distance, weighted direction.
void add_share(glm::vec4& colour, float& distance, glm::vec3& incident, const glm::vec3& flux, float share,
               float dist, const glm::vec3& wi) {
  colour += glm::vec4(flux * share, share);
  distance += share * dist;
  incident += share * wi;
}

// add_share at texel (x, y) of `face`.
void deposit(MapTarget& t, int face, int x, int y, const glm::vec3& flux, float share, float dist,
             const glm::vec3& wi) {
  add_share(t.m.colour[face].at(x, y), t.m.distance[face].at(x, y), t.incident[face].at(x, y), flux, share, dist, wi);
}

// A tent kernel of `radius` texels about continuous pixel position c, clipped to the face:
// the texels it covers, weighted max(0, 1 − |texel centre − c| / (radius + ½)).
struct SplatKernel {
  static constexpr int kColumns = 24;  // 2 kMaxSplatRadius + 1, rounded up to lanes of 8
  int x0, x1, y0, y1;                  // inclusive
  float reach;
  SplatKernel(const CubeCoord& c, int radius, int size) {
    const int cx = std::clamp(static_cast<int>(c.pixel.x), 0, size - 1);
    const int cy = std::clamp(static_cast<int>(c.pixel.y), 0, size - 1);
    x0 = std::max(0, cx - radius);
    x1 = std::min(size - 1, cx + radius);
    y0 = std::max(0, cy - radius);
    y1 = std::min(size - 1, cy + radius);
    reach = static_cast<float>(radius) + 0.5f;
  }
  // Row y's weights, columns x0..x1, into w[0, x1 − x0], and each over `total` into share:
  // eight columns at once in lanes.
  void row_weights(const CubeCoord& c, int y, float total, float (&w)[kColumns], float (&share)[kColumns]) const {
    using L = par::Lanes<8>;
    const float dy = static_cast<float>(y) + 0.5f - c.pixel.y;
    const L::f32 dy2(dy * dy), zero(0.0f);
    for (int i = 0; i <= x1 - x0; i += 8) {
      const L::f32 dx = L::to_float(L::iota(x0 + i)) + 0.5f - c.pixel.x;
      const L::f32 weight = L::max(zero, 1.0f - L::sqrt(dx * dx + dy2) / reach);
      L::store(weight, w + i);
      L::store(weight / total, share + i);
    }
  }
};

// A photon as the splat filter stores it: the texel position of its direction from the map's
// centre, its distance, kernel radius and the sum of its kernel's weights.
struct PhotonSplat {
  CubeCoord c;
  float dist = 0.0f;
  int radius = 0;
  float total = 1.0f;
  const PhotonImage* image = nullptr;
  std::uint32_t texel = 0;
};

// The kernel weights' sums of `count` (1..8) splats of radius > 0 on size² faces: each lane
// adds one kernel's weights in row-major order (a serial sum per splat: eight side by side
// keep the adder busy), with the operations of SplatKernel::row_weights.
void splat_totals8(PhotonSplat* const* sp, int count, int size) {
  using L = par::Lanes<8>;
  alignas(32) std::int32_t x0[8] = {}, x1[8] = {}, y0[8] = {}, n[8] = {};
  alignas(32) float px[8] = {}, py[8] = {}, reach[8] = {}, total[8];
  int steps = 0;
  for (int j = 0; j < count; ++j) {
    const SplatKernel k(sp[j]->c, sp[j]->radius, size);
    x0[j] = k.x0, x1[j] = k.x1, y0[j] = k.y0, reach[j] = k.reach;
    n[j] = (k.x1 - k.x0 + 1) * (k.y1 - k.y0 + 1);
    px[j] = sp[j]->c.pixel.x, py[j] = sp[j]->c.pixel.y;
    steps = std::max(steps, n[j]);
  }
  const L::i32 first_x = L::load_aligned(x0), last_x = L::load_aligned(x1), texels = L::load_aligned(n);
  const L::f32 cx = L::load_aligned(px), cy = L::load_aligned(py), r = L::load_aligned(reach), zero(0.0f);
  L::i32 x = first_x, y = L::load_aligned(y0);
  L::f32 sum(0.0f);
  for (int k = 0; k < steps; ++k) {
    const L::f32 dx = L::to_float(x) + 0.5f - cx, dy = L::to_float(y) + 0.5f - cy;
    const L::f32 w = L::max(zero, 1.0f - L::sqrt(dx * dx + dy * dy) / r);
    sum = L::select(L::i32(k) < texels, sum + w, sum);
    x = x + 1;
    const L::mask wrap = x > last_x;
    y = L::select(wrap, y + 1, y);
    x = L::select(wrap, first_x, x);
  }
  L::store_aligned(sum, total);
  for (int j = 0; j < count; ++j) sp[j]->total = total[j];
}

// Adds a photon's flux to the texel under c alone.
void deposit_nearest(MapTarget& t, const CubeCoord& c, const glm::vec3& flux, float dist, const glm::vec3& wi) {
  const int size = t.m.size;
  deposit(t, c.face, std::clamp(static_cast<int>(c.pixel.x), 0, size - 1),
          std::clamp(static_cast<int>(c.pixel.y), 0, size - 1), flux, 1.0f, dist, wi);
}

// Photon sp's flux spread by its tent kernel, the weights normalized over the texels of its
// face (so they sum to one), deposited in rows [row_begin, row_end) only: a face stored in
// bands of rows gets the sums of one pass.
void splat_rows(MapTarget& t, const PhotonSplat& sp, int row_begin, int row_end) {
  const glm::vec3& flux = sp.image->flux[sp.texel];
  const glm::vec3& wi = sp.image->wi[sp.texel];
  if (sp.radius <= 0) {
    const int cy = std::clamp(static_cast<int>(sp.c.pixel.y), 0, t.m.size - 1);
    if (cy >= row_begin && cy < row_end) deposit_nearest(t, sp.c, flux, sp.dist, wi);
    return;
  }
  const SplatKernel k(sp.c, sp.radius, t.m.size);
  alignas(32) float w[SplatKernel::kColumns], share[SplatKernel::kColumns];
  for (int y = std::max(k.y0, row_begin); y <= std::min(k.y1, row_end - 1); ++y) {
    k.row_weights(sp.c, y, sp.total, w, share);
    // add_share along the row, the three planes' row pointers found once.
    glm::vec4* colour = &t.m.colour[sp.c.face].at(k.x0, y);
    float* distance = &t.m.distance[sp.c.face].at(k.x0, y);
    glm::vec3* incident = &t.incident[sp.c.face].at(k.x0, y);
    for (int i = 0; i <= k.x1 - k.x0; ++i)
      if (w[i] > 0.0f) add_share(colour[i], distance[i], incident[i], flux, share[i], sp.dist, wi);
  }
}

float edge(glm::vec2 a, glm::vec2 b, glm::vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

// The area of triangle p inside texel [x, x+1] × [y, y+1]: the triangle clipped by the
// texel's four sides (Sutherland–Hodgman; at most 7 corners), then the shoelace formula.
float texel_overlap(const glm::vec2 (&p)[3], float x, float y) {
  glm::vec2 poly[8] = {p[0], p[1], p[2]}, next[8];
  int n = 3;
  // Each side as (axis, bound, keep the side above the bound).
  const struct { int axis; float bound; bool above; } sides[4] = {
      {0, x, true}, {0, x + 1.0f, false}, {1, y, true}, {1, y + 1.0f, false}};
  for (const auto& side : sides) {
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const glm::vec2 a = poly[i], b = poly[(i + 1) % n];
      const float da = side.above ? a[side.axis] - side.bound : side.bound - a[side.axis];
      const float db = side.above ? b[side.axis] - side.bound : side.bound - b[side.axis];
      if (da >= 0.0f) next[m++] = a;
      if ((da >= 0.0f) != (db >= 0.0f)) next[m++] = a + (b - a) * (da / (da - db));
    }
    n = m;
    if (n == 0) return 0.0f;
    std::copy(next, next + n, poly);
  }
  float twice = 0.0f;
  for (int i = 0; i < n; ++i) twice += poly[i].x * poly[(i + 1) % n].y - poly[(i + 1) % n].x * poly[i].y;
  return 0.5f * std::fabs(twice);
}

// A caustic triangle's flux spread over the texels it overlaps in proportion to the area of
// each overlap (box-filtered rasterization: a triangle smaller than a texel does not alias
// against the texel grid), normalized over the face's texels so its total is kept exactly;
// a triangle with no area inside the face goes to the texel under its centroid.
void raster_triangle(MapTarget& t, int face, const glm::vec2 (&p)[3], const glm::vec3& flux, float dist,
                     const glm::vec3& wi, std::vector<TexelShare>& scratch) {
  const CubeMap& m = t.m;
  scratch.clear();
  const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
  const int x1 = std::min(m.size - 1, static_cast<int>(std::floor(std::max({p[0].x, p[1].x, p[2].x}))));
  const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
  const int y1 = std::min(m.size - 1, static_cast<int>(std::floor(std::max({p[0].y, p[1].y, p[2].y}))));
  float total = 0.0f;
  if (edge(p[0], p[1], p[2]) != 0.0f)
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const float a = texel_overlap(p, static_cast<float>(x), static_cast<float>(y));
        if (a > 0.0f) {
          scratch.push_back({x, y, a});
          total += a;
        }
      }
  if (!(total > 0.0f)) {
    const glm::vec2 g = (p[0] + p[1] + p[2]) / 3.0f;
    scratch.assign(1, {std::clamp(static_cast<int>(g.x), 0, m.size - 1), std::clamp(static_cast<int>(g.y), 0, m.size - 1), 1.0f});
    total = 1.0f;
  }
  for (const TexelShare& e : scratch) deposit(t, face, e.x, e.y, flux, e.w / total, dist, wi);
}

// A normalized 3×3 tent blur inside each face: every texel's flux goes to its in-face
// neighbours with weights that sum to one (the total is kept).
void blur(CubeMap& m, CubeDirections& incident) {
  static constexpr float k[3] = {0.25f, 0.5f, 0.25f};
  for (int f = 0; f < kCubeFaces; ++f) {
    ImageRGBA colour(m.size, m.size, glm::vec4(0.0f));
    ImageF dist(m.size, m.size, 0.0f);
    Buffer2D<glm::vec3> inc(m.size, m.size, glm::vec3(0.0f));
    for (int y = 0; y < m.size; ++y)
      for (int x = 0; x < m.size; ++x) {
        const glm::vec4 c = m.colour[f].at(x, y);
        if (c.w == 0.0f) continue;
        const float d = m.distance[f].at(x, y);
        const glm::vec3 wi = incident[f].at(x, y);
        float total = 0.0f;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if (x + dx >= 0 && x + dx < m.size && y + dy >= 0 && y + dy < m.size) total += k[dx + 1] * k[dy + 1];
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx)
            if (x + dx >= 0 && x + dx < m.size && y + dy >= 0 && y + dy < m.size) {
              const float w = k[dx + 1] * k[dy + 1] / total;
              colour.at(x + dx, y + dy) += c * w;
              dist.at(x + dx, y + dy) += d * w;
              inc.at(x + dx, y + dy) += wi * w;
            }
      }
    m.colour[f] = std::move(colour);
    m.distance[f] = std::move(dist);
    incident[f] = std::move(inc);
  }
}

}  // namespace

std::vector<std::uint32_t> caustic_generator_objects(const Scene& scene) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    if (obj.triangle_count == 0 || obj.material >= scene.materials.size()) continue;
    if (generator_material(surface_params(scene.materials[obj.material]))) out.push_back(o);
  }
  return out;
}

namespace {

// A photon on its way: texel i of its photon image, at x going along r, carrying flux.
struct PhotonStep {
  std::uint32_t i;
  glm::vec3 x, r, flux;
};

// search_distance_map from each step's x along its r, eight at a time (search_distance_map8:
// each the bits of the search alone).
std::vector<DistanceSearchResult> first_searches(const CubeMap& map, const std::vector<PhotonStep>& steps,
                                                 const DistanceSearchOptions& options) {
  std::vector<DistanceSearchResult> found(steps.size());
  for (std::size_t first = 0; first < steps.size(); first += 8) {
    const int count = static_cast<int>(std::min<std::size_t>(8, steps.size() - first));
    glm::vec3 x[8], r[8];
    for (int j = 0; j < count; ++j) x[j] = steps[first + j].x, r[j] = steps[first + j].r;
    search_distance_map8(map, x, r, count, options, &found[first]);
  }
  return found;
}

}  // namespace

CausticPhotons trace_photon_images(par::Executor& ex, const Scene& scene, const ReflectorMaps& maps,
                                   const RefractorImpostors* impostors, const CausticPhotonOptions& opt) {
  if (opt.photon_res < 1 || opt.photon_res > 4096)
    throw InputError("caustic_photons", "photon_res out of range (1..4096)");
  CausticPhotons out;
  const std::vector<std::uint32_t> gens = caustic_generator_objects(scene);
  // What a photon needs of a generator it reaches from another: its impostor (to know it is
  // there, and its normal), its material and its distance map.
  struct Generator {
    std::uint32_t object = 0;
    const CubeMap* impostor = nullptr;
    const CubeMap* map = nullptr;
    SurfaceParams surface;
  };
  std::vector<Generator> generators;
  for (std::uint32_t o : gens) {
    Generator gen;
    gen.object = o;
    gen.impostor = impostors ? impostors->for_object(o) : nullptr;
    if (o < maps.map_of_object.size() && maps.map_of_object[o] >= 0)
      gen.map = &maps.cubes[static_cast<std::size_t>(maps.map_of_object[o])];
    gen.surface = surface_params(scene.materials[scene.objects[o].material]);
    generators.push_back(gen);
  }
  // Refracted in at p (unit v towards the surface, n the outward normal facing v) and out
  // through the exit the impostor finds, total internal reflections followed up to `chain`
  // in all (each × transmission, as the reference weights them). 0, with the photon's flux
  // weighted by (1 − F1)(1 − F2) × (transmission × base colour)² and its exit x, r; or why it
  // was lost: 2 TIR beyond the bound, 3 no exit found.
  const auto refract_through = [&](const CubeMap& im, const SurfaceParams& s, const glm::vec3& p, const glm::vec3& v,
                                   const glm::vec3& n, std::uint8_t& chain, glm::vec3& flux, glm::vec3& x,
                                   glm::vec3& r) -> std::uint8_t {
    RefractionPath path = enter_refractor(p, v, n, s.ior);
    glm::vec3 start = p, p2, n2;
    glm::vec3 inside_weight(1.0f);
    for (;;) {
      if (!find_impostor_exit(im, start, path.inside, opt.exit_search, p2, n2)) return 3;
      leave_refractor(path, p2, n2, s.ior);
      if (!path.total_internal) break;
      if (chain == opt.chain) return 2;
      ++chain;
      inside_weight *= s.transmission;
      start = p2;
      path.inside = glm::normalize(path.internal);
    }
    const glm::vec3 t = s.transmission * s.base_color;
    flux *= inside_weight * t * (1.0f - path.f_entry) * t * (1.0f - path.f_exit);
    x = p2;
    r = glm::normalize(path.exit_direction);
    return 0;
  };
  for (std::uint32_t li = 0; li < scene.lights.size(); ++li) {
    const Light& light = scene.lights[li];
    for (std::uint32_t object : gens) {
      if (object >= maps.map_of_object.size() || maps.map_of_object[object] < 0) continue;
      const int map_index = maps.map_of_object[object];
      const CubeMap& env = maps.cubes[static_cast<std::size_t>(map_index)];
      const Sphere sphere = bounding_sphere(scene, scene.objects[object]);
      // The light's view of the generator: a square frustum holding its bounding sphere. A
      // directional light looks from 100 radii away along its direction (nearly parallel
      // rays; the photon's direction is the light's own).
      const bool directional = light.type == LightType::Directional;
      Camera cam;
      float dist_to_centre = 0.0f;
      if (directional) {
        dist_to_centre = 100.0f * sphere.radius;
        cam.eye = sphere.centre - glm::normalize(light.direction) * dist_to_centre;
      } else {
        cam.eye = light.position;
        dist_to_centre = glm::length(sphere.centre - light.position);
        if (dist_to_centre <= sphere.radius) continue;  // the light inside its generator's sphere
      }
      cam.target = sphere.centre;
      const glm::vec3 forward = glm::normalize(cam.target - cam.eye);
      cam.up = std::fabs(forward.y) > 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      const float half = std::asin(std::min(1.0f, sphere.radius / dist_to_centre));
      cam.vfov_degrees = glm::degrees(2.0f * half);
      cam.znear = std::max(1e-4f * dist_to_centre, (dist_to_centre - sphere.radius) * 1e-3f);
      cam.zfar = dist_to_centre + 2.0f * sphere.radius;
      const int res = opt.photon_res;
      const VisibilityBuffer vis = render_visibility(ex, scene, cam, res, res);
      const GBuffer gb = resolve_gbuffer(ex, scene, vis, cam.eye);
      const float tan_half = std::tan(half);
      const float pixel_area = (2.0f * tan_half / static_cast<float>(res)) * (2.0f * tan_half / static_cast<float>(res));
      // A refractor makes two photon images from one view: the refracted path and the
      // surface reflection (each photon image carries one path per texel).
      const bool refractor = surface_params(scene.materials[scene.objects[object].material]).is_refractor();
      for (int kind = 0; kind < (refractor ? 2 : 1); ++kind) {
        const bool surface_reflection = kind == 1;
        PhotonImage img;
        img.object = object;
        img.light = li;
        img.res = res;
        img.surface_reflection = surface_reflection;
        img.centre = maps.centres[static_cast<std::size_t>(map_index)];
        const std::size_t n = static_cast<std::size_t>(res) * res;
        img.hit.assign(n, glm::vec3(0.0f));
        img.wi.assign(n, glm::vec3(0.0f));
        img.flux.assign(n, glm::vec3(0.0f));
        img.valid.assign(n, 0);
        std::vector<glm::vec3> arriving(n, glm::vec3(0.0f));
        std::vector<std::uint8_t> state(n, 0);  // 0 none, 1 stored, 2 TIR, 3 no receiver, 4 chain bound
        std::vector<std::uint8_t> chain(n, 0);  // internal reflections and hops followed
        std::vector<std::uint8_t> hops(n, 0);   // of which into other generators
        const CubeMap* impostor = impostors ? impostors->for_object(object) : nullptr;
        ex.parallel_for("caustic_photons", n, 256, [&](std::size_t b, std::size_t e) {
          // Each texel's photon up to a mirror's self-searches or its receiver, then those
          // searches, the first of each photon side by side with others' (in texel order).
          std::vector<PhotonStep> pending, mirrored;
          for (std::size_t i = b; i < e; ++i) {
            if (gb.object.pixels[i] != object) continue;
            const SurfaceParams& s = gb.surface[i];
            if (!generator_material(s)) continue;
            const glm::vec3 p1 = gb.position.pixels[i];
            const glm::vec3 v = directional ? glm::normalize(light.direction) : glm::normalize(p1 - light.position);
            // Power: I(ω) Ω_texel (Ω = the texel's unit-plane area × cos³θ), or E × the texel's
            // area for a directional light. sample_light gives E = I window cone / d² at p1.
            const LightSample ls = sample_light(light, p1);
            glm::vec3 flux;
            if (directional) {
              flux = ls.irradiance * (pixel_area * dist_to_centre * dist_to_centre);
            } else {
              const float cos_t = glm::dot(v, forward);
              flux = ls.irradiance * (ls.distance * ls.distance) * (pixel_area * cos_t * cos_t * cos_t);
            }
            if (flux == glm::vec3(0.0f)) continue;
            arriving[i] = flux;
            glm::vec3 x(0.0f), r(0.0f);
            if (s.is_refractor() && !surface_reflection) {
              glm::vec3 n1 = gb.normal.pixels[i];
              if (glm::dot(n1, v) >= 0.0f) n1 = -n1;
              if (!impostor) continue;
              const std::uint8_t lost = refract_through(*impostor, s, p1, v, n1, chain[i], flux, x, r);
              if (lost) {
                state[i] = lost;
                continue;
              }
            } else if (s.is_refractor()) {
              // The refractor's surface reflection, weighted as the reference weights it:
              // transmission × exact Fresnel F.
              glm::vec3 n1 = gb.normal.pixels[i];
              if (glm::dot(n1, v) > 0.0f) n1 = -n1;
              flux *= s.transmission * fresnel_dielectric(-glm::dot(n1, v), s.ior);
              x = p1;
              r = reflect(v, n1);
            } else {
              glm::vec3 n1 = gb.normal.pixels[i];
              if (glm::dot(n1, v) > 0.0f) n1 = -n1;
              flux *= specular_reflectance(s, -glm::dot(n1, v));
              x = p1;
              r = reflect(v, n1);
              if (impostor) {  // its self-searches below, the first side by side with others'
                mirrored.push_back({static_cast<std::uint32_t>(i), x, r, flux});
                continue;
              }
            }
            pending.push_back({static_cast<std::uint32_t>(i), x, r, flux});
          }
          // A concave mirror (a ring, a bowl) meets itself again: the ray searched in the
          // mirror's own distance impostor. A crossing is the next reflection when it is
          // bracketed, lies on the stored surface (within 2 %: a bracket from an empty
          // direction into one behind the surface is none), beyond a twentieth of the
          // mirror's radius, and before the receiver the environment search brackets;
          // up to `chain` of them. A photon still meeting the mirror after those is
          // dropped (its receiver would be behind the mirror: a light leak).
          const std::vector<DistanceSearchResult> self_first =
              impostor ? first_searches(*impostor, mirrored, opt.exit_search) : std::vector<DistanceSearchResult>{};
          for (std::size_t q = 0; q < mirrored.size(); ++q) {
            const std::size_t i = mirrored[q].i;
            const SurfaceParams& s = gb.surface[i];
            glm::vec3 x = mirrored[q].x, r = mirrored[q].r, flux = mirrored[q].flux;
            bool lost = false;
            for (bool first = true;; first = false) {
              const DistanceSearchResult self = first ? self_first[q] : search_distance_map(*impostor, x, r, opt.exit_search);
              if (!self.bracketed || !(self.d > 0.05f * sphere.radius)) break;
              const glm::vec3 on = x + r * self.d - impostor->centre;
              const float surface = impostor->distance_towards(on);
              if (!(std::fabs(glm::length(on) - surface) <= 0.02f * surface)) break;
              const DistanceSearchResult before = search_distance_map(env, x, r, opt.receiver_search);
              if (before.bracketed && before.d < self.d) break;
              if (chain[i] == opt.chain) {
                state[i] = 4;
                lost = true;
                break;
              }
              ++chain[i];
              x += r * self.d;
              glm::vec3 nm(impostor->colour_towards(self.direction));
              nm = glm::dot(nm, nm) > 0.0f ? glm::normalize(nm) : glm::normalize(x - impostor->centre);
              if (glm::dot(nm, r) > 0.0f) nm = -nm;
              flux *= specular_reflectance(s, -glm::dot(nm, r));
              r = glm::normalize(reflect(r, nm));
            }
            if (lost) continue;
            pending.push_back({static_cast<std::uint32_t>(i), x, r, flux});
          }
          // The receivers, their first searches in the generator's distance map side by side.
          const std::vector<DistanceSearchResult> receiver = first_searches(env, pending, opt.receiver_search);
          for (std::size_t q = 0; q < pending.size(); ++q) {
            const std::size_t i = pending[q].i;
            glm::vec3 x = pending[q].x, r = pending[q].r, flux = pending[q].flux;
            // The receiver, searched in the generator's distance map. Where it lies on another
            // generator (on that generator's impostor surface, within 3 %), the photon goes on
            // through it (reflected off a mirror, or refracted in and out of a refractor: its
            // surface reflection is not followed) and searches that generator's distance map,
            // each such hop one of the `chain` steps; it is stored in its first generator's map.
            const CubeMap* search_map = &env;
            std::uint32_t current = object;
            glm::vec3 hit(0.0f);
            bool lost = false;
            for (bool first = true;; first = false) {
              const DistanceSearchResult found =
                  first ? receiver[q] : search_distance_map(*search_map, x, r, opt.receiver_search);
              const float stored = std::isfinite(found.d) ? search_map->distance_towards(found.direction) : kInf;
              if (!std::isfinite(stored)) {
                state[i] = 3;
                lost = true;
                break;
              }
              hit = search_map->centre + glm::normalize(found.direction) * stored;
              const Generator* next = nullptr;
              glm::vec3 nn(0.0f);
              for (const Generator& gen : generators) {
                if (gen.object == current || !gen.impostor || !gen.map) continue;
                const glm::vec3 on = hit - gen.impostor->centre;
                const float surface = gen.impostor->distance_towards(on);
                if (std::isfinite(surface) && std::fabs(glm::length(on) - surface) <= 0.03f * surface) {
                  next = &gen;
                  nn = glm::vec3(gen.impostor->colour_towards(on));
                  nn = glm::dot(nn, nn) > 0.0f ? glm::normalize(nn) : glm::normalize(on);
                  break;
                }
              }
              if (!next) break;  // a diffuse receiver
              if (chain[i] == opt.chain) {
                state[i] = 4;
                lost = true;
                break;
              }
              ++chain[i];
              ++hops[i];
              const SurfaceParams& sn = next->surface;
              if (sn.is_refractor()) {
                if (glm::dot(nn, r) >= 0.0f) nn = -nn;
                glm::vec3 x2, r2;
                const std::uint8_t why = refract_through(*next->impostor, sn, hit, r, nn, chain[i], flux, x2, r2);
                if (why) {
                  state[i] = why;
                  lost = true;
                  break;
                }
                x = x2;
                r = r2;
              } else {
                if (glm::dot(nn, r) > 0.0f) nn = -nn;
                flux *= specular_reflectance(sn, -glm::dot(nn, r));
                x = hit;
                r = glm::normalize(reflect(r, nn));
              }
              search_map = next->map;
              current = next->object;
            }
            if (lost) continue;
            img.hit[i] = hit;
            const glm::vec3 back = x - img.hit[i];
            img.wi[i] = glm::dot(back, back) > 0.0f ? glm::normalize(back) : -r;
            img.flux[i] = flux;
            img.valid[i] = 1;
            state[i] = 1;
          }
        });
        for (std::size_t i = 0; i < n; ++i) {
          if (arriving[i] == glm::vec3(0.0f)) continue;
          if (!surface_reflection) {  // each texel's arriving power counted once
            ++out.photons;
            out.generator_flux += glm::dvec3(arriving[i]);
          }
          out.internal_reflections += chain[i] - hops[i];
          out.generator_hops += hops[i];
          if (state[i] == 1) {
            ++out.stored;
            out.stored_flux += glm::dvec3(img.flux[i]);
          } else if (state[i] == 2) {
            ++out.total_internal;
          } else if (state[i] == 3) {
            ++out.no_receiver;
          } else if (state[i] == 4) {
            ++out.chain_limited;
          }
        }
        out.images.push_back(std::move(img));
      }
    }
  }
  return out;
}

float cube_texel_solid_angle(int x, int y, int size) {
  const float s = static_cast<float>(size);
  const float u = 2.0f * (static_cast<float>(x) + 0.5f) / s - 1.0f, v = 2.0f * (static_cast<float>(y) + 0.5f) / s - 1.0f;
  const float q = 1.0f + u * u + v * v;
  return (2.0f / s) * (2.0f / s) / (q * std::sqrt(q));
}

glm::dvec3 caustic_map_flux(const CubeMap& map) {
  glm::dvec3 sum(0.0);
  for (int f = 0; f < kCubeFaces; ++f)
    for (const glm::vec4& c : map.colour[f].pixels) sum += glm::dvec3(c.x, c.y, c.z);
  return sum;
}

// The splats of image `img`'s photons into map m, in the order of its texels, with their
// kernels' totals.
void photon_splats(const PhotonImage& img, const CubeMap& m, const CausticMapOptions& opt,
                   std::vector<PhotonSplat>& out) {
  const int res = img.res;
  const std::array<FacePlane, kCubeFaces> planes = face_planes(m.size);
  auto idx = [&](int x, int y) { return static_cast<std::size_t>(y) * res + x; };
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) {
      const std::size_t i = idx(x, y);
      if (!img.valid[i]) continue;
      PhotonSplat sp;
      const glm::vec3 d = img.hit[i] - m.centre;
      sp.c = cube_coord(d, m.size);
      sp.dist = glm::length(d);
      sp.radius = opt.splat_radius;
      if (opt.adaptive) {
        // The photon's reach: the farthest of its photon-image neighbours on the same
        // receiver (distances within 20 %), in caustic-map texels, so sparse photons
        // leave no holes and dense ones stay sharp.
        float spacing = 0.0f;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
          if (nx[k] < 0 || ny[k] < 0 || nx[k] >= res || ny[k] >= res) continue;
          const std::size_t j = idx(nx[k], ny[k]);
          if (!img.valid[j]) continue;
          const glm::vec3 dj = img.hit[j] - m.centre;
          const float lj = glm::length(dj);
          if (std::max(lj, sp.dist) > 1.2f * std::min(lj, sp.dist)) continue;
          glm::vec2 pj;
          if (face_pixel(dj, planes[sp.c.face], m.size, pj)) spacing = std::max(spacing, glm::length(pj - sp.c.pixel));
        }
        sp.radius = std::max(sp.radius, std::min(kMaxSplatRadius, static_cast<int>(std::ceil(spacing))));
      }
      sp.image = &img;
      sp.texel = static_cast<std::uint32_t>(i);
      out.push_back(sp);
    }
  // Eight splats of one radius at a time (their kernels as long, but at the face's edges).
  for (int radius = 1; radius <= kMaxSplatRadius; ++radius) {
    PhotonSplat* wide[8];
    int count = 0;
    for (PhotonSplat& sp : out) {
      if (sp.radius != radius) continue;
      wide[count++] = &sp;
      if (count == 8) splat_totals8(wide, count, m.size), count = 0;
    }
    if (count > 0) splat_totals8(wide, count, m.size);
  }
}

// Stores the caustic triangles of image `img` into its map (target), in the order of its
// texels, on every face.
void store_caustic_triangles(const PhotonImage& img, MapTarget& target, std::vector<TexelShare>& scratch) {
  CubeMap& m = target.m;
  const int res = img.res;
  auto idx = [&](int x, int y) { return static_cast<std::size_t>(y) * res + x; };
  const std::array<FacePlane, kCubeFaces> planes = face_planes(m.size);
  // Caustic triangles (§6.3.2): a cell of four neighbouring photons whose receiver
  // distances agree within 20 % (one receiver surface) makes two triangles, drawn on the
  // face of the cell's mean direction. Each photon's flux is shared equally by the cells it
  // is a corner of; a photon in none is splatted into its texel.
  const int cells = res - 1;
  std::vector<std::uint8_t> cell_ok(static_cast<std::size_t>(std::max(cells, 0)) * std::max(cells, 0), 0);
  std::vector<float> dists(img.valid.size(), 0.0f);
  for (std::size_t i = 0; i < img.valid.size(); ++i)
    if (img.valid[i]) dists[i] = glm::length(img.hit[i] - m.centre);
  std::vector<int> corner_of(img.valid.size(), 0);
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      const std::size_t c[4] = {idx(x, y), idx(x + 1, y), idx(x + 1, y + 1), idx(x, y + 1)};
      bool ok = true;
      float lo = kInf, hi = 0.0f;
      for (std::size_t k : c) {
        ok = ok && img.valid[k];
        lo = std::min(lo, dists[k]);
        hi = std::max(hi, dists[k]);
      }
      if (!ok || hi > 1.2f * lo) continue;
      cell_ok[static_cast<std::size_t>(y) * cells + x] = 1;
      for (std::size_t k : c) ++corner_of[k];
    }
  for (std::size_t i = 0; i < img.valid.size(); ++i)
    if (img.valid[i] && corner_of[i] == 0) deposit_nearest(target, cube_coord(img.hit[i] - m.centre, m.size), img.flux[i], dists[i], img.wi[i]);
  for (int y = 0; y < cells; ++y)
    for (int x = 0; x < cells; ++x) {
      if (!cell_ok[static_cast<std::size_t>(y) * cells + x]) continue;
      const std::size_t c[4] = {idx(x, y), idx(x + 1, y), idx(x + 1, y + 1), idx(x, y + 1)};
      glm::vec3 flux(0.0f), wi(0.0f);
      float dist = 0.0f;
      glm::vec2 p[4];
      glm::vec3 mean_dir(0.0f);
      for (int k = 0; k < 4; ++k) {
        flux += img.flux[c[k]] / static_cast<float>(corner_of[c[k]]);
        dist += 0.25f * dists[c[k]];
        wi += 0.25f * img.wi[c[k]];
        mean_dir += (img.hit[c[k]] - m.centre) / dists[c[k]];
      }
      const int face = cube_coord(mean_dir, m.size).face;
      bool projected = true;
      for (int k = 0; k < 4; ++k) projected = projected && face_pixel(img.hit[c[k]] - m.centre, planes[face], m.size, p[k]);
      if (!projected) {  // a cell wider than a face's half space: its corners as points
        for (int k = 0; k < 4; ++k)
          deposit_nearest(target, cube_coord(img.hit[c[k]] - m.centre, m.size),
                          img.flux[c[k]] / static_cast<float>(corner_of[c[k]]), dists[c[k]], img.wi[c[k]]);
        continue;
      }
      const glm::vec2 t0[3] = {p[0], p[1], p[2]}, t1[3] = {p[0], p[2], p[3]};
      raster_triangle(target, face, t0, flux * 0.5f, dist, wi, scratch);
      raster_triangle(target, face, t1, flux * 0.5f, dist, wi, scratch);
    }
}

// Rows [row_begin, row_end) of face f: flux-weighted mean distances (+inf where nothing
// landed) and unit incident directions; the weights' sums are done with.
void finish_rows(CubeMap& m, CubeDirections& incident, int f, int row_begin, int row_end) {
  const std::size_t w = static_cast<std::size_t>(m.size);
  for (std::size_t i = static_cast<std::size_t>(row_begin) * w; i < static_cast<std::size_t>(row_end) * w; ++i) {
    glm::vec4& c = m.colour[f].pixels[i];
    float& d = m.distance[f].pixels[i];
    glm::vec3& wi = incident[f].pixels[i];
    d = c.w > 0.0f ? d / c.w : kInf;
    wi = glm::dot(wi, wi) > 0.0f ? glm::normalize(wi) : glm::vec3(0.0f);
    c.w = 1.0f;
  }
}

void finish_face(CubeMap& m, CubeDirections& incident, int f) { finish_rows(m, incident, f, 0, m.size); }

CausticMaps build_caustic_maps(par::Executor& executor, const Scene& scene, const CausticPhotons& photons,
                               const CausticMapOptions& opt) {
  if (opt.size < 1 || opt.size > 4096) throw InputError("caustic_map", "size out of range (1..4096)");
  if (opt.splat_radius < 0 || opt.splat_radius > kMaxSplatRadius)
    throw InputError("caustic_map", "splat_radius out of range (0..8)");
  CausticMaps out;
  out.map_of_object.assign(scene.objects.size(), -1);
  // One map per generator (cube storage), or per generator and light (light storage), in the
  // order the images first name them; each map's images in image order.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> map_index;
  std::vector<std::vector<const PhotonImage*>> images_of;
  const bool light_space = opt.storage == CausticStorage::Light;
  for (const PhotonImage& img : photons.images) {
    const std::pair<std::uint32_t, std::uint32_t> key{img.object, light_space ? img.light : 0u};
    if (!map_index.count(key)) {
      map_index[key] = out.cubes.size();
      if (out.map_of_object[img.object] < 0) out.map_of_object[img.object] = static_cast<int>(out.cubes.size());
      CubeMap m;
      m.size = opt.size;
      m.centre = img.centre;
      if (light_space) {
        // Centred at the light (a directional light: two scene diameters back along its rays).
        const Light& l = scene.lights[img.light];
        m.centre = l.type == LightType::Directional
                       ? img.centre - glm::normalize(l.direction) * (2.0f * glm::length(scene.bounds().extent()))
                       : l.position;
      }
      for (int f = 0; f < kCubeFaces; ++f) {
        m.colour[f] = ImageRGBA(opt.size, opt.size, glm::vec4(0.0f));
        m.distance[f] = ImageF(opt.size, opt.size, 0.0f);
      }
      out.cubes.push_back(std::move(m));
      out.objects.push_back(img.object);
      CubeDirections inc;
      for (int f = 0; f < kCubeFaces; ++f) inc[f] = Buffer2D<glm::vec3>(opt.size, opt.size, glm::vec3(0.0f));
      out.incident.push_back(std::move(inc));
      images_of.emplace_back();
    }
    images_of[map_index[key]].push_back(&img);
  }
  if (opt.filter == CausticFilter::Triangles) {
    // The maps side by side; in each the photons land in the order of its images and their
    // texels (a serial blend per map: the same sums for any thread count).
    executor.parallel_for("caustic_map.store", out.cubes.size(), 1, [&](std::size_t begin, std::size_t end) {
      std::vector<TexelShare> scratch;
      for (std::size_t k = begin; k < end; ++k) {
        MapTarget target{out.cubes[k], out.incident[k]};
        for (const PhotonImage* img : images_of[k]) store_caustic_triangles(*img, target, scratch);
        blur(out.cubes[k], out.incident[k]);
        for (int f = 0; f < kCubeFaces; ++f) finish_face(out.cubes[k], out.incident[k], f);
      }
    });
    return out;
  }
  // Splats: each image's splats found side by side, then listed per face in the order of the
  // map's images and their texels. A splat lands on its own face alone, so the faces, and
  // bands of rows within them, are stored side by side, each texel's photons blended in
  // that order (the same sums for any thread count).
  std::vector<std::pair<std::size_t, const PhotonImage*>> jobs;
  for (std::size_t k = 0; k < images_of.size(); ++k)
    for (const PhotonImage* img : images_of[k]) jobs.emplace_back(k, img);
  std::vector<std::vector<PhotonSplat>> splats(jobs.size());
  executor.parallel_for("caustic_map.splats", jobs.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) photon_splats(*jobs[j].second, out.cubes[jobs[j].first], opt, splats[j]);
  });
  std::vector<std::vector<PhotonSplat>> on_face(out.cubes.size() * kCubeFaces);
  for (std::size_t j = 0; j < jobs.size(); ++j)
    for (const PhotonSplat& sp : splats[j]) on_face[jobs[j].first * kCubeFaces + static_cast<std::size_t>(sp.c.face)].push_back(sp);
  const int band_rows = 16;
  const std::size_t bands = static_cast<std::size_t>((opt.size + band_rows - 1) / band_rows);
  executor.parallel_for("caustic_map.store", on_face.size() * bands, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t task = begin; task < end; ++task) {
      const std::size_t face_index = task / bands;
      const std::size_t k = face_index / kCubeFaces;
      const int face = static_cast<int>(face_index % kCubeFaces);
      const int row_begin = static_cast<int>(task % bands) * band_rows;
      const int row_end = std::min(opt.size, row_begin + band_rows);
      MapTarget target{out.cubes[k], out.incident[k]};
      for (const PhotonSplat& sp : on_face[face_index]) {
        const float cy = sp.c.pixel.y;
        if (cy + static_cast<float>(sp.radius) + 1.0f < static_cast<float>(row_begin) ||
            cy - static_cast<float>(sp.radius) - 1.0f >= static_cast<float>(row_end))
          continue;
        splat_rows(target, sp, row_begin, row_end);
      }
      finish_rows(out.cubes[k], out.incident[k], face, row_begin, row_end);
    }
  });
  return out;
}

namespace {

// Eight receivers' caustic light from one map's texels: the bilinear flux Φ at each lane's
// coordinate (CubeMap::colour_at), the nearest texel's mean photon direction wi and solid
// angle Ω, for the lanes in `lit`.
struct CausticTexels8 {
  Vec3Lanes<8> flux, wi;
  par::Lanes<8>::f32 solid_angle;
};

CausticTexels8 caustic_texels8(const CausticMaps& maps, std::size_t k, const CubeCoordLanes& cc,
                               const par::Lanes<8>::mask& lit) {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using i32 = L::i32;
  const CubeMap& m = maps.cubes[k];
  // Lanes not lit read texel (0, 0) of face 0: valid coordinates, results dropped.
  const CubeCoordLanes at{L::select(lit, cc.face, i32(0)), L::select(lit, cc.x, f32(0.0f)),
                          L::select(lit, cc.y, f32(0.0f))};
  CausticTexels8 out;
  f32 flux[3];
  bilinear_rgb8(RgbaFaces(m.colour), at, flux);
  out.flux = {flux[0], flux[1], flux[2]};
  i32 x, y;
  nearest_texel8(at, m.size, x, y);
  alignas(32) std::int32_t face[8], px[8], py[8];
  L::store_aligned(at.face, face), L::store_aligned(x, px), L::store_aligned(y, py);
  alignas(32) float wi[3][8];
  for (int j = 0; j < 8; ++j) {
    const glm::vec3& w = maps.incident[k][face[j]].at(px[j], py[j]);
    wi[0][j] = w.x, wi[1][j] = w.y, wi[2][j] = w.z;
  }
  out.wi = {L::load_aligned(wi[0]), L::load_aligned(wi[1]), L::load_aligned(wi[2])};
  // cube_texel_solid_angle(x, y, size).
  const float size = static_cast<float>(m.size);
  const f32 su = 2.0f * (L::to_float(x) + 0.5f) / size - 1.0f, sv = 2.0f * (L::to_float(y) + 0.5f) / size - 1.0f;
  const f32 q = 1.0f + su * su + sv * sv;
  out.solid_angle = (2.0f / size) * (2.0f / size) / (q * L::sqrt(q));
  return out;
}

}  // namespace

ImageRGBA gather_caustics(par::Executor& ex, const GBuffer& g, const CausticMaps& maps, const ImageRGBA& direct,
                          float tolerance) {
  if (direct.width != g.width || direct.height != g.height)
    throw InputError("caustic_gather", "direct light and G-buffer differ in size");
  ImageRGBA out = direct;
  const std::size_t n = static_cast<std::size_t>(g.width) * g.height;
  using L = par::Lanes<8>;
  using f32 = L::f32;
  using V = Vec3Lanes<8>;
  ex.parallel_for("caustic_gather", n, 1024, [&](std::size_t b, std::size_t e) {
    // The chunk's receivers (covered, not refractors), eight at a time in lanes, each lane
    // with the scalar operations in their order: map by map the distance tests, then the
    // lit receivers' texels shaded; each receiver's sum in map order.
    std::vector<std::uint32_t> at;
    for (std::size_t i = b; i < e; ++i)
      if (g.covered(i) && !g.surface[i].is_refractor()) at.push_back(static_cast<std::uint32_t>(i));
    for (std::size_t first = 0; first < at.size(); first += 8) {
      const int count = static_cast<int>(std::min<std::size_t>(8, at.size() - first));
      glm::vec3 p[8], nr[8], view_dir[8];
      const SurfaceParams* surface[8];
      for (int j = 0; j < count; ++j) {
        const std::size_t i = at[first + j];
        p[j] = g.position.pixels[i], nr[j] = g.normal.pixels[i], view_dir[j] = g.view_direction(i);
        surface[j] = &g.surface[i];
      }
      const V pv = V::load(p, count), nv = V::load(nr, count), vv = V::load(view_dir, count);
      // The receivers' BRDF terms at their viewer (brdf_at_view), made when a map lights one.
      std::optional<BrdfAtViewLanes<8>> view;
      L::mask mirror(false);
      V sum(f32(0.0f), f32(0.0f), f32(0.0f));
      for (std::size_t k = 0; k < maps.cubes.size(); ++k) {
        const CubeMap& m = maps.cubes[k];
        const float texel = 2.0f / static_cast<float>(m.size);
        alignas(32) std::int32_t mine[8] = {};
        for (int j = 0; j < count; ++j) mine[j] = g.object.pixels[at[first + j]] == maps.objects[k];  // a generator is not its own receiver
        const f32 d[3] = {pv.x - f32(m.centre.x), pv.y - f32(m.centre.y), pv.z - f32(m.centre.z)};
        const f32 dist = L::sqrt((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]);
        const L::mask tested = L::first_n(count) && (L::load_aligned(mine) == 0) && (dist > 0.0f);
        if (L::none(tested)) continue;
        const CubeCoordLanes cc = cube_coord8(d, m.size);
        alignas(32) float stored_at[8];
        for (int j = 0; j < 8; ++j) {
          const CubeCoord c{cc.face[j], {cc.x[j], cc.y[j]}};
          stored_at[j] = tested[j] ? m.distance_at(c) : 0.0f;
        }
        const f32 stored = L::load_aligned(stored_at);
        // The shadow-map-like test: only the receiver the photons found is lit. Across one
        // texel (angle ≈ 2/size) a receiver at angle α to the line of sight from the centre
        // changes its distance by about d (2/size) tanα, so grazing receivers are allowed
        // that much more (tanα capped at 16, beyond which no texel resolves the surface).
        // std::min/max's operand order kept, so NaNs fall as they would.
        const f32 cos_view = L::abs((nv.x * d[0] + nv.y * d[1]) + nv.z * d[2]) / dist;
        const f32 sin2 = 1.0f - cos_view * cos_view;
        const f32 sin_view = L::sqrt(L::select(f32(0.0f) < sin2, sin2, f32(0.0f)));
        const f32 ratio = sin_view / L::select(cos_view < 1e-3f, f32(1e-3f), cos_view);
        const f32 tan_view = L::select(ratio < 16.0f, ratio, f32(16.0f));
        const f32 slack = tolerance * stored + 2.0f * dist * tan_view * texel;
        const L::mask lit = tested && (L::abs(stored) < std::numeric_limits<float>::infinity()) &&
                            !(L::abs(dist - stored) > slack);
        if (L::none(lit)) continue;
        // The texel's flux lands on the receiver area Ω d² / |cosα| it subtends (α between
        // the normal and the line from the centre): irradiance Φ |cosα| / (Ω d²), arriving
        // from the texel's mean photon direction wi, none when that is below the surface.
        // shade_light returns f (N·L) E, so it is given E / (N·wi).
        const CausticTexels8 t = caustic_texels8(maps, k, cc, lit);
        const f32 cos_in = dot(nv, t.wi);
        const L::mask received = lit && !(cos_in <= 1e-4f);
        if (L::none(received)) continue;
        const V irradiance = t.flux * (cos_view / (t.solid_angle * dist * dist * cos_in));
        if (!view) view = brdf_at_view_lanes(punctual_brdf_params_lanes<8>(surface, count, mirror), nv, vv);
        sum = select(received, sum + shade_light_lanes(*view, mirror, nv, vv, t.wi, irradiance), sum);
      }
      glm::vec3 light[8];
      sum.store(light, count);
      for (int j = 0; j < count; ++j) out.pixels[at[first + j]] += glm::vec4(light[j], 0.0f);
    }
  });
  return out;
}

CausticPhotons CausticPhotonsPass::operator()(par::NodeContext& c, const ReflectorMaps& maps,
                                              const RefractorImpostors* impostors) const {
  CausticPhotons p = trace_photon_images(c.executor(), *scene, maps, impostors, options);
  c.count("photons", static_cast<double>(p.photons));
  c.count("stored", static_cast<double>(p.stored));
  c.count("total_internal", static_cast<double>(p.total_internal));
  c.count("no_receiver", static_cast<double>(p.no_receiver));
  c.count("internal_reflections", static_cast<double>(p.internal_reflections));
  c.count("generator_hops", static_cast<double>(p.generator_hops));
  c.count("chain_limited", static_cast<double>(p.chain_limited));
  return p;
}

CausticMaps CausticMapPass::operator()(par::NodeContext& c, const CausticPhotons& photons) const {
  CausticMaps m = build_caustic_maps(c.executor(), *scene, photons, options);
  c.count("maps", static_cast<double>(m.cubes.size()));
  return m;
}

ReflectorMaps shade_caustic_reflector_maps(par::Executor& executor, const Scene& scene,
                                           const std::vector<ShadowMap>& shadows, const EnvironmentMap& env,
                                           const ReflectorMaps& distances, const DistanceSearches& searches,
                                           const std::vector<CubeTileMask>* refraction_reads,
                                           const CausticMaps& caustics, float tolerance) {
  std::vector<CubeTileMask> tiles = searches.tiles;
  if (refraction_reads) merge_reads(tiles, *refraction_reads);
  else
    for (std::size_t m = 0; m < tiles.size() && m < distances.refracts.size(); ++m)
      if (distances.refracts[m]) tiles[m].mark_all();
  return shade_reflector_maps(executor, scene, shadows, env, distances, std::move(tiles),
                              [&](const GBuffer& face, const ImageRGBA& direct) {
                                return gather_caustics(executor, face, caustics, direct, tolerance);
                              });
}

ReflectorMaps CausticReflectorColourPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                     const EnvironmentMap& environment, const ReflectorMaps& distances,
                                                     const DistanceSearches& searches,
                                                     const std::vector<CubeTileMask>& refraction_reads,
                                                     const CausticMaps& caustics) const {
  ReflectorMaps maps = shade_caustic_reflector_maps(c.executor(), *scene, shadows, environment, distances, searches,
                                                    &refraction_reads, caustics, tolerance);
  count_maps(c, maps);
  return maps;
}

ImageRGBA CausticGatherPass::operator()(par::NodeContext& c, const GBuffer& gbuffer, const CausticMaps& maps,
                                        const ImageRGBA& direct) const {
  return gather_caustics(c.executor(), gbuffer, maps, direct, tolerance);
}

}  // namespace speculum::raster
