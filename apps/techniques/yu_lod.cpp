// The yu-lod technique's recipe (see yu_lod.h): raster passes of the envmap
// recipe for primary visibility and direct light, trace/ nodes for the glossy layer.
#include "apps/techniques/yu_lod.h"

#include <memory>
#include <vector>

#include "apps/techniques/frame_passes.h"
#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"
#include "trace/bvh.h"
#include "trace/glossy_rays.h"
#include "trace/hit_radiance.h"
#include "trace/lod_bvh.h"
#include "trace/lod_trace.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;
using LodHits = std::vector<trace::LodHit>;
using BvhPtr = std::shared_ptr<const trace::Bvh>;
using LightingPtr = std::shared_ptr<const trace::TriangleLighting>;
using LodPtr = std::shared_ptr<const trace::LodBvh>;

void add_yu_lod_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  add_yu_lod_passes_prebuilt(g, scene, f, nullptr);
}

void add_yu_lod_passes_prebuilt(par::Graph& g, const Scene* scene, const FrameSettings& f,
                                std::shared_ptr<YuLodStatic> pre) {
  const int n_rays = f.spp;
  const bool lod_on = f.alpha > 0.0f;
  const int env_samples = static_cast<int>(f.param("env_samples", 8));

  // One sample per pixel: N is the number of glossy rays, not supersamples.
  FrameSettings one = f;
  one.supersample = 1;
  SurfacePassNotes notes;
  notes.shadow_map = "shadow maps of the punctual lights (direct light of primary hits)";
  notes.visibility = "primary visibility by rasterization (YU §3.5 step 1)";
  notes.gbuffer = "positions, normals and materials of the visible samples (YU §3.5)";
  add_surface_passes(g, scene, one, notes);

  g.add("bvh_build", [scene, pre](par::NodeContext& c) {
     BvhPtr bvh = pre ? pre->bvh : nullptr;
     if (!bvh) bvh = std::make_shared<const trace::Bvh>(trace::Bvh::build(scene->mesh, c.executor()));
     else c.count("cached");
     if (pre) pre->bvh = bvh;
     c.count("triangles", bvh->triangle_count());
     c.count("nodes", bvh->threaded_nodes().size());
     c.set_output("bvh", bvh);
   }).writes<BvhPtr>("bvh")
     .describe("binned-SAH BVH with its threaded layout: hit and miss links (YU §3.2, [CHCH06])");

  g.add("radiance_bake", [scene, f, env_samples, pre](par::NodeContext& c) {
     LightingPtr lighting = pre ? pre->lighting : nullptr;
     if (!lighting) {
       trace::RadianceBakeOptions o;
       o.environment_samples = env_samples;
       o.seed = f.seed;
       lighting = std::make_shared<const trace::TriangleLighting>(trace::bake_triangle_lighting(
           c.executor(), *scene, *c.input<BvhPtr>("bvh"), o));
     } else {
       c.count("cached");
     }
     if (pre) pre->lighting = lighting;
     c.set_output("triangle_lighting", lighting);
   }).reads<BvhPtr>("bvh").writes<LightingPtr>("triangle_lighting")
     .param("env_samples", env_samples)
     .describe("per-triangle light visibility and occluded sky irradiance: the level-0 texels "
               "of the radiance pyramid (YU §3.4)");

  g.add("lod_build", [pre](par::NodeContext& c) {
     LodPtr lod = pre ? pre->lod : nullptr;
     if (!lod)
       lod = std::make_shared<const trace::LodBvh>(trace::build_lod_bvh(
           *c.input<BvhPtr>("bvh"), c.input<LightingPtr>("triangle_lighting")->radiance));
     else
       c.count("cached");
     if (pre) pre->lod = lod;
     c.set_output("lod_bvh", lod);
   }).reads<BvhPtr>("bvh").reads<LightingPtr>("triangle_lighting").writes<LodPtr>("lod_bvh")
     .describe("per-node approximate geometry (quad or box) and filtered radiance (YU §3.2)");

  g.add("glossy_rays", [n_rays, f](par::NodeContext& c) {
     const GBuffer& gb = c.input<GBuffer>("gbuffer");
     trace::GlossyRayOptions o;
     o.rays_per_pixel = n_rays;
     o.seed = f.seed;
     auto& rays = c.output<trace::GlossyRays>("glossy_rays");
     rays = trace::generate_glossy_rays(c.executor(), gb.position, gb.normal, gb.surface,
                                        gb.object, gb.eye, o);
     c.count("glossy_pixels", rays.pixel.size());
     c.count("rays", rays.ray_count());
     c.count("below_horizon", rays.below_horizon);
   }).reads<GBuffer>("gbuffer").writes<trace::GlossyRays>("glossy_rays").param("N", n_rays)
     .describe("N Phong-lobe rays per glossy pixel from a rotated Hamersley set, with their "
               "solid angles (YU §3.3, eq.4-5)");

  g.add("lod_trace", [lod_on, f](par::NodeContext& c) {
     const auto& rays = c.input<trace::GlossyRays>("glossy_rays");
     trace::LodOptions o;
     o.enabled = lod_on;
     o.alpha = f.alpha;
     trace::LodCounters k;
     trace::closest_hit_lod_stream(*c.input<BvhPtr>("bvh"), *c.input<LodPtr>("lod_bvh"),
                                   rays.rays, rays.solid_angle, o, c.output<LodHits>("glossy_hits"),
                                   c.executor(), &k);
     c.count("rays", k.traversal.rays);
     c.count("nodes_visited", k.traversal.nodes_visited);
     c.count("triangle_tests", k.traversal.triangle_tests);
     c.count("lod_stops", k.lod_stops);
     c.count("proxy_hits", k.proxy_hits);
   }).reads<BvhPtr>("bvh").reads<LodPtr>("lod_bvh").reads<trace::GlossyRays>("glossy_rays")
     .writes<LodHits>("glossy_hits").param("alpha", f.alpha).param("lod", lod_on ? 1 : 0)
     .describe("stackless threaded-BVH traversal with the LOD test Ω_box ≤ α² Ω_s (YU §3.4, "
               "eq.6-7)");

  g.add("hit_radiance", [scene](par::NodeContext& c) {
     trace::HitRadianceStats st;
     c.set_output("specular", trace::glossy_reflection(
                                  c.executor(), *scene, *c.input<LodPtr>("lod_bvh"),
                                  *c.input<LightingPtr>("triangle_lighting"),
                                  c.input<trace::GlossyRays>("glossy_rays"),
                                  c.input<LodHits>("glossy_hits"), &st));
     c.count("triangle_hits", st.triangle_hits);
     c.count("proxy_hits", st.proxy_hits);
     c.count("misses", st.misses);
   }).reads<LodPtr>("lod_bvh").reads<LightingPtr>("triangle_lighting")
     .reads<trace::GlossyRays>("glossy_rays").reads<LodHits>("glossy_hits")
     .writes<ImageRGBA>("specular")
     .describe("radiance at each hit at the eq.8-9 level, environment on a miss; F × the "
               "mean of the N samples (YU §3.4-3.5)");

  add_output_passes(g, one);
}

}  // namespace speculum::pipeline
