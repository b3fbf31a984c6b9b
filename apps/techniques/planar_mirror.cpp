// The planar-mirror technique's recipe: see planar_mirror.h.
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/planar_mirror.h"

#include <algorithm>
#include <vector>

#include "core/error.h"
#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/planar_mirror.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;
using PlanarMirrors = std::vector<PlanarMirror>;

void add_planar_mirror_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const double depth_param = f.param("depth", 3.0);
  if (!(depth_param >= 0.0 && depth_param <= 16.0))
    throw InputError("--param depth", "planar-mirror depth must be in [0, 16]");
  const int depth = static_cast<int>(depth_param);

  SurfacePassNotes notes;
  notes.shadow_map = "Shadow maps of the punctual lights, shared by every mirrored view (SURVEY §5).";
  notes.visibility = "Camera visibility buffer; the mirror samples are the stencil of SURVEY §5.";
  add_surface_passes(g, scene, f, notes);

  g.add("planar_mirrors", [scene](par::NodeContext& c) {
     auto& mirrors = c.output<PlanarMirrors>("planar_mirrors");
     mirrors = find_planar_mirrors(*scene);
     c.count("mirrors", mirrors.size());
   }).writes<PlanarMirrors>("planar_mirrors")
     .describe("Planar mirror objects (coplanar within 1e-3 of their size) and the scene "
               "clipped to each side of each mirror plane (SURVEY §5).");

  g.add("planar_mirror_reflect", [scene, f, depth](par::NodeContext& c) {
     PlanarMirrorSettings settings;
     settings.depth = depth;
     PlanarMirrorStats stats;
     c.set_output("specular",
                  planar_mirror_reflect(c.executor(), *scene, c.input<PlanarMirrors>("planar_mirrors"),
                                        c.input<GBuffer>("gbuffer"), f.camera,
                                        c.input<ShadowMaps>("shadow_maps"),
                                        c.input<EnvironmentMap>("environment"), settings, &stats));
     c.count("mirrored_views", stats.mirrored_views);
     c.count("mirror_samples", stats.mirror_samples);
   }).reads<PlanarMirrors>("planar_mirrors").reads<GBuffer>("gbuffer")
     .reads<ShadowMaps>("shadow_maps").reads<EnvironmentMap>("environment")
     .writes<ImageRGBA>("specular").param("depth", depth)
     .describe("Each planar mirror's samples get F × the view of the camera reflected about "
               "the mirror plane (scene clipped at the plane), recursively to depth k; other "
               "specular samples the environment map (SURVEY §5).");

  add_output_passes(g, f);
}

}  // namespace speculum::pipeline
