// The passes of ROGER's ray hierarchy: see ray_hierarchy_passes.h.
#include "trace/ray_hierarchy_passes.h"

#include <string>

#include "core/fallback_mask.h"

namespace speculum::trace {

namespace {

// A traversal's counters on its node: pairs per level, tests, candidates, batches, and the
// stage wall times of the thesis's split (not deterministic, like every *_ns counter).
void count_traversal(par::NodeContext& c, const HierarchyTraverseStats& s) {
  for (std::size_t l = 0; l < s.pairs_per_level.size(); ++l)
    c.count("pairs_level_" + std::to_string(l), s.pairs_per_level[l]);
  c.count("cone_sphere_tests", s.cone_sphere_tests);
  c.count("candidates", s.candidates);
  c.count("rays", s.active_rays);
  c.count("level_passes", s.level_passes);
  c.count("overflow_batches", s.overflow_batches);
  c.count("batches", s.batches);
  c.count("hits", s.hits);
  c.count("candidates_per_ray", s.candidates_per_ray());
  c.count("tests_ns", s.tests_ms * 1e6);
  c.count("compaction_ns", s.compaction_ms * 1e6);
  c.count("exact_ns", s.exact_ms * 1e6);
}

}  // namespace

RayHierarchy RayHierarchyPass::operator()(par::NodeContext& c, const SecondaryRays& rays) const {
  RayHierarchy h = build_ray_hierarchy(c.executor(), rays.rays, rays.active, width ? width : rays.width,
                                       width ? height : rays.height);
  c.count("levels", h.levels);
  c.count("leaves", double(h.side) * double(h.side));
  return h;
}

HitStream HierarchyTraversePass::operator()(par::NodeContext& c, const SecondaryRays& rays,
                                            const RayHierarchy& hierarchy) const {
  HitStream hits;
  HierarchyTraverseStats st;
  hierarchy_closest_hits(c.executor(), scene->mesh.positions, scene->mesh.indices, hierarchy,
                         rays.rays, hits, options, &st);
  count_traversal(c, st);
  return hits;
}

ShadowHits ShadowRaysPass::operator()(par::NodeContext& c, const SecondaryRays& rays,
                                      const HitStream& hits) const {
  ShadowHits out(scene->lights.size(), HitStream{});
  for (std::size_t l = 0; l < scene->lights.size(); ++l) {
    const SecondaryRays sr = shadow_rays(c.executor(), *scene, scene->lights[l], rays, hits);
    const RayHierarchy hi = build_ray_hierarchy(c.executor(), sr.rays, sr.active, width ? width : rays.width,
                                                width ? height : rays.height);
    HierarchyTraverseStats st;
    hierarchy_closest_hits(c.executor(), scene->mesh.positions, scene->mesh.indices, hi, sr.rays,
                           out[l], options, &st);
    c.count("shadow_rays", sr.count);
    c.count("shadow_cone_sphere_tests", st.cone_sphere_tests);
    c.count("shadow_candidates", st.candidates);
    c.count("shadowed", st.hits);
  }
  return out;
}

ImageRGBA ShadeHitsPass::operator()(par::NodeContext& c, const SecondaryRays& rays,
                                    const HitStream& hits, const ShadowHits& shadows,
                                    const ImageRGBA* earlier_bounces) const {
  ImageRGBA specular = earlier_bounces ? *earlier_bounces
                                       : ImageRGBA(width ? width : rays.width, width ? height : rays.height,
                                                   glm::vec4(0.0f));
  shade_hits(c.executor(), *scene, rays, hits, shadows, specular);
  // Hits that would reflect or refract again are shaded as they are (direct light and the
  // ambient term) and their specular continuation reads the environment instead of being
  // traced: the depth is exhausted.
  if (last) {
    const SecondaryRays next = bounce_rays(c.executor(), *scene, rays, hits);
    add_environment_fallback(c.executor(), *scene, next, specular);
    c.count("fallback_depth_exhausted", next.count);
    if (c.capturing()) {
      FallbackMask fallbacks(rays.width, rays.height);
      for (std::size_t i = 0; i < next.active.size(); ++i)
        if (next.active[i]) fallbacks.mark(i, Fallback::depth_exhausted);
      c.publish("fallback", std::move(fallbacks));
    }
  }
  return specular;
}

SecondaryRays BounceRaysPass::operator()(par::NodeContext& c, const SecondaryRays& rays,
                                         const HitStream& hits) const {
  SecondaryRays next = bounce_rays(c.executor(), *scene, rays, hits);
  c.count("rays", next.count);
  return next;
}

}  // namespace speculum::trace
