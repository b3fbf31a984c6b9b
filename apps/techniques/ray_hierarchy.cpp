// The ray-hierarchy technique's recipe: see ray_hierarchy.h (ROGER ch.3).
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/ray_hierarchy.h"

#include <algorithm>
#include <string>
#include <vector>

#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;
using ShadowHits = std::vector<trace::HitStream>;

namespace {

// Adds a traversal's counters to the node (pairs per level, tests, candidates, batches).
void count_traversal(par::NodeContext& c, const trace::HierarchyTraverseStats& s) {
  for (std::size_t l = 0; l < s.pairs_per_level.size(); ++l) c.count("pairs_level_" + std::to_string(l), s.pairs_per_level[l]);
  c.count("cone_sphere_tests", s.cone_sphere_tests);
  c.count("candidates", s.candidates);
  c.count("rays", s.active_rays);
  c.count("level_passes", s.level_passes);
  c.count("overflow_batches", s.overflow_batches);
  c.count("batches", s.batches);
  c.count("hits", s.hits);
  c.count("candidates_per_ray_x1000", static_cast<std::uint64_t>(s.candidates_per_ray() * 1000.0 + 0.5));
  // Stage wall times (the thesis's split; not deterministic, like every *_ns counter).
  c.count("tests_ns", static_cast<std::uint64_t>(s.tests_ms * 1e6));
  c.count("compaction_ns", static_cast<std::uint64_t>(s.compaction_ms * 1e6));
  c.count("exact_ns", static_cast<std::uint64_t>(s.exact_ms * 1e6));
}

}  // namespace

void add_ray_hierarchy_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  const int bounces = std::max(1, f.bounces);
  trace::HierarchyTraverseOptions topt;
  topt.pair_capacity = static_cast<std::size_t>(std::max(1.0, f.param("pair_capacity", 2048.0 * 2048.0)));
  topt.block_size = static_cast<std::size_t>(std::max(1.0, f.param("block", 64.0)));

  SurfacePassNotes notes;
  notes.shadow_map = "shadow maps of the punctual lights for the primary hits (ROGER §3.5 set-up)";
  notes.visibility = "primary visibility by rasterization (ROGER §3.1: rays start from the G-buffer)";
  notes.gbuffer = "positions, normals and materials of the visible samples (ROGER §3.1)";
  add_surface_passes(g, scene, f, notes);

  g.add("secondary_rays", [f](par::NodeContext& c) {
     const GBuffer& gb = c.input<GBuffer>("gbuffer");
     auto& rays = c.output<trace::SecondaryRays>("rays_1");
     rays = trace::secondary_rays(c.executor(), gb.position, gb.normal, gb.surface, gb.object, f.camera.eye);
     c.count("rays", rays.count);
   }).reads<GBuffer>("gbuffer").writes<trace::SecondaryRays>("rays_1")
     .describe("one reflected or refracted ray per specular pixel (ROGER §3.1)");

  for (int b = 1; b <= bounces; ++b) {
    const std::string sfx = b == 1 ? "" : "_" + std::to_string(b);
    const std::string rays = "rays_" + std::to_string(b), hier = "hierarchy_" + std::to_string(b),
                      hits = "hits_" + std::to_string(b), shadow = "shadow_hits_" + std::to_string(b),
                      spec_in = "specular_" + std::to_string(b - 1), spec = "specular_" + std::to_string(b);
    if (b > 1) {
      const std::string prev_rays = "rays_" + std::to_string(b - 1), prev_hits = "hits_" + std::to_string(b - 1);
      g.add("bounce_rays" + sfx, [scene, prev_rays, prev_hits, rays](par::NodeContext& c) {
         auto& out = c.output<trace::SecondaryRays>(rays);
         out = trace::bounce_rays(c.executor(), *scene, c.input<trace::SecondaryRays>(prev_rays),
                                  c.input<trace::HitStream>(prev_hits));
         c.count("rays", out.count);
       }).reads<trace::SecondaryRays>(prev_rays).reads<trace::HitStream>(prev_hits)
         .writes<trace::SecondaryRays>(rays).param("bounce", b)
         .describe("the next generation rebuilt from the specular hits (ROGER §3.4)");
    }

    g.add("ray_hierarchy" + sfx, [rays, hier, sw, sh](par::NodeContext& c) {
       const auto& r = c.input<trace::SecondaryRays>(rays);
       auto& h = c.output<trace::RayHierarchy>(hier);
       h = trace::build_ray_hierarchy(c.executor(), r.rays, r.active, sw, sh);
       c.count("levels", std::uint64_t(h.levels));
       c.count("leaves", std::uint64_t(h.side) * std::uint64_t(h.side));
     }).reads<trace::SecondaryRays>(rays).writes<trace::RayHierarchy>(hier).param("bounce", b)
       .describe("screen-space quad-tree of cone-spheres built bottom-up, one kernel per level (ROGER §3.2)");

    g.add("hierarchy_traverse" + sfx, [scene, rays, hier, hits, topt](par::NodeContext& c) {
       auto& out = c.output<trace::HitStream>(hits);
       trace::HierarchyTraverseStats st;
       trace::hierarchy_closest_hits(c.executor(), scene->mesh.positions, scene->mesh.indices,
                                     c.input<trace::RayHierarchy>(hier), c.input<trace::SecondaryRays>(rays).rays,
                                     out, topt, &st);
       count_traversal(c, st);
     }).reads<trace::SecondaryRays>(rays).reads<trace::RayHierarchy>(hier).writes<trace::HitStream>(hits)
       .param("pair_capacity", topt.pair_capacity).param("block", topt.block_size)
       .describe("(node, triangle) pairs refined per level with eq.3.1 and compacted, then exact tests and the "
                 "closest hit per ray (ROGER §3.3, §4.3)");

    g.add("shadow_rays" + sfx, [scene, rays, hits, shadow, topt, sw, sh](par::NodeContext& c) {
       const auto& gen = c.input<trace::SecondaryRays>(rays);
       const auto& h = c.input<trace::HitStream>(hits);
       auto& out = c.output<ShadowHits>(shadow);
       out.assign(scene->lights.size(), trace::HitStream{});
       for (std::size_t l = 0; l < scene->lights.size(); ++l) {
         const trace::SecondaryRays sr = trace::shadow_rays(c.executor(), *scene, scene->lights[l], gen, h);
         const trace::RayHierarchy hi = trace::build_ray_hierarchy(c.executor(), sr.rays, sr.active, sw, sh);
         trace::HierarchyTraverseStats st;
         trace::hierarchy_closest_hits(c.executor(), scene->mesh.positions, scene->mesh.indices, hi, sr.rays,
                                       out[l], topt, &st);
         c.count("shadow_rays", sr.count);
         c.count("shadow_cone_sphere_tests", st.cone_sphere_tests);
         c.count("shadow_candidates", st.candidates);
         c.count("shadowed", st.hits);
       }
     }).reads<trace::SecondaryRays>(rays).reads<trace::HitStream>(hits).writes<ShadowHits>(shadow)
       .describe("shadow rays reversed to start at each point light, traced through their own hierarchy "
                 "(ROGER §3.4)");

    par::NodeBuilder shade =
        g.add("shade_hits" + sfx, [scene, rays, hits, shadow, spec_in, spec, b, sw, sh](par::NodeContext& c) {
           auto& out = c.output<ImageRGBA>(spec);
           out = b == 1 ? ImageRGBA(sw, sh, glm::vec4(0.0f)) : c.input<ImageRGBA>(spec_in);
           trace::shade_hits(c.executor(), *scene, c.input<trace::SecondaryRays>(rays),
                             c.input<trace::HitStream>(hits), c.input<ShadowHits>(shadow), out);
         });
    shade.reads<trace::SecondaryRays>(rays).reads<trace::HitStream>(hits).reads<ShadowHits>(shadow)
        .writes<ImageRGBA>(spec).param("bounce", b)
        .describe("the hits shaded with the shared model (environment on a miss), weighted and added to the "
                  "specular layer (ROGER §3.5)");
    if (b > 1) shade.reads<ImageRGBA>(spec_in);
  }

  const std::string last = "specular_" + std::to_string(bounces);
  add_output_passes(g, f, last);
}

}  // namespace speculum::pipeline
