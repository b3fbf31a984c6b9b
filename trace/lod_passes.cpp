// The passes of YU's glossy reflections: see lod_passes.h.
#include "trace/lod_passes.h"

namespace speculum::trace {

BvhPtr BvhBuildPass::operator()(par::NodeContext& c) const {
  BvhPtr bvh = cache ? cache->bvh : nullptr;
  if (!bvh) bvh = std::make_shared<const Bvh>(Bvh::build(scene->mesh, c.executor()));
  else c.count("cached");
  if (cache) cache->bvh = bvh;
  c.count("triangles", bvh->triangle_count());
  c.count("nodes", bvh->threaded_nodes().size());
  return bvh;
}

TriangleLightingPtr RadianceBakePass::operator()(par::NodeContext& c, const BvhPtr& bvh) const {
  TriangleLightingPtr lighting = cache ? cache->lighting : nullptr;
  if (!lighting)
    lighting = std::make_shared<const TriangleLighting>(
        bake_triangle_lighting(c.executor(), *scene, *bvh, options));
  else
    c.count("cached");
  if (cache) cache->lighting = lighting;
  return lighting;
}

LodBvhPtr LodBuildPass::operator()(par::NodeContext& c, const BvhPtr& bvh,
                                   const TriangleLightingPtr& lighting) const {
  LodBvhPtr lod = cache ? cache->lod : nullptr;
  if (!lod) lod = std::make_shared<const LodBvh>(build_lod_bvh(*bvh, lighting->radiance, &c.executor()));
  else c.count("cached");
  if (cache) cache->lod = lod;
  c.count("proxy_textures", static_cast<double>(lod->proxy_texels.size() / (kProxyGrid * kProxyGrid)));
  return lod;
}

LodHits LodTracePass::operator()(par::NodeContext& c, const BvhPtr& bvh, const LodBvhPtr& lod,
                                 const GlossyRays& rays) const {
  LodHits hits;
  LodCounters k;
  closest_hit_lod_stream(*bvh, *lod, rays.rays, rays.solid_angle, options, hits, c.executor(), &k);
  c.count("rays", k.traversal.rays);
  c.count("nodes_visited", k.traversal.nodes_visited);
  c.count("triangle_tests", k.traversal.triangle_tests);
  c.count("lod_stops", k.lod_stops);
  c.count("proxy_hits", k.proxy_hits);
  return hits;
}

ImageRGBA HitRadiancePass::operator()(par::NodeContext& c, const LodBvhPtr& lod,
                                      const TriangleLightingPtr& lighting, const GlossyRays& rays,
                                      const LodHits& hits) const {
  HitRadianceStats st;
  ImageRGBA specular = glossy_reflection(c.executor(), *scene, *lod, *lighting, rays, hits, &st);
  c.count("triangle_hits", st.triangle_hits);
  c.count("proxy_hits", st.proxy_hits);
  c.count("misses", st.misses);
  return specular;
}

}  // namespace speculum::trace
