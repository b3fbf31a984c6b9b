// The planar-mirror technique's recipe (SURVEY §5): mirrors rendered by geometry
// transformation, recursively to depth k; see recipes.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/recipes.h"
#include "raster/planar_mirror.h"
#include "raster/reflector_maps.h"

namespace speculum::pipeline {

using namespace speculum::raster;

FrameOutputs add_planar_mirror_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  SurfacePassNotes notes;
  notes.shadow_map = "Shadow maps of the punctual lights, shared by every mirrored view (SURVEY §5).";
  notes.visibility = "Camera visibility buffer; the mirror samples are the stencil of SURVEY §5.";
  const SurfaceResources s = add_surface_passes(g, scene, f, notes);
  auto mirrors = g.add("planar_mirrors", PlanarMirrorsPass{scene});
  // Curved and glossy reflectors are not planar mirrors: they get the distance-map search in
  // cube maps of their own (SURVEY §4.2), in the camera's view and in every mirrored one —
  // their distances first, their colour only where the searches of all views read it.
  // (Reflectors the camera does not see may be seen in a mirror: every one gets a map.)
  auto distances = g.add("reflector_distance_maps",
                         ReflectorDistanceMapsPass{scene, f.cube_map_size, ReflectorSelection::not_planar_mirrors,
                                                   searched_distance_maps(false, true)},
                         s.gbuffer);
  auto views = g.add("planar_mirror_views", PlanarMirrorViewsPass{scene, f.camera, static_cast<int>(f.param("depth"))},
                     mirrors, s.gbuffer, s.shadow_maps, s.environment, distances);
  auto curved = g.add("reflector_cube_maps", ReflectorColourPass<PlanarMirrorViews>{scene}, s.shadow_maps,
                      s.environment, distances, views);
  auto specular = g.add("planar_mirror_reflect", PlanarMirrorComposePass{}, views, s.gbuffer, mirrors, s.environment,
                        curved);
  return add_output_passes(g, f, s.direct, specular);
}

}  // namespace speculum::pipeline
