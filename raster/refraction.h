// The `refraction` node (SURVEY §4.4): refractor samples of the camera G-buffer follow the
// refracted ray — single interface (T1 looked up in the environment distance map), double
// interface by Wyman's two-face method (back-face normal + depth pass, thickness
// interpolation, exit normal from the back-face buffer), or distance impostors (the exit
// found by searching the refractor's own normal + distance cube) — then leave it (or are
// totally internally reflected) and look the outgoing ray up in the colour + distance
// cube map around the refractor (reflector_maps.h) with the localized search of
// distance_map_search.h. Non-refractor samples keep the given specular layer.
#pragma once

#include <cstdint>
#include <vector>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/distance_map_search.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/refraction_impostor.h"
#include "raster/visibility.h"

namespace speculum::raster {

// --param method=0|1|2.
enum class RefractionMethod : int { SingleInterface = 0, TwoFace = 1, DistanceImpostor = 2 };

// What a sample's refracted path did (for tests and counters).
enum class RefractionOutcome : std::uint8_t { None = 0, Refracted = 1, TotalInternal = 2, NoExit = 3 };

// The back faces of the refractors seen from the camera (cull front faces, every other
// object excluded): position and outward normal per sample — the two-face method's pass.
GBuffer render_refractor_back_faces(par::Executor& executor, const Scene& scene,
                                    const Camera& camera, int width, int height);

struct RefractionInputs {
  const GBuffer* front = nullptr;             // the camera G-buffer
  const VisibilityBuffer* front_vis = nullptr;  // its triangles and barycentrics (two-face d_N)
  const TriangleMesh* mesh = nullptr;
  Camera camera;
  const ReflectorMaps* maps = nullptr;        // colour + distance cubes around each refractor
  const EnvironmentMap* env = nullptr;        // for refractors without a cube
  const GBuffer* back = nullptr;              // two-face: render_refractor_back_faces
  const std::vector<float>* vertex_thickness = nullptr;  // two-face: d_N per mesh vertex
  const RefractorImpostors* impostors = nullptr;          // distance impostors
};

struct RefractionOptions {
  RefractionMethod method = RefractionMethod::TwoFace;
  DistanceSearchOptions environment_search;  // outgoing rays in the environment cube
  DistanceSearchOptions exit_search;         // impostors: the exit inside the refractor
};

struct RefractionLayer {
  ImageRGBA specular;
  Buffer2D<std::uint8_t> outcome;  // RefractionOutcome per sample
  // Where the path leaves the refractor and in which direction (refractor samples only;
  // single interface: P1 and T1): what the slab and prism tests measure.
  Buffer2D<glm::vec3> exit_point, exit_direction;
  std::uint64_t refracted = 0, total_internal = 0, no_exit = 0, exit_normal_fallbacks = 0;
};

// `specular` is the layer of every other sample (e.g. envmap_reflect's); refractor samples
// are replaced by F1·L(P1, R1) + (1 − F1)·base·transmission-weighted exit radiance:
// (1 − F2)·base·L(P2, T2) + F2·L(P2, R2) (R2 the internal reflection, looked up as if it
// left at P2: one internal bounce, no further interfaces).
RefractionLayer refract_layer(par::Executor& executor, const RefractionInputs& in,
                              const RefractionOptions& options, const ImageRGBA& specular);

// The tiles of the refractors' maps whose colour refract_layer reads, marked into `tiles`
// (per map of in.maps, from tile_mask_for_reads; in.maps needs only its distances): the same
// paths and searches, each search's colour read marked (its level-0 bilinear taps) instead of
// made. Shading a refractor's map on those tiles alone gives refract_layer the same bytes.
// Launch "refraction_reads.mark".
void mark_refraction_reads(par::Executor& executor, const RefractionInputs& in, const RefractionOptions& options,
                           std::vector<CubeTileMask>& tiles);

using VertexThickness = std::vector<float>;  // d_N per mesh vertex (two-face method)

// Pass "back_faces": render_refractor_back_faces at the camera's sample grid.
struct RefractorBackFacesPass {
  static constexpr const char* description =
      "Refractors alone, front faces culled: back-face position (d_V) and normal N2 per sample "
      "(two-face method, SURVEY §4.4).";
  const Scene* scene = nullptr;
  Camera camera;
  int width = 0, height = 0;
  void parameters(par::Params& p) const { p.set("width", width).set("height", height); }
  GBuffer operator()(par::NodeContext& c) const;
};

// Pass "refraction_reads": mark_refraction_reads on the maps' distances, so that the maps'
// colour is shaded where the refraction pass will read it.
struct RefractionReadsPass {
  static constexpr const char* description =
      "The refracted paths of the refraction pass traced ahead in the maps' distances alone: "
      "the tiles of the refractors' maps whose colour they will read (SURVEY §4.4).";
  const Scene* scene = nullptr;
  Camera camera;
  RefractionOptions options;
  void parameters(par::Params& p) const { p.set("method", static_cast<int>(options.method)); }
  std::vector<CubeTileMask> operator()(par::NodeContext& c, const GBuffer& gbuffer, const VisibilityBuffer& visibility,
                                       const ReflectorMaps& maps, const GBuffer* back, const VertexThickness* thickness,
                                       const RefractorImpostors* impostors) const;
};

// Pass "refraction": the refractor samples of the specular layer replaced by refract_layer's.
// `back` and `thickness` are bound for the two-face method, `impostors` for distance impostors.
struct RefractionPass {
  static constexpr const char* description =
      "Refractor samples: T1 at the front face, exit by the chosen method, refract out or total "
      "internal reflection, outgoing rays searched in the environment distance map; exact "
      "Fresnel at both interfaces (SURVEY §4.4).";
  const Scene* scene = nullptr;
  Camera camera;
  RefractionOptions options;
  void parameters(par::Params& p) const {
    p.set("method", static_cast<int>(options.method))
        .set("linear_steps", options.environment_search.linear_steps)
        .set("secant_steps", options.environment_search.secant_steps);
  }
  ImageRGBA operator()(par::NodeContext& c, const GBuffer& gbuffer, const VisibilityBuffer& visibility,
                       const ReflectorMaps& maps, const EnvironmentMap& environment,
                       const ImageRGBA& specular, const GBuffer* back,
                       const VertexThickness* thickness, const RefractorImpostors* impostors) const;
};

}  // namespace speculum::raster
