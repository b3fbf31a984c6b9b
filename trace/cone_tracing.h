// ROGER ch.5 cone tracing over the ray hierarchy (§5.2): one cone per pixel whose apex
// angle holds the pixel's footprint reflected off a sphere of the surface's mean curvature
// and the material's glossy lobe (§5.2.2), the ray hierarchy built over these cones (§5.2.1),
// the exact coverage of each surviving (cone, triangle) pair (§5.2.5), the n nearest kept per
// pixel and blended front to back with saturate semantics, the rest from the environment
// (§5.2.4, §5.2.6). Kernels over core types only; the recipe in apps/ wires them to the
// G-buffer.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "trace/hierarchy_traverse.h"
#include "trace/ray_hierarchy.h"
#include "trace/secondary_rays.h"
#include "trace/traversal.h"

namespace speculum::trace {

struct PixelConeOptions {
  float footprint = 1.0f;     // scale of the primary (pixel) cone; 0: no anti-aliasing
  float gloss_angle = -1.0f;  // θ_g for every reflecting pixel (rad); < 0: from the material
  float lobe_energy = 0.5f;   // the glossy cone holds this fraction of the Phong lobe
  float far_blur = 0.5f;      // far plane where θ_g blurs by this fraction of the scene
                              // radius; 0: no far plane
  float scene_radius = 1.0f;
};

// One cone per pixel (row-major width × height): the axis is the reflected (or refracted)
// ray of secondary_rays with its weight; a pixel whose radius and angle are both 0 is a ray.
struct PixelCones {
  SecondaryRays axes;
  std::vector<float> radius;         // cross-section radius at the axis origin
  std::vector<float> angle;          // leaf half-angle: reflected pixel cone + glossy angle
  std::vector<float> near, far;      // axial distances of the near and far planes
  std::vector<std::uint32_t> self;   // the pixel's own triangle (never its own occluder)
  std::uint64_t cones = 0;           // pixels traced as cones
  std::uint64_t ray_fallbacks = 0;   // concave spots whose reflected cone would be a double cone
  std::uint64_t refraction_rays = 0; // refracted pixels, traced as rays
  std::uint64_t horizon_clamped = 0; // cones narrowed to stay above the surface's tangent plane
};

// The cones of a G-buffer's planes (ROGER §5.2.2): the primary cone of pixel (x, y) has the
// pixel's solid angle (half-angle √(Ω/π), Ω = s² cos³θ for a pinhole of pixel pitch s at
// unit distance), times `footprint`; its footprint radius at the surface is w = D tan β. The
// surface is a sphere of the pixel's mean curvature κ (> 0 convex): in the plane of incidence
// the reflected half-angle is β + 2κw / cos θ_i, across it β + 2κw cos θ_i (the normal turns
// by κ per unit length and reflection doubles it); the circular cone takes their mean excess,
// α_r = β + 2κw. Where the in-plane angle is negative the reflected rays cross (a double
// cone, ROGER Fig.5.3): that pixel is traced as a ray and counted. The glossy angle θ_g holds
// `lobe_energy` of the normalized Phong lobe of the material's exponent n,
// cos θ_g = (1 − E)^(1/(n+1)); the leaf angle is α_r + θ_g, narrowed to half the axis's
// elevation above the tangent plane (the lobe's part below the horizon does not reflect: the
// direction dependence of §5.2.2). The near plane is where the cone leaves the reflector's
// tangent plane (with a margin of a quarter of the elevation for the facets' tilt), the far
// plane far_blur · scene radius / tan θ_g (§5.2.6). Kernel "pixel_cones".
PixelCones pixel_cones(par::Executor& executor, const Buffer2D<glm::vec3>& position,
                       const Buffer2D<glm::vec3>& normal, const SurfacePlane& surface,
                       const IdBuffer& object, const IdBuffer& triangle, const ImageF& curvature,
                       const Camera& camera, const PixelConeOptions& options);

// The n nearest hits of every pixel's cone, sorted by (distance, triangle): slot
// [pixel · kept + j] for j < count[pixel].
struct ConeHits {
  int width = 0, height = 0, kept = 0;
  std::vector<float> distance, coverage, u, v;
  std::vector<std::uint32_t> triangle;
  std::vector<std::uint32_t> count;  // hits kept per pixel (<= kept)
  std::vector<std::uint32_t> total;  // hits found per pixel (beyond kept: overflow)
  std::vector<float> dropped;        // summed coverage of the hits dropped per pixel
  std::uint64_t pairs = 0;           // (cone, triangle) pairs tested exactly
  std::uint64_t hits = 0;            // pairs with a non-zero coverage
  std::uint64_t overflow = 0;        // hits dropped because a pixel already kept n nearer ones
  std::uint32_t max_count = 0;
};

// The hierarchy over the cones (leaves: sphere of radius `radius` at the axis origin swept by
// the leaf angle), built and traversed by the ray hierarchy's code.
RayHierarchy build_cone_hierarchy(par::Executor& executor, const PixelCones& cones);

// Traverses the cone hierarchy (hierarchy_candidates) and intersects every surviving pair:
// a ray leaf by the watertight test (coverage 1 at its hit), a cone leaf by
// cone_triangle_coverage (§5.2.5) on the triangles that face its origin (a closed surface's
// back faces, hidden behind its front faces, would add its coverage twice in the blend). Each batch's hits are grouped by pixel (stable
// partition) and merged into the pixel's n nearest (kernels "cone_triangle_coverage",
// "cone_hits_compact", "cone_hits_partition", "cone_keep_nearest"): the kept set is the
// same whatever the batches.
ConeHits cone_triangle_hits(par::Executor& executor, const Scene& scene, const PixelCones& cones,
                            const RayHierarchy& hierarchy, int kept, const HierarchyTraverseOptions& options,
                            HierarchyTraverseStats* stats = nullptr);

// The kept hits laid out as one generation on a stacked grid: layer j of pixel (x, y) at
// ((y·ty + j / tx) · width·tx + x·tx + j % tx), tx × ty >= the most hits any pixel kept, so a
// pixel's layers are neighbours (the hierarchies over the layers' shadow and bounce rays
// keep their screen coherence). With one layer it is the pixel grid itself.
struct LayerGrid {
  int width = 0, height = 0, tx = 1, ty = 1;
  std::size_t index(std::size_t pixel, std::uint32_t layer) const {
    const std::size_t x = pixel % std::size_t(width), y = pixel / std::size_t(width);
    return (y * std::size_t(ty) + layer / std::uint32_t(tx)) * std::size_t(width) * std::size_t(tx) +
           x * std::size_t(tx) + layer % std::uint32_t(tx);
  }
};
LayerGrid layer_grid(const ConeHits& hits);

// Front-to-back saturate blending (ROGER §5.2.4, GL_SRC_ALPHA_SATURATE, GL_ONE): hit j of a
// pixel adds min(coverage_j, 1 − accumulated) of its colour. Returns the generation whose
// layer j carries that share in its weight (axis weight × share), its ray towards the hit's
// centroid point (a ray leaf keeps its own ray), and the hits themselves in `layer_hits`.
// Kernel "cone_blend".
SecondaryRays blend_layers(par::Executor& executor, const Scene& scene, const PixelCones& cones,
                           const ConeHits& hits, HitStream& layer_hits);

// The specular layer: the layers' shaded radiance summed per pixel in layer order, then the
// uncovered rest 1 − accumulated filled: with `fill_dropped`, first by the hits dropped
// beyond the n nearest (their saturate share min(dropped coverage, rest), in the mean colour
// of the kept hits: their coverage is known, their colour is not), then by the axis weight
// times the environment along the axis (§5.2.4's filling colour). Kernel "cone_gather".
ImageRGBA gather_layers(par::Executor& executor, const Scene& scene, const PixelCones& cones,
                        const ConeHits& hits, const ImageRGBA& layers, bool fill_dropped);

// Layer 0 (each pixel's nearest kept hit) of the layer generation, on the pixel grid.
// Kernel "cone_first_layer".
SecondaryRays first_layer(par::Executor& executor, const SecondaryRays& layers, const HitStream& layer_hits,
                          const ConeHits& hits, HitStream& first_hits);

// Shadow hits of layer 0 (per light, on the pixel grid) spread to every layer of the pixel:
// the layers of a pixel share the shadow of its nearest hit. Kernel "cone_shadow_spread".
std::vector<HitStream> spread_first_layer_shadows(par::Executor& executor, const std::vector<HitStream>& first,
                                                  const ConeHits& hits);

// The next generation from the layers' hits, on the pixel grid: each pixel continues along
// the continuation of its nearest layer that has one, weighted by the sum of all its layers'
// continuation weights (its farther specular layers follow the nearest one's path); the
// number of continuations merged so is counted in `dropped`. With one layer it is
// bounce_rays itself. Kernel "cone_first_layer".
SecondaryRays first_layer_bounce(par::Executor& executor, const Scene& scene, const SecondaryRays& layers,
                                 const HitStream& layer_hits, const ConeHits& hits, std::uint64_t* dropped);

}  // namespace speculum::trace
