// The technique table: see technique_table.h.
#include "apps/techniques/technique_table.h"

#include <algorithm>

#include "apps/techniques/distance_map.h"
#include "apps/techniques/planar_mirror.h"
#include "apps/techniques/ray_hierarchy.h"
#include "apps/techniques/refraction.h"
#include "apps/techniques/yu_lod.h"
#include "core/error.h"

namespace speculum::pipeline {

const std::vector<Technique>& techniques() {
  static const std::vector<Technique> table = {
      {"envmap",
       "environment mapping (SURVEY §3.1): reflect/refract into the prefiltered environment "
       "cube, Schlick Fresnel; no parallax",
       add_envmap_passes,
       {}},
      {"reference",
       "reference tracer: BVH ray tracing, Whitted mirrors/refraction, Phong-lobe glossy "
       "sampling (--spp path samples); the ground truth",
       add_reference_passes,
       {}},
      {"distance-map",
       "distance maps (SURVEY §4.1-4.2): per-reflector colour+distance cube, searched per "
       "sample; --param parallax|linear|secant=0/1, parallax_steps=1, linear_steps=16, "
       "secant_steps=4",
       add_distance_map_passes,
       {"parallax", "linear", "secant", "parallax_steps", "linear_steps", "secant_steps"}},
      {"multi-reflection",
       "inter-object reflections (SURVEY §4.3): reflector distance maps rebuilt in rounds, one "
       "bounce each; --param rounds=3, lagged=0/1 (one round per frame from the previous "
       "frame's maps), plus the distance-map search params",
       add_multi_reflection_passes,
       {"rounds", "lagged", "parallax", "linear", "secant", "parallax_steps", "linear_steps",
        "secant_steps"}},
      {"layered-distance-map",
       "layered distance maps (SURVEY §4.5): the scene depth-peeled into cube layers, "
       "recursive linear+secant tracer; --param layers=3, layer_size=128, linear_steps=16, "
       "secant_steps=4, bounces=2",
       add_layered_distance_map_passes,
       {"layers", "layer_size", "linear_steps", "secant_steps", "bounces"}},
      {"planar-mirror",
       "planar mirrors by geometry transformation (SURVEY §5): the camera reflected about "
       "each mirror plane, scene clipped at the plane, recursive to --param depth=3; other "
       "specular surfaces as envmap",
       add_planar_mirror_passes,
       {"depth"}},
      {"refraction",
       "refraction (SURVEY §4.4): --param method=0 single interface, 1 two-face (default), "
       "2 distance impostors; exit refracted or totally internally reflected, looked up in "
       "the refractor's colour+distance cube (linear_steps=16, secant_steps=4)",
       add_refraction_passes,
       {"method", "linear_steps", "secant_steps", "impostor_size"}},
      {"yu-lod",
       "YU glossy reflections: --spp N Phong-sampled rays per glossy pixel through a threaded "
       "BVH with adaptive LOD (eq.7, --alpha A; 0: LOD off), pre-filtered hit radiance (eq.8-9)",
       add_yu_lod_passes,
       {"env_samples"}},
      {"ray-hierarchy",
       "ROGER ch.3 ray hierarchy: one reflected/refracted ray per specular pixel through a "
       "screen-space cone-sphere quad-tree over stream compaction, exact closest hits; "
       "--bounces B; --param pair_capacity=4194304, block=64",
       add_ray_hierarchy_passes,
       {"pair_capacity", "block"}},
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

void check_technique_params(const Technique& technique,
                            const std::map<std::string, double>& params) {
  for (const auto& entry : params) {
    const std::string& name = entry.first;
    if (std::find(technique.params.begin(), technique.params.end(), name) != technique.params.end())
      continue;
    std::string list;
    for (const std::string& p : technique.params) list += (list.empty() ? "" : ", ") + p;
    throw InputError("--param " + name,
                     "unknown parameter '" + name + "' for technique '" + technique.name + "' (" +
                         (list.empty() ? std::string("it takes no parameters")
                                       : "known: " + list) +
                         ")");
  }
}

}  // namespace speculum::pipeline
