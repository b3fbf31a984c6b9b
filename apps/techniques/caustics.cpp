// The caustics technique's recipe (SURVEY §6): the distance-map frame (mirrors searched in
// their colour + distance cubes, refractors by distance impostors, §4), with the direct
// light completed by the caustics of the light pass: caustic_photons → caustic_map →
// caustic_gather, and caustic_reflector_maps (the cubes again, caustics on their faces) for
// the reflections and refractions.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/caustics.h"
#include "raster/distance_map_reflect.h"
#include "raster/reflector_maps.h"
#include "raster/refraction.h"
#include "raster/refraction_impostor.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_caustics_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  DistanceSearchOptions search;
  search.linear_steps = static_cast<int>(f.param("linear_steps"));
  search.linear = search.linear_steps >= 2;
  search.secant_steps = static_cast<int>(f.param("secant_steps"));
  const SurfaceResources s = add_surface_passes(g, scene, f);
  // The photons search these maps' distances only, and so do the camera's searches; what
  // reflections read is the lit maps' colour below, shaded where those searches read it.
  auto maps = g.add("reflector_cube_maps",
                    ReflectorDistanceMapsPass{scene, f.cube_map_size, ReflectorSelection::all, searched_distance_maps(false, false)},
                    s.gbuffer)
                  .describe("Distance cube map around each specular object, itself left out: what the "
                            "photons leaving a generator search (SURVEY §4.1, §6.1).");
  auto impostors = g.add("refractor_impostors",
                         RefractorImpostorsPass{scene, static_cast<int>(f.param("impostor_size")), true})
                       .describe("Each refractor and mirror alone from its centre: normal + distance cube map, "
                                 "searched for a refracted ray's exit and for a photon meeting its generator "
                                 "again (distance impostors, SURVEY §4.4).");
  CausticPhotonOptions po;
  po.photon_res = static_cast<int>(f.param("photon_res"));
  po.chain = static_cast<int>(f.param("chain"));
  po.receiver_search = search;
  po.exit_search = search;
  auto photons = g.add("caustic_photons", CausticPhotonsPass{scene, po}, maps, impostors);
  CausticMapOptions mo;
  mo.size = static_cast<int>(f.param("caustic_size"));
  mo.filter = static_cast<CausticFilter>(static_cast<int>(f.param("filter")));
  mo.storage = static_cast<CausticStorage>(static_cast<int>(f.param("storage")));
  mo.splat_radius = static_cast<int>(f.param("splat_radius"));
  mo.adaptive = f.param("adaptive") != 0.0;
  auto caustic_maps = g.add("caustic_map", CausticMapPass{scene, mo}, photons);
  const float tolerance = static_cast<float>(f.param("tolerance"));
  auto lit = g.add("caustic_gather", CausticGatherPass{tolerance}, s.gbuffer, caustic_maps, s.direct);
  // What reflections and refractions look up: the maps' colour with the caustics on it, where
  // the camera's searches and the refraction pass's paths (traced ahead in the distances) read it.
  RefractionOptions ro;
  ro.method = RefractionMethod::DistanceImpostor;
  ro.environment_search = search;
  ro.exit_search = search;
  auto searches = g.add("distance_map_search", DistanceMapSearchPass{search}, s.gbuffer, maps);
  auto refraction_reads = g.add("refraction_reads", RefractionReadsPass{scene, f.camera, ro}, s.gbuffer, s.visibility,
                                maps, par::Resource<GBuffer>{}, par::Resource<VertexThickness>{}, impostors);
  auto lit_maps = g.add("caustic_reflector_maps", CausticReflectorColourPass{scene, tolerance}, s.shadow_maps,
                        s.environment, maps, searches, refraction_reads, caustic_maps);
  auto reflected = g.add("distance_map_reflect", DistanceMapLookupPass{search}, s.gbuffer, s.environment, lit_maps,
                         searches);
  auto specular = g.add("refraction", RefractionPass{scene, f.camera, ro}, s.gbuffer, s.visibility, lit_maps,
                        s.environment, reflected, par::Resource<GBuffer>{}, par::Resource<VertexThickness>{},
                        impostors);
  return add_output_passes(g, f, lit, specular);
}

}  // namespace speculum::pipeline
