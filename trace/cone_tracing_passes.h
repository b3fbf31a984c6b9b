// The passes of ROGER ch.5 cone tracing (§5.2) after the pixel cones (whose pass reads the
// G-buffer, so it lives in apps/techniques/gbuffer_rays.h): the ray hierarchy over the cones,
// the exact coverage of every surviving (cone, triangle) pair with the n nearest kept, their
// front-to-back blend as one generation of layers (shaded, shadowed and bounced by the ray
// hierarchy's passes), and the gather of the layers into the specular layer.
#pragma once

#include "core/image.h"
#include "core/scene.h"
#include "parallel/graph_node.h"
#include "trace/cone_tracing.h"
#include "trace/ray_hierarchy_passes.h"

namespace speculum::trace {

// Pass "cone_hierarchy": the ray hierarchy with cone leaves.
struct ConeHierarchyPass {
  static constexpr const char* description =
      "Screen-space quad-tree of cone-spheres over the pixel cones: leaves are cones, the levels "
      "built as for rays (ROGER §5.2.1, §3.3.2).";
  RayHierarchy operator()(par::NodeContext& c, const PixelCones& cones) const {
    RayHierarchy h = build_cone_hierarchy(c.executor(), cones);
    c.count("levels", h.levels);
    return h;
  }
};

// Pass "cone_triangle_coverage": traversal, exact coverage per pair, n nearest per pixel.
struct ConeTriangleCoveragePass {
  static constexpr const char* description =
      "The hierarchy traversed to (cone, triangle) pairs; per pair the exact area of triangle ∩ "
      "cone cross-section and its centroid (8 cases, ROGER §5.2.5); the n nearest kept per pixel "
      "(§5.2.4), overflow counted.";
  const Scene* scene = nullptr;
  int kept = 20;
  HierarchyTraverseOptions options;
  void parameters(par::Params& p) const {
    p.set("kept", kept).set("pair_capacity", options.pair_capacity).set("block", options.block_size);
  }
  ConeHits operator()(par::NodeContext& c, const PixelCones& cones, const RayHierarchy& hierarchy) const {
    HierarchyTraverseStats st;
    ConeHits h = cone_triangle_hits(c.executor(), *scene, cones, hierarchy, kept, options, &st);
    c.count("cone_sphere_tests", st.cone_sphere_tests);
    c.count("candidates", st.candidates);
    c.count("overflow_batches", st.overflow_batches);
    c.count("pairs", h.pairs);
    c.count("hits", h.hits);
    c.count("kept_overflow", h.overflow);
    c.count("max_kept", h.max_count);
    return h;
  }
};

// Pass "cone_blend": the kept hits as one generation of layers, weighted by their
// saturate-blend shares.
struct ConeBlendPass {
  static constexpr const char* description =
      "Per pixel the kept hits front to back, each adding min(coverage, 1 − accumulated) "
      "(GL_SRC_ALPHA_SATURATE, GL_ONE; ROGER §5.2.4), as one generation of layer rays.";
  const Scene* scene = nullptr;
  SecondaryRays operator()(par::NodeContext& c, const PixelCones& cones, const ConeHits& hits) const {
    HitStream layer_hits;
    SecondaryRays gen = blend_layers(c.executor(), *scene, cones, hits, layer_hits);
    c.count("layers", double(layer_grid(hits).tx) * double(layer_grid(hits).ty));
    c.count("layer_rays", gen.count);
    return gen;
  }
};

// Pass "cone_layer_hits": the hits of the layer generation (the same blend, its hit side).
struct ConeLayerHitsPass {
  static constexpr const char* description =
      "The hits of the layer generation at the centroid of each triangle ∩ cone (ROGER §5.2.3).";
  const Scene* scene = nullptr;
  HitStream operator()(par::NodeContext& c, const PixelCones& cones, const ConeHits& hits) const {
    HitStream layer_hits;
    blend_layers(c.executor(), *scene, cones, hits, layer_hits);
    return layer_hits;
  }
};

// Pass "shadow_rays" of cone tracing: the shadow rays of each pixel's nearest layer traced
// as ray-hierarchy traces them, their result shared by the pixel's farther layers (ROGER
// §5.2.3 shades a triangle's contribution locally; one shadow ray per pixel keeps the cost
// of ray tracing).
struct ConeShadowRaysPass {
  static constexpr const char* description =
      "Shadow rays of each pixel's nearest kept hit, reversed to start at each point light and "
      "traced through their own hierarchy (ROGER §3.3.5); the pixel's farther layers share them.";
  const Scene* scene = nullptr;
  HierarchyTraverseOptions options;
  ShadowHits operator()(par::NodeContext& c, const SecondaryRays& layers, const HitStream& layer_hits,
                        const ConeHits& hits) const {
    HitStream first_hits;
    const SecondaryRays first = first_layer(c.executor(), layers, layer_hits, hits, first_hits);
    const ShadowHits shadows = ShadowRaysPass{scene, options, 0, 0}(c, first, first_hits);
    return spread_first_layer_shadows(c.executor(), shadows, hits);
  }
};

// Pass "cone_gather": the shaded layers summed per pixel plus the environment for the rest.
struct ConeGatherPass {
  static constexpr const char* description =
      "The shaded layers summed per pixel; the coverage the kept hits leave is filled from the "
      "environment along the axis (ROGER §5.2.4, §5.2.6).";
  const Scene* scene = nullptr;
  bool fill_dropped = true;
  void parameters(par::Params& p) const { p.set("fill", fill_dropped ? 1 : 0); }
  ImageRGBA operator()(par::NodeContext& c, const PixelCones& cones, const ConeHits& hits,
                       const ImageRGBA& layers) const {
    return gather_layers(c.executor(), *scene, cones, hits, layers, fill_dropped);
  }
};

// Pass "bounce_rays_2" of cone tracing: the second generation from each pixel's nearest layer.
struct ConeBounceRaysPass {
  static constexpr const char* description =
      "The next generation rebuilt from each pixel's nearest continuing layer, weighted by all its "
      "layers' continuations (ROGER §3.3.5 on the layers of §5.2.4).";
  const Scene* scene = nullptr;
  SecondaryRays operator()(par::NodeContext& c, const SecondaryRays& layers, const HitStream& layer_hits,
                           const ConeHits& hits) const {
    std::uint64_t dropped = 0;
    SecondaryRays next = first_layer_bounce(c.executor(), *scene, layers, layer_hits, hits, &dropped);
    c.count("rays", next.count);
    c.count("merged_layer_continuations", dropped);
    return next;
  }
};

}  // namespace speculum::trace
