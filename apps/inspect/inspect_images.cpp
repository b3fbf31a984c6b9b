// Drawing captured node outputs for `inspect`: see inspect_images.h.
#include "apps/inspect/inspect_images.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "apps/inspect/inspect_trace_images.h"
#include "apps/techniques/frame_settings.h"
#include "core/fallback_mask.h"
#include "core/shading.h"
#include "raster/composite.h"
#include "raster/cube_map.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/vertex_projection.h"
#include "raster/shadow_map.h"
#include "raster/soff.h"
#include "raster/visibility.h"

namespace speculum::inspect {

namespace draw {

constexpr std::size_t kMaxListed = 8;  // cube maps / lights drawn per output

std::string dims(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// A picture from sRGB colours (what the PNG bytes should show).
glm::vec4 from_srgb(glm::vec3 c) {
  return {srgb_to_linear(std::clamp(c.x, 0.0f, 1.0f)), srgb_to_linear(std::clamp(c.y, 0.0f, 1.0f)),
          srgb_to_linear(std::clamp(c.z, 0.0f, 1.0f)), 1.0f};
}

// Samples outside `mask` (when given) are background: drawn black, left out of ranges.
using Mask = const IdBuffer*;
bool masked_out(Mask mask, std::size_t i) { return mask && mask->pixels[i] == kNoId; }

const glm::vec3 kNoValue{0.05f, 0.05f, 0.25f};  // ±inf / NaN in ramps: dark blue

struct Range {
  float lo = 0, hi = 0;
  bool any = false;
};
Range finite_range(const ImageF& img, Mask mask) {
  Range r{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest(), false};
  for (std::size_t i = 0; i < img.size(); ++i) {
    const float v = img.pixels[i];
    if (!std::isfinite(v) || masked_out(mask, i)) continue;
    r.lo = std::min(r.lo, v), r.hi = std::max(r.hi, v), r.any = true;
  }
  if (!r.any) r.lo = r.hi = 0;
  return r;
}

// Grey ramp over [lo, hi] (shared by several images so cube faces agree).
ImageRGBA ramp(const ImageF& img, Range r, Mask mask) {
  ImageRGBA out(img.width, img.height, glm::vec4(0, 0, 0, 1));
  const float span = r.hi > r.lo ? r.hi - r.lo : 1.0f;
  for (std::size_t i = 0; i < img.size(); ++i) {
    const float v = img.pixels[i];
    if (masked_out(mask, i)) continue;
    out.pixels[i] = std::isfinite(v) ? from_srgb(glm::vec3((v - r.lo) / span)) : from_srgb(kNoValue);
  }
  return out;
}

std::string ramp_encoding(Range r) {
  return r.any ? "grey ramp " + fmt(r.lo) + " (black) .. " + fmt(r.hi) + " (white); dark blue: no value"
               : "no finite values";
}

View scalar_view(std::string label, const ImageF& img, Mask mask) {
  const Range r = finite_range(img, mask);
  return {std::move(label), ramp_encoding(r), ramp(img, r, mask), {}, img};
}

ImageF ids_as_float(const IdBuffer& ids) {
  ImageF f(ids.width, ids.height);
  for (std::size_t i = 0; i < ids.size(); ++i)
    f.pixels[i] = ids.pixels[i] == kNoId ? -1.0f : static_cast<float>(ids.pixels[i]);
  return f;
}

View id_view(std::string label, const IdBuffer& ids) {
  ImageRGBA pic(ids.width, ids.height);
  for (std::size_t i = 0; i < ids.size(); ++i) pic.pixels[i] = from_srgb(id_colour(ids.pixels[i]));
  return {std::move(label), "hash colour per id; black: none (EXR: id, -1 for none)", std::move(pic),
          {}, ids_as_float(ids)};
}

View count_view(std::string label, const IdBuffer& counts) {
  View v = scalar_view(std::move(label), ids_as_float(counts));
  v.encoding = "count, " + v.encoding;
  return v;
}

template <class Vec>
ImageRGBA raw_rgba(const Buffer2D<Vec>& b) {
  ImageRGBA out(b.width, b.height);
  for (std::size_t i = 0; i < b.size(); ++i) {
    glm::vec4 c(0, 0, 0, 1);
    for (int k = 0; k < Vec::length(); ++k) c[k] = b.pixels[i][k];
    out.pixels[i] = c;
  }
  return out;
}

View normal_view(std::string label, const Buffer2D<glm::vec3>& n, Mask mask) {
  ImageRGBA pic(n.width, n.height, glm::vec4(0, 0, 0, 1));
  for (std::size_t i = 0; i < n.size(); ++i)
    if (!masked_out(mask, i)) pic.pixels[i] = from_srgb(n.pixels[i] * 0.5f + 0.5f);
  return {std::move(label), "n*0.5+0.5 as RGB; black: background", std::move(pic), raw_rgba(n), {}};
}

// Each channel over the range of its finite values (a bounding box for positions); ranges
// that fit in [0, 1] are shown unscaled (barycentrics, uv).
template <class Vec>
View channels_view(std::string label, const Buffer2D<Vec>& b, Mask mask) {
  constexpr int kN = Vec::length();
  Vec lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (masked_out(mask, i)) continue;
    for (int k = 0; k < kN; ++k)
      if (std::isfinite(b.pixels[i][k]))
        lo[k] = std::min(lo[k], b.pixels[i][k]), hi[k] = std::max(hi[k], b.pixels[i][k]);
  }
  std::string encoding = "channels as RGB over";
  for (int k = 0; k < kN; ++k) {
    if (lo[k] > hi[k]) lo[k] = 0, hi[k] = 1;
    if (lo[k] >= 0 && hi[k] <= 1) lo[k] = 0, hi[k] = 1;
    encoding += " [" + fmt(lo[k]) + ", " + fmt(hi[k]) + "]";
  }
  ImageRGBA pic(b.width, b.height, glm::vec4(0, 0, 0, 1));
  for (std::size_t i = 0; i < b.size(); ++i) {
    if (masked_out(mask, i)) continue;
    glm::vec3 c(0.0f);
    for (int k = 0; k < kN; ++k)
      c[k] = hi[k] > lo[k] ? (b.pixels[i][k] - lo[k]) / (hi[k] - lo[k]) : 0.0f;
    pic.pixels[i] = from_srgb(c);
  }
  return {std::move(label), encoding, std::move(pic), raw_rgba(b), {}};
}

// Linear radiance through the display tone curve (raster/composite.h, exposure 1).
View radiance_view(std::string label, const ImageRGBA& img, par::Executor& executor) {
  return {std::move(label), "radiance, ACES tone-mapped (exposure 1)",
          raster::tonemap(executor, img, 1.0f), img, {}};
}

std::array<ImageRGBA, 6> tonemapped_faces(const std::array<ImageRGBA, 6>& faces,
                                          par::Executor& executor) {
  std::array<ImageRGBA, 6> out;
  for (int f = 0; f < 6; ++f) out[f] = raster::tonemap(executor, faces[f], 1.0f);
  return out;
}

// The raw cross for the EXR (faces untouched) and the tone-mapped cross for the PNG.
View colour_cross_view(std::string label, const std::array<ImageRGBA, 6>& faces,
                       par::Executor& executor) {
  return {std::move(label), "cube faces as a cross, radiance ACES tone-mapped",
          cube_cross(tonemapped_faces(faces, executor)), cube_cross(faces), {}};
}

View distance_cross_view(std::string label, const std::array<ImageF, 6>& faces) {
  Range r{std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest(), false};
  for (const auto& f : faces) {
    const Range fr = finite_range(f, nullptr);
    if (fr.any) r.lo = std::min(r.lo, fr.lo), r.hi = std::max(r.hi, fr.hi), r.any = true;
  }
  if (!r.any) r.lo = r.hi = 0;
  std::array<ImageRGBA, 6> pics, raws;
  for (int f = 0; f < 6; ++f) {
    pics[f] = ramp(faces[f], r, nullptr);
    raws[f] = ImageRGBA(faces[f].width, faces[f].height);
    for (std::size_t i = 0; i < faces[f].size(); ++i)
      raws[f].pixels[i] = glm::vec4(glm::vec3(faces[f].pixels[i]), 1.0f);
  }
  return {std::move(label), "cube faces as a cross, distance " + ramp_encoding(r), cube_cross(pics),
          cube_cross(raws), {}};
}

bool has_faces(const std::array<ImageRGBA, 6>& faces) {
  return std::all_of(faces.begin(), faces.end(), [](const ImageRGBA& f) { return !f.empty(); }) &&
         std::all_of(faces.begin(), faces.end(),
                     [&](const ImageRGBA& f) { return f.width == faces[0].width && f.height == faces[0].height; });
}
bool has_faces(const std::array<ImageF, 6>& faces) {
  return std::all_of(faces.begin(), faces.end(), [](const ImageF& f) { return !f.empty(); }) &&
         std::all_of(faces.begin(), faces.end(),
                     [&](const ImageF& f) { return f.width == faces[0].width && f.height == faces[0].height; });
}

// "; faces -Y, +Z not rendered (why)" for a cube that leaves faces out (bit f of `faces`: face
// f rendered), else "": their cells of the cross hold no rendering.
std::string unrendered_faces(unsigned faces, const char* why) {
  static const char* const names[6] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  std::string list;
  for (int f = 0; f < 6; ++f) {
    if (faces >> f & 1u) continue;
    if (!list.empty()) list += ", ";
    list += names[f];
  }
  if (list.empty()) return list;
  std::string note = "; faces ";
  note += list;
  note += " not rendered (";
  note += why;
  note += ')';
  return note;
}

// The cube's colour and distance crosses; `note` is added to each caption.
void draw_cube(Drawing& d, const std::string& prefix, const raster::CubeMap& cube, par::Executor& executor,
               const std::string& note = "") {
  if (has_faces(cube.colour)) {
    d.views.push_back(colour_cross_view(prefix + "colour", cube.colour, executor));
    d.views.back().encoding += note;
  }
  if (has_faces(cube.distance)) {
    d.views.push_back(distance_cross_view(prefix + "distance", cube.distance));
    d.views.back().encoding += note;
  }
}

void draw_gbuffer(Drawing& d, const raster::GBuffer& g) {
  const Mask mask = &g.object;
  d.views.push_back(id_view("object", g.object));
  d.views.push_back(channels_view("position", g.position, mask));
  d.views.push_back(normal_view("normal", g.normal, mask));
  d.views.push_back(channels_view("uv", g.uv, mask));
  Buffer2D<glm::vec3> base(g.width, g.height);
  ImageF roughness(g.width, g.height);
  for (std::size_t i = 0; i < g.surface.size(); ++i)
    base.pixels[i] = g.surface[i].base_color, roughness.pixels[i] = g.surface[i].roughness;
  d.views.push_back(channels_view("base_color", base, mask));
  d.views.push_back(scalar_view("roughness", roughness, mask));
  d.views.push_back(scalar_view("specular_level", raster::specular_level_image(g), mask));
  d.views.push_back(scalar_view("glossiness", raster::glossiness_image(g), mask));
  d.views.push_back(id_view("reflector", g.reflector));
}

void draw_visibility(Drawing& d, const raster::VisibilityBuffer& v) {
  d.views.push_back(id_view("triangle", v.triangle));
  d.views.push_back(id_view("object", v.object));
  d.views.push_back(scalar_view("depth", v.depth));
  d.views.push_back(channels_view("bary", v.bary, &v.triangle));
  if (!v.coverage.empty()) d.views.push_back(count_view("coverage", v.coverage));
}

bool contains(const std::string& s, const char* part) { return s.find(part) != std::string::npos; }

}  // namespace draw

using namespace draw;

glm::vec3 id_colour(std::uint32_t id) {
  if (id == kNoId) return glm::vec3(0.0f);
  std::uint32_t h = id * 0x9e3779b9u;  // finalizer of MurmurHash3
  h ^= h >> 16, h *= 0x85ebca6bu, h ^= h >> 13, h *= 0xc2b2ae35u, h ^= h >> 16;
  // Channels in [0.25, 1] so no id is (nearly) black like the background.
  return glm::vec3(0.25f) + 0.75f * glm::vec3(float(h & 0xff), float((h >> 8) & 0xff),
                                              float((h >> 16) & 0xff)) / 255.0f;
}

ImageRGBA cube_cross(const std::array<ImageRGBA, 6>& faces) {
  const int s = faces[0].width, t = faces[0].height;
  ImageRGBA out(4 * s, 3 * t, glm::vec4(0, 0, 0, 1));
  // Cells (column, row) of +X, −X, +Y, −Y, +Z, −Z: the row −X +Z +X −Z with +Y/−Y at +Z.
  constexpr int kCell[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
  for (int f = 0; f < 6; ++f) {
    if (faces[f].width != s || faces[f].height != t) continue;
    for (int y = 0; y < t; ++y)
      for (int x = 0; x < s; ++x) out.at(kCell[f][0] * s + x, kCell[f][1] * t + y) = faces[f].at(x, y);
  }
  return out;
}

namespace {

// A fallback mask: each reason in its own colour, the rest black; the size line counts them.
// The EXR keeps the Fallback codes.
void draw_fallbacks(Drawing& d, const FallbackMask& m) {
  struct Reason {
    Fallback why;
    const char* name;
    const char* colour_name;
    glm::vec3 colour;  // sRGB
  };
  constexpr Reason kReasons[] = {{Fallback::search_missed, "search missed", "red", {1.0f, 0.2f, 0.2f}},
                                 {Fallback::depth_exhausted, "depth exhausted", "blue", {0.3f, 0.5f, 1.0f}},
                                 {Fallback::refractor_environment, "refractor environment", "green", {0.2f, 0.9f, 0.3f}}};
  ImageRGBA picture(m.reason.width, m.reason.height, glm::vec4(0, 0, 0, 1));
  ImageF raw(m.reason.width, m.reason.height);
  std::string legend;
  for (const Reason& r : kReasons)
    legend += std::string(legend.empty() ? "" : ", ") + r.name + " " + std::to_string(m.count(r.why)) + " (" +
              r.colour_name + ")";
  for (std::size_t i = 0; i < m.reason.size(); ++i) {
    raw.pixels[i] = m.reason.pixels[i];
    for (const Reason& r : kReasons)
      if (m.reason.pixels[i] == static_cast<std::uint8_t>(r.why)) picture.pixels[i] = from_srgb(r.colour);
  }
  d.size = dims(m.reason.width, m.reason.height) + "; " + legend;
  d.views.push_back({"", "fallback per pixel: " + legend + "; black: none", picture, {}, raw});
}

}  // namespace

Drawing draw_output(const par::CapturedOutput& o, par::Executor& executor) {
  Drawing d;
  d.drawable = true;
  if (const auto* fallbacks = o.as<FallbackMask>()) {
    if (fallbacks->empty()) d.drawable = false;
    else draw_fallbacks(d, *fallbacks);
  } else if (const auto* img = o.as<ImageRGBA>()) {
    d.size = dims(img->width, img->height);
    if (o.resource == pipeline::kDisplay)
      d.views.push_back({"", "display colour (already tone-mapped)", *img, *img, {}});
    else
      d.views.push_back(radiance_view("", *img, executor));
  } else if (const auto* f = o.as<ImageF>()) {
    d.size = dims(f->width, f->height);
    d.views.push_back(scalar_view("", *f));
  } else if (const auto* ids = o.as<IdBuffer>()) {
    d.size = dims(ids->width, ids->height);
    d.views.push_back(contains(o.resource, "count") ? count_view("", *ids) : id_view("", *ids));
  } else if (const auto* v3 = o.as<Buffer2D<glm::vec3>>()) {
    d.size = dims(v3->width, v3->height);
    d.views.push_back(contains(o.resource, "normal") ? normal_view("", *v3, nullptr)
                                                     : channels_view("", *v3, nullptr));
  } else if (const auto* v2 = o.as<Buffer2D<glm::vec2>>()) {
    d.size = dims(v2->width, v2->height);
    d.views.push_back(channels_view("", *v2, nullptr));
  } else if (const auto* vis = o.as<raster::VisibilityBuffer>()) {
    d.size = dims(vis->width, vis->height);
    draw_visibility(d, *vis);
  } else if (const auto* g = o.as<raster::GBuffer>()) {
    d.size = dims(g->width, g->height);
    draw_gbuffer(d, *g);
  } else if (const auto* env = o.as<raster::EnvironmentMap>()) {
    d.size = "6 faces " + dims(env->size, env->size) + ", " + std::to_string(env->levels.size()) + " levels";
    if (!env->levels.empty() && has_faces(env->levels.front()))
      d.views.push_back(colour_cross_view("level0", env->levels.front(), executor));
    if (env->levels.size() > 1 && has_faces(env->levels.back()))
      d.views.push_back(colour_cross_view("level" + std::to_string(env->levels.size() - 1),
                                          env->levels.back(), executor));
  } else if (const auto* cube = o.as<raster::CubeMap>()) {
    d.size = "6 faces " + dims(cube->size, cube->size);
    draw_cube(d, "", *cube, executor);
  } else if (const auto* shadows = o.as<std::vector<raster::ShadowMap>>()) {
    d.size = std::to_string(shadows->size()) + " lights";
    for (std::size_t l = 0; l < shadows->size() && l < kMaxListed; ++l) {
      const auto& s = (*shadows)[l];
      const std::string name = "light" + std::to_string(l);
      if (has_faces(s.cube.distance)) {
        d.views.push_back(distance_cross_view(name, s.cube.distance));
        d.views.back().encoding += unrendered_faces(s.faces, "outside the spot light's cone");
      } else if (!s.distance.empty()) {
        d.views.push_back(scalar_view(name, s.distance));
      }
    }
  } else if (const auto* clusters = o.as<raster::SoffClusters>()) {
    // SOFF Fig. 4: every cluster in its own false colour, diffuse samples black.
    d.size = dims(clusters->width, clusters->height) + ", " + std::to_string(clusters->count()) + " clusters";
    IdBuffer ids(clusters->width, clusters->height);
    ids.pixels = clusters->cluster;
    d.views.push_back(id_view("clusters", ids));
  } else if (const auto* maps = o.as<raster::ReflectorMaps>()) {
    d.size = std::to_string(maps->cubes.size()) + " cube maps";
    for (std::size_t m = 0; m < maps->cubes.size() && m < kMaxListed; ++m) {
      std::string note = m < maps->faces.size() ? unrendered_faces(maps->faces[m], "no camera sample reads them") : "";
      if (m < maps->tiles.size() && maps->tiles[m].active())
        note += "; within the rendered faces, only the tiles the camera's lookups reach";
      draw_cube(d, "map" + std::to_string(m) + ".", maps->cubes[m], executor, note);
    }
  } else if (const auto* params = o.as<raster::ReflectorParams>()) {
    // Vertex projection's parameterization: r(u) of each reflector as a cube cross.
    d.size = std::to_string(params->reflectors.size()) + " reflectors";
    for (std::size_t m = 0; m < params->reflectors.size() && m < kMaxListed; ++m) {
      std::array<ImageF, 6> radius;  // the texels' r
      for (std::size_t f = 0; f < radius.size(); ++f) {
        const Buffer2D<glm::vec4>& texels = params->reflectors[m].texels[f];
        radius[f] = ImageF(texels.width, texels.height);
        for (std::size_t i = 0; i < texels.size(); ++i) radius[f].pixels[i] = texels.pixels[i].w;
      }
      if (has_faces(radius)) d.views.push_back(distance_cross_view("radius" + std::to_string(m), radius));
    }
  } else if (const auto* layer = o.as<raster::ReflectedLayer>()) {
    d.size = dims(layer->width, layer->height);
    d.views.push_back(scalar_view("iterations", layer->iterations));
    d.views.push_back(id_view("triangle", layer->triangle));
  } else if (!draw_trace_output(o, executor, d)) {
    d.drawable = false;
  }
  if (d.views.empty()) d.drawable = false;  // e.g. no reflector of that kind: nothing to show
  return d;
}

}  // namespace speculum::inspect
