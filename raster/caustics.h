// Caustics by the light pass through distance maps (SURVEY §6): photons are shot from each
// light at each caustic generator (a mirror or refractor object), follow the generator's
// specular path and find their diffuse receiver in the generator's environment distance map
// (§4); their hits are stored in a cube map centred at the generator (§6.2), filtered by
// splatting or by caustic triangles (§6.3), and each shaded point reads the map in its own
// direction from the generator's centre, accepting the light only where the stored distance
// matches its own (§6.3.3) — the shadow-map-like test that keeps occluded receivers dark.
//
// Three passes:
// - caustic_photons (§6.1.2): per light × generator, the generator rendered from the light
//   into a photon_res² photon image; each texel on the generator reflects (mirror) or
//   refracts in and out (refractor: the distance impostor of §4.4 finds the exit) and then
//   searches the generator's distance map for its receiver. Its power is the light's
//   intensity times the texel's solid angle (Φ·Ω_texel/(4π) of a point light of power Φ),
//   or the irradiance times the texel's area for a directional light, times the path's
//   Fresnel factors and transmittance.
// - caustic_map (§6.2–6.3): the photon hits in cube-map space about the generator's centre:
//   flux per texel and the flux-weighted receiver distance. filter splat: each photon's flux
//   spread by a normalized tent kernel of splat_radius texels, or (adaptive) of the distance
//   to its neighbours in the photon image, at most 8 (the weights sum to one, so the map's
//   total flux does not depend on the radius); filter triangles: neighbouring photon
//   texels joined into caustic triangles whose flux is spread over the texels they cover,
//   then a normalized 3×3 blur.
// - caustic_gather (§6.3.3): per G-buffer sample and generator, the flux of the texel the
//   sample is seen through from the centre, as irradiance Φ cosα/(Ω d²) on the sample's
//   surface (α between its normal and the line from the centre), arriving from the texel's
//   mean photon direction, shaded with the surface's BRDF, added to the direct light.
//
// A refractor's photons take two paths, refracted in and out and reflected off its surface
// (one photon image each). Up to `chain` steps are followed per photon: a mirror that meets
// itself again (a ring, a bowl) is found in its own distance impostor (§4.4's search, the
// mirror alone), a refractor's total internal reflections in its impostor, and a receiver
// found on another generator's impostor surface sends the photon on through that generator
// and its distance map. Limits: one path per photon (a refractor's partial reflections are
// not followed), and a photon leaving a refractor does not meet it again. Reflections and
// refractions see the caustics through
// caustic_reflector_maps, the reflector cube maps rendered again with the caustics gathered
// on their faces.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"
#include "raster/distance_map_reflect.h"
#include "raster/distance_map_search.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/refraction_impostor.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

struct CausticPhotonOptions {
  int photon_res = 128;                // photon image side per light × generator
  // Steps followed per photon beyond its first generator: a mirror meeting itself again
  // (found in its own distance impostor), a refractor's total internal reflections, a
  // passage into another generator.
  int chain = 4;
  DistanceSearchOptions receiver_search;  // in the generator's environment distance map
  DistanceSearchOptions exit_search;      // in a refractor's distance impostor
};

// The photons of one light × generator: photon_res² texels, row-major.
struct PhotonImage {
  std::uint32_t object = 0;  // the generator
  std::uint32_t light = 0;
  int res = 0;
  bool surface_reflection = false;   // a refractor's reflected twin (else its refracted path, or a mirror's)
  glm::vec3 centre{0.0f};            // the generator's map centre o
  std::vector<glm::vec3> hit;        // receiver point (world)
  std::vector<glm::vec3> wi;         // unit, from the receiver point back along the photon
  std::vector<glm::vec3> flux;       // W; zero where the texel carries no photon
  std::vector<std::uint8_t> valid;   // 1: a photon that found its receiver
};

struct CausticPhotons {
  std::vector<PhotonImage> images;
  std::uint64_t photons = 0;         // photon-image texels that see their generator (a
                                     // refractor's reflected twin not counted again)
  std::uint64_t stored = 0;          // photons with a receiver
  std::uint64_t total_internal = 0;  // refracted photons dropped by total internal reflection
                                     // beyond the chain bound
  std::uint64_t internal_reflections = 0;  // reflections followed inside the generators
  std::uint64_t generator_hops = 0;  // photons' passages from one generator into another
  std::uint64_t chain_limited = 0;   // photons still meeting a generator after `chain` steps
  std::uint64_t no_receiver = 0;     // searches that found nothing (the environment)
  glm::dvec3 generator_flux{0.0};    // Σ photon power arriving at the generators
  glm::dvec3 stored_flux{0.0};       // Σ power of the stored photons (after the path's Fresnel)
};

// The caustic generators: objects whose material is a mirror or a refractor.
std::vector<std::uint32_t> caustic_generator_objects(const Scene& scene);

CausticPhotons trace_photon_images(par::Executor& executor, const Scene& scene, const ReflectorMaps& maps,
                                   const RefractorImpostors* impostors, const CausticPhotonOptions& options);

enum class CausticFilter : std::uint8_t { Splat = 0, Triangles = 1 };

// Where the photon hits are stored: a cube map centred at the generator (SURVEY §6.2), or
// the same map centred at the light (shadow-map space, the variant §6.2 argues against: its
// distance check cannot tell the photons' receiver from a point behind it along the
// light's ray).
enum class CausticStorage : std::uint8_t { Cube = 0, Light = 1 };

struct CausticMapOptions {
  int size = 128;                // cube face side
  CausticFilter filter = CausticFilter::Splat;
  CausticStorage storage = CausticStorage::Cube;
  int splat_radius = 1;          // texels, 0..8 (0: the nearest texel only)
  bool adaptive = true;          // splat: radius raised to the spacing of neighbouring photons
};

// One cube per generator (per generator and light with light storage): colour rgb = flux
// (W) per texel, distance = flux-weighted mean receiver distance |y − o| (+inf where no flux
// landed).
using CubeDirections = std::array<Buffer2D<glm::vec3>, kCubeFaces>;
struct CausticMaps {
  std::vector<int> map_of_object;  // the generator's (first) map; -1: not a generator
  std::vector<CubeMap> cubes;
  // Per texel the flux-weighted mean direction the photons arrived from (unit): receivers
  // beside the generator are lit from its surface, not from its centre.
  std::vector<CubeDirections> incident;
  std::vector<std::uint32_t> objects;
};

CausticMaps build_caustic_maps(par::Executor& executor, const Scene& scene, const CausticPhotons& photons,
                               const CausticMapOptions& options);
// Sum of the flux stored in a map (red, green, blue).
glm::dvec3 caustic_map_flux(const CubeMap& map);
// The solid angle of texel (x, y) of a size² cube face.
float cube_texel_solid_angle(int x, int y, int size);

// `direct` + the caustic light of every map on the G-buffer's samples (the same size).
// `tolerance`: the relative distance mismatch still accepted as the same receiver.
ImageRGBA gather_caustics(par::Executor& executor, const GBuffer& gbuffer, const CausticMaps& maps,
                          const ImageRGBA& direct, float tolerance);

// Pass "caustic_photons".
struct CausticPhotonsPass {
  static constexpr const char* description =
      "Per light and caustic generator, the generator rendered from the light into a photon "
      "image; each texel reflects or refracts through it and searches the generator's distance "
      "map for its diffuse receiver, with power Φ·Ω_texel/(4π) times Fresnel (SURVEY §6.1.2).";
  const Scene* scene = nullptr;
  CausticPhotonOptions options;
  void parameters(par::Params& p) const { p.set("photon_res", options.photon_res).set("chain", options.chain); }
  CausticPhotons operator()(par::NodeContext& c, const ReflectorMaps& maps, const RefractorImpostors* impostors) const;
};

// Pass "caustic_map".
struct CausticMapPass {
  static constexpr const char* description =
      "Photon hits in a cube map centred at each generator (flux + distance), filtered by "
      "normalized splats or caustic triangles (SURVEY §6.2-6.3).";
  const Scene* scene = nullptr;
  CausticMapOptions options;
  void parameters(par::Params& p) const {
    p.set("size", options.size)
        .set("filter", options.filter == CausticFilter::Splat ? "splat" : "triangles")
        .set("storage", options.storage == CausticStorage::Cube ? "cube" : "light")
        .set("splat_radius", options.splat_radius)
        .set("adaptive", options.adaptive ? 1 : 0);
  }
  CausticMaps operator()(par::NodeContext& c, const CausticPhotons& photons) const;
};

// The caustics technique's lit maps: the colour of `distances` (rendered with
// MapSizing::keep_visibility) with the caustics gathered on the faces, shaded only on the
// tiles `searches` read and those `refraction_reads` marks (mark_refraction_reads: where the
// refraction pass's paths read the refractors' maps); null: a refractor's map whole.
ReflectorMaps shade_caustic_reflector_maps(par::Executor& executor, const Scene& scene,
                                           const std::vector<ShadowMap>& shadows, const EnvironmentMap& env,
                                           const ReflectorMaps& distances, const DistanceSearches& searches,
                                           const std::vector<CubeTileMask>* refraction_reads,
                                           const CausticMaps& caustics, float tolerance);

// Pass "caustic_reflector_maps" after the camera's searches and the refraction pass's reads:
// the same maps' colour, shaded only where those read it (shade_reflector_maps with the
// caustics on the faces).
struct CausticReflectorColourPass {
  static constexpr const char* description =
      "Per specular object the colour of its cube map, its faces' direct light completed by the "
      "caustic maps, shaded only where the camera's searches and refracted paths read it: caustics "
      "seen in reflections and through refractors (SURVEY §6.3.3).";
  const Scene* scene = nullptr;
  float tolerance = 0.05f;
  void parameters(par::Params& p) const { p.set("tiles", "read by the searches and the refracted paths"); }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows, const EnvironmentMap& environment,
                           const ReflectorMaps& distances, const DistanceSearches& searches,
                           const std::vector<CubeTileMask>& refraction_reads, const CausticMaps& caustics) const;
};

// Pass "caustic_gather".
struct CausticGatherPass {
  static constexpr const char* description =
      "Direct light plus caustics: each sample reads the caustic map in its direction from the "
      "generator's centre where the stored distance matches its own (SURVEY §6.3.3).";
  float tolerance = 0.05f;
  void parameters(par::Params& p) const { p.set("tolerance", tolerance); }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const CausticMaps& maps,
                       const ImageRGBA& direct) const;
};

}  // namespace speculum::raster
