// Drawing the trace-side node outputs for `inspect`: see inspect_trace_images.h. Rays map to
// pixels as their kernels lay them out: SecondaryRays slot i = pixel i (trace/secondary_rays.h),
// GlossyRays slots [k N, k N + N) = pixel pixel[k] (trace/glossy_rays.h).
#include "apps/inspect/inspect_trace_images.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>

#include <glm/geometric.hpp>

#include "raster/layered_distance_map.h"
#include "trace/cone_tracing.h"
#include "trace/glossy_rays.h"
#include "trace/lod_trace.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"

namespace speculum::inspect {

namespace {

using namespace draw;

constexpr std::size_t kMaxListed = 8;  // lights / layers drawn per output
constexpr int kHierarchyLevelsShown = 3;  // the finest inner levels (leaves have r = α = 0)

// The pixel grid of a ray stream: slot s belongs to pixel pixel[s / per_pixel] (identity
// when `pixel` is empty).
struct RayGrid {
  int width = 0, height = 0, per_pixel = 1;
  std::vector<std::uint32_t> pixel;
  std::size_t pixel_of(std::size_t slot) const {
    const std::size_t k = slot / std::size_t(per_pixel);
    return pixel.empty() ? k : pixel[k];
  }
};

std::mutex grids_mutex;
std::map<std::size_t, std::shared_ptr<const RayGrid>> grids;  // by ray count

void remember(std::size_t count, RayGrid grid) {
  std::lock_guard lock(grids_mutex);
  grids[count] = std::make_shared<const RayGrid>(std::move(grid));
}
std::shared_ptr<const RayGrid> grid_for(std::size_t count) {
  std::lock_guard lock(grids_mutex);
  const auto it = grids.find(count);
  return it == grids.end() ? nullptr : it->second;
}

// A mask in the IdBuffer form the ramps take: 0 = shown, kNoId = background.
IdBuffer mask_of(int w, int h, const std::vector<std::uint8_t>& on) {
  IdBuffer m(w, h, kNoId);
  for (std::size_t i = 0; i < m.size() && i < on.size(); ++i)
    if (on[i]) m.pixels[i] = 0;
  return m;
}

ImageF as_image(int w, int h, const std::vector<std::uint8_t>& on) {
  ImageF f(w, h, 0.0f);
  for (std::size_t i = 0; i < f.size() && i < on.size(); ++i) f.pixels[i] = on[i] ? 1.0f : 0.0f;
  return f;
}

View mask_view(std::string label, ImageF values, const char* meaning) {
  View v = scalar_view(std::move(label), values);
  v.encoding = std::string(meaning) + "; " + v.encoding;
  return v;
}

// Unit directions as d*0.5+0.5; pixels outside `mask` black. The EXR keeps the raw vector.
View direction_view(std::string label, const Buffer2D<glm::vec3>& dirs, const IdBuffer& mask) {
  ImageRGBA pic(dirs.width, dirs.height, glm::vec4(0, 0, 0, 1));
  ImageRGBA raw(dirs.width, dirs.height, glm::vec4(0, 0, 0, 1));
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    if (mask.pixels[i] == kNoId) continue;
    const glm::vec3 d = dirs.pixels[i];
    raw.pixels[i] = glm::vec4(d, 1.0f);
    const float len = glm::length(d);
    if (len > 0.0f && std::isfinite(len)) pic.pixels[i] = from_srgb(d / len * 0.5f + 0.5f);
  }
  return {std::move(label), "unit direction d*0.5+0.5 as RGB; black: no ray", std::move(pic), std::move(raw),
          {}};
}

void draw_secondary_rays(Drawing& d, const trace::SecondaryRays& r) {
  const int w = r.width, h = r.height;
  const std::size_t n = std::size_t(w) * std::size_t(h);
  if (r.rays.size() != n || r.active.size() != n) {
    d.drawable = false;
    return;
  }
  remember(n, RayGrid{w, h, 1, {}});
  d.size = dims(w, h) + ", " + std::to_string(r.count) + " active";
  const IdBuffer mask = mask_of(w, h, r.active);
  Buffer2D<glm::vec3> dirs(w, h);
  ImageF weight(w, h, 0.0f);
  for (std::size_t i = 0; i < n; ++i) {
    dirs.pixels[i] = {r.rays.dx[i], r.rays.dy[i], r.rays.dz[i]};
    if (i < r.weight.size()) weight.pixels[i] = (r.weight[i].x + r.weight[i].y + r.weight[i].z) / 3.0f;
  }
  d.views.push_back(direction_view("direction", dirs, mask));
  d.views.push_back(mask_view("active", as_image(w, h, r.active), "active mask, 1 (white): the pixel has a ray"));
  View wv = scalar_view("weight", weight, &mask);
  wv.encoding = "mean of the RGB weight, " + wv.encoding;
  d.views.push_back(std::move(wv));
}

void draw_hierarchy(Drawing& d, const trace::RayHierarchy& hi) {
  d.size = "side " + std::to_string(hi.side) + ", " + std::to_string(hi.levels) + " levels over " +
           dims(hi.width, hi.height);
  if (hi.nodes.size() != std::size_t(hi.levels) + 1) {
    d.drawable = false;
    return;
  }
  for (int l = hi.levels - 1; l >= 0 && l >= hi.levels - kHierarchyLevelsShown; --l) {
    const int s = 1 << l;
    const auto& nodes = hi.nodes[std::size_t(l)];
    if (nodes.size() != std::size_t(s) * std::size_t(s)) continue;
    ImageF alpha(s, s), radius(s, s);
    IdBuffer mask(s, s, kNoId);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      alpha.pixels[i] = nodes[i].alpha, radius.pixels[i] = nodes[i].r;
      if (!nodes[i].empty()) mask.pixels[i] = 0;
    }
    const std::string name = "level" + std::to_string(l);
    View a = scalar_view(name + ".alpha", alpha, &mask);
    a.encoding = "cone half-angle α (rad) per node, " + a.encoding + "; black: empty node";
    View r = scalar_view(name + ".radius", radius, &mask);
    r.encoding = "origin-sphere radius r per node, " + r.encoding + "; black: empty node";
    d.views.push_back(std::move(a));
    d.views.push_back(std::move(r));
  }
}

void draw_hits(Drawing& d, const trace::HitStream& hits) {
  const auto grid = grid_for(hits.t.size());
  if (!grid || grid->per_pixel != 1 || hits.triangle.size() != hits.t.size()) {
    d.drawable = false;
    return;
  }
  const int w = grid->width, h = grid->height;
  ImageF t(w, h, std::numeric_limits<float>::infinity());
  IdBuffer tri(w, h, kNoId);
  std::uint64_t count = 0;
  for (std::size_t s = 0; s < hits.t.size(); ++s) {
    if (hits.triangle[s] == trace::kNoHit) continue;
    const std::size_t p = grid->pixel_of(s);
    t.pixels[p] = hits.t[s], tri.pixels[p] = hits.triangle[s], ++count;
  }
  d.size = dims(w, h) + ", " + std::to_string(count) + " hits";
  View tv = scalar_view("t", t, &tri);
  tv.encoding = "hit distance t, " + tv.encoding + "; black: no hit";
  d.views.push_back(std::move(tv));
  View iv = id_view("triangle", tri);
  iv.encoding = "triangle id, " + iv.encoding;
  d.views.push_back(std::move(iv));
}

void draw_shadow_hits(Drawing& d, const std::vector<trace::HitStream>& lights) {
  d.size = std::to_string(lights.size()) + " lights";
  bool any = false;
  for (std::size_t l = 0; l < lights.size() && l < kMaxListed; ++l) {
    const auto grid = grid_for(lights[l].triangle.size());
    if (!grid || grid->per_pixel != 1) continue;
    ImageF occluded(grid->width, grid->height, 0.0f);
    for (std::size_t s = 0; s < lights[l].triangle.size(); ++s)
      if (lights[l].triangle[s] != trace::kNoHit) occluded.pixels[grid->pixel_of(s)] = 1.0f;
    d.views.push_back(mask_view("light" + std::to_string(l), std::move(occluded),
                                "occlusion, 1 (white): the shadow ray is blocked; black: lit or no ray"));
    any = true;
  }
  d.drawable = any;
}

void draw_glossy_rays(Drawing& d, const trace::GlossyRays& g) {
  const int w = g.width, h = g.height, n = g.rays_per_pixel;
  if (n <= 0 || g.rays.size() != g.pixel.size() * std::size_t(n) || g.solid_angle.size() != g.rays.size()) {
    d.drawable = false;
    return;
  }
  remember(g.rays.size(), RayGrid{w, h, n, g.pixel});
  d.size = dims(w, h) + ", " + std::to_string(g.pixel.size()) + " glossy pixels x " + std::to_string(n) + " rays";
  ImageF omega(w, h, 0.0f), active(w, h, 0.0f);
  Buffer2D<glm::vec3> mean_dir(w, h, glm::vec3(0.0f));
  IdBuffer mask(w, h, kNoId);
  for (std::size_t k = 0; k < g.pixel.size(); ++k) {
    const std::size_t p = g.pixel[k];
    if (p >= mask.size()) continue;
    mask.pixels[p] = 0;
    float sum = 0.0f;
    int on = 0;
    glm::vec3 dir(0.0f);
    for (int j = 0; j < n; ++j) {
      const std::size_t s = k * std::size_t(n) + std::size_t(j);
      if (!(g.rays.tmin[s] <= g.rays.tmax[s])) continue;  // below the horizon
      sum += g.solid_angle[s], ++on;
      dir += glm::vec3(g.rays.dx[s], g.rays.dy[s], g.rays.dz[s]);
    }
    omega.pixels[p] = on ? sum / float(on) : 0.0f;
    active.pixels[p] = float(on) / float(n);
    mean_dir.pixels[p] = dir;
  }
  View ov = scalar_view("solid_angle", omega, &mask);
  ov.encoding = "mean Ω_s (sr) of the pixel's active rays (YU eq.5), " + ov.encoding + "; black: not glossy";
  d.views.push_back(std::move(ov));
  View dv = direction_view("direction", mean_dir, mask);
  dv.encoding = "mean direction of the active rays, " + dv.encoding;
  d.views.push_back(std::move(dv));
  View av = scalar_view("active_fraction", active, &mask);
  av.encoding = "fraction of samples above the horizon, " + av.encoding;
  d.views.push_back(std::move(av));
}

void draw_lod_hits(Drawing& d, const std::vector<trace::LodHit>& hits) {
  const auto grid = grid_for(hits.size());
  if (!grid) {
    d.drawable = false;
    return;
  }
  const int w = grid->width, h = grid->height, n = grid->per_pixel;
  ImageF hit(w, h, 0.0f), proxy(w, h, 0.0f), t(w, h, std::numeric_limits<float>::infinity());
  IdBuffer mask(w, h, kNoId);
  std::vector<int> t_count(std::size_t(w) * std::size_t(h), 0);
  std::vector<float> t_sum(t_count.size(), 0.0f);
  std::uint64_t proxies = 0;
  for (std::size_t s = 0; s < hits.size(); ++s) {
    const std::size_t p = grid->pixel_of(s);
    if (p >= mask.size()) continue;
    mask.pixels[p] = 0;
    if (!hits[s].hit()) continue;
    hit.pixels[p] += 1.0f / float(n);
    if (hits[s].triangle == trace::kNoHit) proxy.pixels[p] += 1.0f / float(n), ++proxies;
    t_sum[p] += hits[s].t, ++t_count[p];
  }
  for (std::size_t p = 0; p < t_count.size(); ++p)
    if (t_count[p]) t.pixels[p] = t_sum[p] / float(t_count[p]);
  d.size = std::to_string(hits.size()) + " rays on " + dims(w, h) + ", " + std::to_string(proxies) + " proxy hits";
  View hv = mask_view("hit_fraction", std::move(hit), "fraction of the pixel's rays that hit");
  View pv = mask_view("proxy_fraction", std::move(proxy), "fraction of the pixel's rays whose closest hit is a LOD proxy");
  View tv = scalar_view("t", t, &mask);
  tv.encoding = "mean hit distance t, " + tv.encoding + "; dark blue: no hit";
  d.views.push_back(std::move(hv));
  d.views.push_back(std::move(pv));
  d.views.push_back(std::move(tv));
}

void draw_layered_map(Drawing& d, const raster::LayeredDistanceMap& m, par::Executor& executor) {
  d.size = std::to_string(m.layers.size()) + " layers, 6 faces " + dims(m.size, m.size);
  for (std::size_t k = 0; k < m.layers.size() && k < kMaxListed; ++k) {
    const std::string name = "layer" + std::to_string(k);
    if (has_faces(m.layers[k].distance)) d.views.push_back(distance_cross_view(name + ".distance", m.layers[k].distance));
    if (has_faces(m.layers[k].colour))
      d.views.push_back(colour_cross_view(name + ".colour", m.layers[k].colour, executor));
  }
  d.drawable = !d.views.empty();
}

void draw_pixel_cones(Drawing& d, const trace::PixelCones& c) {
  const int w = c.axes.width, h = c.axes.height;
  const std::size_t n = std::size_t(w) * std::size_t(h);
  if (c.angle.size() != n || c.radius.size() != n || c.axes.active.size() != n) {
    d.drawable = false;
    return;
  }
  d.size = dims(w, h) + ", " + std::to_string(c.cones) + " cones, " + std::to_string(c.axes.count - c.cones) +
           " rays";
  const IdBuffer mask = mask_of(w, h, c.axes.active);
  ImageF angle(w, h, 0.0f), radius(w, h, 0.0f);
  for (std::size_t i = 0; i < n; ++i) angle.pixels[i] = c.angle[i], radius.pixels[i] = c.radius[i];
  View a = scalar_view("angle", angle, &mask);
  a.encoding = "leaf cone half-angle (rad: reflected pixel cone + glossy angle), " + a.encoding +
               "; 0: traced as a ray";
  View r = scalar_view("radius", radius, &mask);
  r.encoding = "cone radius at its origin (world units), " + r.encoding;
  d.views.push_back(std::move(a));
  d.views.push_back(std::move(r));
}

void draw_cone_hits(Drawing& d, const trace::ConeHits& hits) {
  const int w = hits.width, h = hits.height;
  const std::size_t n = std::size_t(w) * std::size_t(h), K = std::size_t(std::max(hits.kept, 1));
  if (hits.count.size() != n || hits.coverage.size() != n * K) {
    d.drawable = false;
    return;
  }
  d.size = dims(w, h) + ", up to " + std::to_string(hits.kept) + " kept, " + std::to_string(hits.overflow) +
           " dropped";
  ImageF kept(w, h, 0.0f), coverage(w, h, 0.0f), found(w, h, 0.0f);
  for (std::size_t p = 0; p < n; ++p) {
    kept.pixels[p] = float(hits.count[p]);
    found.pixels[p] = float(hits.total[p]);
    float acc = 0.0f;  // the saturate blend's accumulated coverage
    for (std::uint32_t j = 0; j < hits.count[p]; ++j) acc += std::min(hits.coverage[p * K + j], 1.0f - acc);
    coverage.pixels[p] = acc;
  }
  View k = scalar_view("kept", kept);
  k.encoding = "hits kept per pixel (the n nearest), " + k.encoding;
  View f = scalar_view("found", found);
  f.encoding = "hits found per pixel (beyond kept: dropped), " + f.encoding;
  View c = scalar_view("coverage", coverage);
  c.encoding = "coverage the kept hits blend to (saturate; 1: the cone is covered), " + c.encoding;
  d.views.push_back(std::move(k));
  d.views.push_back(std::move(f));
  d.views.push_back(std::move(c));
}

}  // namespace

void forget_ray_grids() {
  std::lock_guard lock(grids_mutex);
  grids.clear();
}

bool draw_trace_output(const par::CapturedOutput& o, par::Executor& executor, Drawing& d) {
  d.drawable = true;
  if (const auto* rays = o.as<trace::SecondaryRays>()) {
    draw_secondary_rays(d, *rays);
  } else if (const auto* hi = o.as<trace::RayHierarchy>()) {
    draw_hierarchy(d, *hi);
  } else if (const auto* hits = o.as<trace::HitStream>()) {
    draw_hits(d, *hits);
  } else if (const auto* shadow = o.as<std::vector<trace::HitStream>>()) {
    draw_shadow_hits(d, *shadow);
  } else if (const auto* cones = o.as<trace::PixelCones>()) {
    draw_pixel_cones(d, *cones);
  } else if (const auto* cone_hits = o.as<trace::ConeHits>()) {
    draw_cone_hits(d, *cone_hits);
  } else if (const auto* glossy = o.as<trace::GlossyRays>()) {
    draw_glossy_rays(d, *glossy);
  } else if (const auto* lod = o.as<std::vector<trace::LodHit>>()) {
    draw_lod_hits(d, *lod);
  } else if (const auto* layered = o.as<raster::LayeredDistanceMap>()) {
    draw_layered_map(d, *layered, executor);
  } else {
    return false;
  }
  return true;
}

}  // namespace speculum::inspect
