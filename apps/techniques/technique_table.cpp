// The technique table: see technique_table.h.
#include "apps/techniques/technique_table.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "apps/techniques/recipes.h"
#include "core/did_you_mean.h"
#include "core/error.h"

namespace speculum::pipeline {

namespace {

// The distance-map search (SURVEY §4.1), shared by the techniques that search distance maps.
std::vector<TechniqueParam> search_params() {
  // The step counts multiply the search's cost per sample (and, in multi-reflection, per
  // cube-map texel and round); their maxima stop where more steps cannot help: 256 linear
  // steps are finer than a texel along a ray through the default 256² cube face, and the
  // secant and parallax iterations reach float precision long before 16.
  return {{"parallax", 1, 0, 1, true, "1: parallax correction (eq.4) when no bracket is found"},
          {"linear", 1, 0, 1, true, "1: linear search along the ray (§4.1.2)"},
          {"secant", 1, 0, 1, true, "1: secant refinement of the bracket (eq.5)"},
          {"parallax_steps", 1, 1, 16, true, "parallax iterations (converged long before 16)"},
          {"linear_steps", 16, 1, 256, true, "linear search steps (256: under a texel of a 256² face)"},
          {"secant_steps", 4, 0, 16, true, "secant iterations (float precision long before 16)"},
          {"lobe_directions", 8, 1, 64, true, "searches per glossy lobe, each a sub-lobe (1: along R only)"}};
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

std::string TechniqueParam::value_text(double v) const {
  if (!choices.empty() && v >= 0 && v < static_cast<double>(choices.size()) && v == std::floor(v))
    return choices[static_cast<std::size_t>(v)];
  return number(v);
}

std::string TechniqueParam::range_text() const {
  if (choices.empty())
    return std::string(integer ? "integer" : "number") + " in [" + number(min) + ", " + number(max) + "]";
  std::string names;
  for (const std::string& c : choices) names += (names.empty() ? "" : "|") + c;
  return "one of " + names;
}

TechniqueParam choice_param(std::string name, const std::string& fallback, std::vector<std::string> names,
                            std::string doc) {
  const auto at = std::find(names.begin(), names.end(), fallback);
  TechniqueParam p{std::move(name), static_cast<double>(at - names.begin()), 0,
                   static_cast<double>(names.size()) - 1, true, std::move(doc), std::move(names)};
  return p;
}

const std::vector<Technique>& techniques() {
  static const std::vector<Technique> table = {
      {"envmap",
       "environment mapping (SURVEY §3.1): reflect/refract into the prefiltered environment "
       "cube, Schlick Fresnel; no parallax",
       add_envmap_passes,
       {}},
      {"reference",
       "reference tracer: BVH ray tracing, Whitted mirrors/refraction, GGX-lobe glossy "
       "sampling (--spp path samples, --bounces specular depth, default 8), caustics by light "
       "tracing; the ground truth",
       add_reference_passes,
       // Photons cost time only (each splats into the frame it is traced for): 256 per pixel
       // of a 640×480 frame is ~79M per light and generator.
       {{"caustic_photons", 16, 0, 256, true,
         "light-traced caustic photons per pixel, per light and mirror/refractor (0: no caustics)"}},
       double(1 << 26)},  // paths cost time only (memory is per pixel): about two minutes on two cores
      {"specular-reference",
       "reference for the specular term alone: the feed-forward G-buffer and direct light, "
       "reflected/refracted rays traced exactly through the BVH to --bounces, glossy lobes "
       "sampled to convergence",
       add_specular_reference_passes,
       {{"glossy_samples", 256, 1, 4096, true,
         "GGX visible-normal samples per glossy pixel (≤ 4096: time grows with it)"}}},
      {"distance-map",
       "distance maps (SURVEY §4.1-4.2): per-reflector colour+distance cube, searched per sample",
       add_distance_map_passes, search_params()},
      {"multi-reflection",
       "inter-object reflections (SURVEY §4.3): reflector distance maps rebuilt in rounds, one "
       "bounce each",
       add_multi_reflection_passes,
       concat({{"rounds", 3, 1, 8, true, "rounds of map re-rendering (bounces; each re-renders every map)"},
               {"lagged", 0, 0, 1, true, "1: one round per frame from the previous frame's maps"}},
              search_params())},
      {"layered-distance-map",
       "layered distance maps (SURVEY §4.5): the scene depth-peeled into cube layers, recursive "
       "linear+secant tracer",
       add_layered_distance_map_passes,
       {{"layers", 3, 1, 8, true, "depth-peeled layers"},
        // ≈ 100 bytes per texel per layer (a G-buffer, distance and colour): 8 layers of 512²
        // faces peak near 1.5 GB, of 1024² near 5.4 GB.
        {"layer_size", 128, 8, 512, true, "cube face side of the layers (8 layers at 512: ~1.5 GB)"},
        {"linear_steps", 16, 2, 256, true, "linear search steps per layer"},
        {"secant_steps", 4, 0, 16, true, "secant iterations (float precision long before 16)"},
        {"bounces", 2, 1, 16, true, "specular hits followed (--bounces raises it)"}}},
      {"planar-mirror",
       "planar mirrors by geometry transformation (SURVEY §5): the camera reflected about each "
       "mirror plane, scene clipped at the plane, recursive; curved and glossy reflectors by the "
       "distance-map search in their own cube maps (SURVEY §4)",
       add_planar_mirror_passes,
       // Each level renders the frame again per mirror seen: m mirrors that see each other
       // cost up to (m-1)^depth views, so the depth stays small and the pass renders at most
       // 256 mirrored views in all (PlanarMirrorSettings::max_views, counted when reached).
       {{"depth", 3, 0, 8, true, "mirror bounces rendered by reflected cameras (at most 256 views in all)"}}},
      {"soff",
       "second-order feed-forward (SOFF §3): non-diffuse samples binned into clusters by normal "
       "and reflector, a pinhole camera and a rasterized depth image per cluster, reflected rays "
       "walked through it pixel by pixel; glossy: several lobe rays",
       add_soff_passes,
       // Each cluster renders the scene once: the bins bound the clusters (reflectors × θ × φ).
       // The depth images hold at most 4 × image_scale² pixels per clustered sample (~20 bytes
       // each, kept for the frame): at the 2²³-sample limit and scale 2, ~2.7 GB; each side is
       // also bounded by max_image_side. glossy_rays multiplies the walks per glossy sample.
       {{"theta_bins", 13, 1, 64, true, "MAXTHETABINS: normal azimuth bins (clusters grow with it)"},
        {"phi_bins", 8, 1, 32, true, "MAXPHIBINS: normal polar bins (clusters grow with it)"},
        {"share_gain", 16, 0.01, 100, false,
         "bins scale with a reflector's screen share in percent × this / visible reflectors, at most 1 (calibration)"},
        {"image_scale", 1, 0.125, 2, false, "depth-image resolution × this (SOFF Table 5; ≤ 16 pixels per sample at 2)"},
        {"max_image_side", 1024, 16, 4096, true, "largest depth-image side (clamped images are counted)"},
        {"glossy_rays", 8, 1, 64, true, "reflected rays per glossy sample (SOFF §3.5: 8 to 49)"},
        {"glossy_far", 1, 0.05, 1, false, "glossy clusters' far plane at this × the scene diameter (§3.5)"},
        choice_param("fill", "environment", {"environment", "depth-image"},
                     "disoccluded rays: the environment (SOFF), or the depth image beside the silhouette"),
        {"reshade", 1, 0, 1, true, "1: a hit's view-dependent shading is re-evaluated for the ray; 0: the depth image's colour"},
        choice_param("concave", "convex", {"convex", "self"},
                     "concave clusters (SOFF §4.4): like convex ones, or rays first intersected with their own reflector")}},
      {"refraction",
       "refraction (SURVEY §4.4): exit refracted or totally internally reflected, looked up in "
       "the refractor's colour+distance cube",
       add_refraction_passes,
       {choice_param("method", "two-face", {"single", "two-face", "impostors"},
                     "single interface, two-face (back-face normals + thickness), distance impostors"),
        {"linear_steps", 16, 0, 256, true, "linear search steps (both searches; < 2: off)"},
        {"secant_steps", 4, 0, 16, true, "secant iterations (float precision long before 16)"},
        // ≈ 150 MB per refractor at 1024² faces, ≈ 3.6 GB at 4096².
        {"impostor_size", 128, 4, 1024, true, "cube face side of the distance impostors (method=impostors; ~150 MB each at 1024)"}}},
      {"caustics",
       "caustics (SURVEY §6): photons shot from each light through each mirror/refractor, "
       "receivers found in its distance map, stored in a cube map at the generator, splats or "
       "caustic triangles, gathered with a distance check; distance-map reflection/refraction",
       add_caustics_passes,
       // Photon images cost photon_res² texels per light and generator (512: 262k each), the
       // caustic map 6·caustic_size² texels (1024: ~200 MB per generator).
       {{"photon_res", 128, 16, 512, true, "photon image side per light and generator (512: 262k photons)"},
        {"chain", 4, 0, 16, true,
         "steps a photon follows past its first generator: a mirror meeting itself, a refractor's TIR, another generator"},
        choice_param("filter", "splat", {"splat", "triangles"},
                     "normalized tent-kernel splats, or caustic triangles (then blurred)"),
        choice_param("storage", "cube", {"cube", "light"},
                     "caustic map centred at the generator (SURVEY §6.2), or at the light (shadow-map space: leaks)"),
        {"splat_radius", 1, 0, 8, true, "splat kernel radius in caustic-map texels (splat; the least with adaptive)"},
        {"adaptive", 1, 0, 1, true, "1: splat radius grows to the neighbouring photons' spacing (at most 8 texels)"},
        {"caustic_size", 128, 16, 1024, true, "cube face side of the caustic map (1024: ~200 MB per generator)"},
        {"tolerance", 0.05, 0.001, 1, false, "relative distance mismatch still taken as the photons' receiver"},
        {"linear_steps", 16, 0, 256, true, "linear search steps (receiver and exit searches; < 2: off)"},
        {"secant_steps", 4, 0, 16, true, "secant iterations (float precision long before 16)"},
        {"impostor_size", 128, 4, 1024, true, "cube face side of the generators' distance impostors (~150 MB each at 1024)"}}},
      {"yu-lod",
       "YU glossy reflections: --spp N Phong-sampled rays per glossy pixel through a threaded "
       "BVH with adaptive LOD (eq.7, --alpha A; 0: LOD off), pre-filtered hit radiance (eq.8-9)",
       add_yu_lod_passes,
       // The bake traces triangles × env_samples rays; 256 already brings its noise to 1/16
       // of a single ray's (σ/√n).
       {{"env_samples", 8, 0, 256, true, "sky rays per triangle in the radiance bake (time ∝ triangles × samples)"}},
       double(1 << 26),  // glossy rays, ~32 bytes each in flight: ~2 GB at the limit
       // 8 rays per glossy pixel by default: one ray leaves a pixel black wherever it lands in
       // shadow; YU §5 uses 20–40 on the GPU.
       8},
      {"ray-hierarchy",
       "ROGER ch.3 ray hierarchy: one reflected/refracted ray per specular pixel through a "
       "screen-space cone-sphere quad-tree over stream compaction, exact closest hits; --bounces B",
       add_ray_hierarchy_passes,
       // The pair buffer takes ≈ 10 bytes per pair at its fullest: 2^26 pairs ≈ 0.7 GB. A
       // smaller capacity costs nothing but batches (the same hits, ROGER §4.3).
       {{"pair_capacity", 2048.0 * 2048.0, 1, 1 << 26, true, "pair buffer capacity (pairs; ~10 bytes each)"},
        {"block", 64, 1, 65536, true, "block size s of the hierarchical compaction (ROGER §4.3.2)"}},
       double(1 << 22)},  // ~770 bytes per pixel of ray streams and hierarchy: ~3.3 GB at the limit
      {"cone-tracing",
       "ROGER ch.5 cone tracing: one cone per specular pixel (footprint reflected off a sphere of "
       "the pixel's mean curvature, plus the glossy angle) through the ray hierarchy with cone "
       "leaves; exact triangle ∩ cone coverage, the n nearest blended front to back; --bounces B",
       add_cone_tracing_passes,
       {{"kept", 20, 1, 64, true, "nearest triangles blended per pixel (ROGER: n <= 20; more are counted as overflow)"},
        {"footprint", 1, 0, 16, false, "pixel cone scale (1: the pixel's solid angle; 0: no anti-aliasing)"},
        {"gloss_angle", -1, -1, 0.5, false,
         "glossy cone half-angle for every reflecting pixel (rad); -1: from each material's lobe"},
        {"lobe_energy", 0.5, 0.1, 0.999, false, "fraction of a material's Phong lobe its glossy cone holds"},
        {"far_blur", 0.5, 0, 100, false,
         "far plane where the glossy blur reaches this fraction of the scene radius (0: none)"},
        choice_param("fill", "mean", {"environment", "mean"},
                     "the dropped hits' coverage: the environment only, or the kept hits' mean colour before it"),
        {"pair_capacity", 2048.0 * 2048.0, 1, 1 << 26, true, "pair buffer capacity (pairs; ~10 bytes each)"},
        {"block", 64, 1, 65536, true, "block size s of the hierarchical compaction (ROGER §4.3.2)"}},
       // Each pixel has `kept` slots of kept hits (24 bytes) and of the layer generation
       // shaded from them (~80 bytes with its hits, shadows and image): 512² × 64 slots ≈ 1.7 GB.
       double(1 << 18)},
      {"vertex-projection",
       "ROGER ch.2 vertex projection: each scene vertex moved to its Fermat reflection point on "
       "each star-shaped mirror (2-D secant iteration), triangles rasterized between them; "
       "other specular surfaces as envmap",
       add_vertex_projection_passes,
       // Every reflected vertex costs up to max_iterations reflector lookups per reflector;
       // edge splitting multiplies the vertices by about (1/edge)² and stops at 2^22.
       {{"edge", 1.0 / 64.0, 0, 1, false,
         "split reflected edges longer than this fraction of the scene diagonal (0: off; vertices ≤ 2^22)"},
        {"param_size", 256, 8, 2048, true, "reflector parameterization cube face side (2048: 6 × 4M texels, ~400 MB)"},
        {"max_iterations", 32, 1, 32, true, "secant iterations per vertex and reflector (ROGER: ≤ 20 at silhouettes)"},
        {"pixel_tolerance", 1, 0.01, 16, false, "stop when the sample triangle's longest projected edge is under this (pixels)"},
        {"residual", 3e-3, 1e-9, 1, false, "and the path-length gradient |g| at the best sample is under this"}}},
  };
  return table;
}

const Technique& find_technique(const std::string& name) {
  std::string known;
  std::vector<std::string> names;
  for (const Technique& t : techniques()) {
    if (t.name == name) return t;
    known += (known.empty() ? "" : ", ") + t.name;
    names.push_back(t.name);
  }
  throw InputError("--technique", "unknown technique '" + name + "'" + did_you_mean(name, names) +
                                      " (known: " + known + ")");
}

namespace {

// The parameter `name` of `technique`; throws InputError listing the known names.
const TechniqueParam& find_param(const Technique& technique, const std::string& name) {
  for (const TechniqueParam& p : technique.params)
    if (p.name == name) return p;
  std::string list;
  std::vector<std::string> names;
  for (const TechniqueParam& p : technique.params) {
    list += (list.empty() ? "" : ", ") + p.name;
    names.push_back(p.name);
  }
  throw InputError("--param " + name, "unknown parameter '" + name + "' for technique '" + technique.name + "'" +
                                          did_you_mean(name, names) + " (" +
                                          (list.empty() ? std::string("it takes no parameters") : "known: " + list) +
                                          ")");
}

}  // namespace

void check_technique_params(const Technique& technique, const std::map<std::string, double>& params) {
  for (const auto& [name, value] : params) {
    const TechniqueParam* spec = &find_param(technique, name);
    const std::string range = spec->range_text();
    if (!(value >= spec->min && value <= spec->max))
      throw InputError("--param " + name, number(value) + " is outside the valid range of '" + name +
                                              "' for technique '" + technique.name + "': " + range);
    if (spec->integer && value != std::floor(value))
      throw InputError("--param " + name, number(value) + " is not a whole number: '" + name +
                                              "' for technique '" + technique.name + "' takes " +
                                              (spec->choices.empty() ? "an " : "") + range);
  }
}

std::pair<std::string, double> parse_technique_param(const Technique& technique, const std::string& item) {
  const auto eq = item.find('=');
  if (eq == std::string::npos || eq == 0) throw InputError("--param", "expected name=value, got '" + item + "'");
  const std::string name = item.substr(0, eq), text = item.substr(eq + 1);
  const TechniqueParam& p = find_param(technique, name);
  for (std::size_t k = 0; k < p.choices.size(); ++k)
    if (p.choices[k] == text) return {name, static_cast<double>(k)};
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') {
    if (!p.choices.empty())
      throw InputError("--param " + name, "unknown value '" + text + "' of '" + name + "' for technique '" +
                                              technique.name + "'" + did_you_mean(text, p.choices) + ": " +
                                              p.range_text());
    throw InputError("--param " + name, "expected a number, got '" + item + "'");
  }
  if (!std::isfinite(v)) throw InputError("--param " + name, "expected a finite number, got '" + item + "'");
  check_technique_params(technique, {{name, v}});
  return {name, v};
}

FrameSettings Technique::with_defaults(FrameSettings settings) const {
  check_technique_params(*this, settings.params);
  for (const TechniqueParam& p : params) settings.params.emplace(p.name, p.fallback);
  settings.spp = resolve_spp(settings.spp, settings.width, settings.height);
  return settings;
}

int Technique::resolve_spp(int spp, int width, int height) const {
  if (spp > 0) return spp;
  const double pixels = std::max(double(width) * double(height), 1.0);
  return static_cast<int>(std::max(1.0, std::min(double(default_spp), std::floor(max_samples / pixels))));
}

std::string Technique::describe_params(const std::string& indent) const {
  std::string out;
  for (const TechniqueParam& p : params)
    out += indent + p.name + "=" + p.value_text(p.fallback) + "  " + p.range_text() + "  " + p.doc + "\n";
  return out;
}

}  // namespace speculum::pipeline
