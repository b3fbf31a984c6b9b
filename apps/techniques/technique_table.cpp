// The technique table: see technique_table.h.
#include "apps/techniques/technique_table.h"

#include <cmath>
#include <sstream>

#include "apps/techniques/recipes.h"
#include "core/error.h"

namespace speculum::pipeline {

namespace {

// The distance-map search (SURVEY §4.1), shared by the techniques that search distance maps.
std::vector<TechniqueParam> search_params() {
  return {{"parallax", 1, 0, 1, true, "1: parallax correction (eq.4) when no bracket is found"},
          {"linear", 1, 0, 1, true, "1: linear search along the ray (§4.1.2)"},
          {"secant", 1, 0, 1, true, "1: secant refinement of the bracket (eq.5)"},
          {"parallax_steps", 1, 1, 64, true, "parallax iterations"},
          {"linear_steps", 16, 1, 1024, true, "linear search steps"},
          {"secant_steps", 4, 0, 64, true, "secant iterations"}};
}

std::vector<TechniqueParam> concat(std::vector<TechniqueParam> a, const std::vector<TechniqueParam>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Whole numbers in full (2^30 is 1073741824, not 1.07374e+09), others to 6 digits.
std::string number(double v) {
  std::ostringstream s;
  if (v == std::floor(v) && std::fabs(v) < 1e15) s << static_cast<long long>(v);
  else s << v;
  return s.str();
}

}  // namespace

const std::vector<Technique>& techniques() {
  static const std::vector<Technique> table = {
      {"envmap",
       "environment mapping (SURVEY §3.1): reflect/refract into the prefiltered environment "
       "cube, Schlick Fresnel; no parallax",
       add_envmap_passes,
       {}},
      {"reference",
       "reference tracer: BVH ray tracing, Whitted mirrors/refraction, GGX-lobe glossy "
       "sampling (--spp path samples, --bounces specular depth, default 8); the ground truth",
       add_reference_passes,
       {}},
      {"specular-reference",
       "reference for the specular term alone: the feed-forward G-buffer and direct light, "
       "reflected/refracted rays traced exactly through the BVH to --bounces, glossy lobes "
       "sampled to convergence",
       add_specular_reference_passes,
       {{"glossy_samples", 256, 1, 65536, true, "GGX visible-normal samples per glossy pixel"}}},
      {"distance-map",
       "distance maps (SURVEY §4.1-4.2): per-reflector colour+distance cube, searched per sample",
       add_distance_map_passes, search_params()},
      {"multi-reflection",
       "inter-object reflections (SURVEY §4.3): reflector distance maps rebuilt in rounds, one "
       "bounce each",
       add_multi_reflection_passes,
       concat({{"rounds", 3, 1, 16, true, "rounds of map re-rendering (bounces)"},
               {"lagged", 0, 0, 1, true, "1: one round per frame from the previous frame's maps"}},
              search_params())},
      {"layered-distance-map",
       "layered distance maps (SURVEY §4.5): the scene depth-peeled into cube layers, recursive "
       "linear+secant tracer",
       add_layered_distance_map_passes,
       {{"layers", 3, 1, 8, true, "depth-peeled layers"},
        {"layer_size", 128, 8, 1024, true, "cube face side of the layers"},
        {"linear_steps", 16, 2, 1024, true, "linear search steps per layer"},
        {"secant_steps", 4, 0, 64, true, "secant iterations"},
        {"bounces", 2, 1, 16, true, "specular hits followed (--bounces raises it)"}}},
      {"planar-mirror",
       "planar mirrors by geometry transformation (SURVEY §5): the camera reflected about each "
       "mirror plane, scene clipped at the plane, recursive; other specular surfaces as envmap",
       add_planar_mirror_passes,
       {{"depth", 3, 0, 16, true, "mirror bounces rendered by reflected cameras"}}},
      {"refraction",
       "refraction (SURVEY §4.4): exit refracted or totally internally reflected, looked up in "
       "the refractor's colour+distance cube",
       add_refraction_passes,
       {{"method", 1, 0, 2, true, "0 single interface, 1 two-face, 2 distance impostors"},
        {"linear_steps", 16, 0, 1024, true, "linear search steps (both searches; < 2: off)"},
        {"secant_steps", 4, 0, 64, true, "secant iterations"},
        {"impostor_size", 128, 4, 4096, true, "cube face side of the distance impostors (method 2)"}}},
      {"yu-lod",
       "YU glossy reflections: --spp N Phong-sampled rays per glossy pixel through a threaded "
       "BVH with adaptive LOD (eq.7, --alpha A; 0: LOD off), pre-filtered hit radiance (eq.8-9)",
       add_yu_lod_passes,
       {{"env_samples", 8, 0, 1024, true, "sky rays per triangle in the radiance bake"}}},
      {"ray-hierarchy",
       "ROGER ch.3 ray hierarchy: one reflected/refracted ray per specular pixel through a "
       "screen-space cone-sphere quad-tree over stream compaction, exact closest hits; --bounces B",
       add_ray_hierarchy_passes,
       {{"pair_capacity", 2048.0 * 2048.0, 1, 1 << 30, true, "pair buffer capacity (pairs)"},
        {"block", 64, 1, 65536, true, "block size s of the hierarchical compaction (ROGER §4.3.2)"}}},
  };
  return table;
}

const Technique& find_technique(const std::string& name) {
  std::string known;
  for (const Technique& t : techniques()) {
    if (t.name == name) return t;
    known += (known.empty() ? "" : ", ") + t.name;
  }
  throw InputError("--technique", "unknown technique '" + name + "' (known: " + known + ")");
}

void check_technique_params(const Technique& technique, const std::map<std::string, double>& params) {
  for (const auto& [name, value] : params) {
    const TechniqueParam* spec = nullptr;
    for (const TechniqueParam& p : technique.params)
      if (p.name == name) spec = &p;
    if (!spec) {
      std::string list;
      for (const TechniqueParam& p : technique.params) list += (list.empty() ? "" : ", ") + p.name;
      throw InputError("--param " + name,
                       "unknown parameter '" + name + "' for technique '" + technique.name + "' (" +
                           (list.empty() ? std::string("it takes no parameters") : "known: " + list) +
                           ")");
    }
    if (!(value >= spec->min && value <= spec->max) || (spec->integer && value != std::floor(value)))
      throw InputError("--param " + name,
                       number(value) + " is outside the valid range of '" + name + "' for technique '" +
                           technique.name + "': " + (spec->integer ? "whole numbers " : "") + "[" +
                           number(spec->min) + ", " + number(spec->max) + "]");
  }
}

FrameSettings Technique::with_defaults(FrameSettings settings) const {
  check_technique_params(*this, settings.params);
  for (const TechniqueParam& p : params) settings.params.emplace(p.name, p.fallback);
  return settings;
}

std::string Technique::describe_params(const std::string& indent) const {
  std::string out;
  for (const TechniqueParam& p : params)
    out += indent + p.name + "=" + number(p.fallback) + "  [" + number(p.min) + ", " + number(p.max) +
           "]  " + p.doc + "\n";
  return out;
}

}  // namespace speculum::pipeline
