// The `shadow_map` node: one distance map per light — a distance cube around point and
// spot lights, one far perspective face along a directional light — and the filtered
// (3×3 percentage-closer) shadow test the `direct_light` node uses.
#pragma once

#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "core/scene.h"
#include "core/vec3_lanes.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"

namespace speculum::raster {

struct ShadowMap {
  LightType type = LightType::Point;
  int size = 0;
  CubeMap cube;               // point and spot lights: distance from the light position (a
                              // spot light's: only the faces its cone reaches, the others +inf)
  unsigned faces = 0x3fu;     // bit f: cube face f rendered
  Camera camera;              // directional lights: the far camera along the light
  glm::mat4 view_projection{1.0f};
  ImageF distance;            // directional: |y − camera.eye|

  // Fraction of the 3×3 PCF taps that see point p (unit normal n, unit direction to the
  // light l) lit. Against self-shadowing the lookup point moves off the surface along n by
  // 2·sin θ texel footprints (θ between n and l; the footprint is one texel's world width
  // at p), and the depth test allows one footprint: a plane is lit at every incidence,
  // and light leaks at most about one footprint under an occluder touching the receiver.
  // Asked only where the light reaches p (sample_light's irradiance is not zero).
  float visibility(const glm::vec3& p, const glm::vec3& n, const glm::vec3& l) const;
  // The same for the points of eight in lanes whose bit is set in `lanes`, into out[j] (the
  // others' left as they were).
  void visibility_lanes(const Vec3Lanes<8>& p, const Vec3Lanes<8>& n, const Vec3Lanes<8>& l, unsigned lanes,
                        float* out) const;

  // Where visibility reads: the texel its 3×3 taps are centred on and the biased distance
  // they are compared with (img null: no tap, the point is lit).
  struct Taps {
    const ImageF* img = nullptr;
    int cx = 0, cy = 0;
    float biased = 0.0f;
  };
  Taps taps(const glm::vec3& p, const glm::vec3& n, const glm::vec3& l) const;
  // taps for the points of eight in lanes whose bit is set in `lanes`, into out[j]: a cube
  // map's (point and spot lights) share their arithmetic in lanes, with per lane the
  // operations of taps in its order (the same bits); a directional map's run one by one.
  void taps_lanes(const Vec3Lanes<8>& p, const Vec3Lanes<8>& n, const Vec3Lanes<8>& l, unsigned lanes, Taps* out) const;
  // The fraction of the taps at least `biased` away.
  float filtered(const Taps& t) const;
};

using ShadowMaps = std::vector<ShadowMap>;

// One map per scene light, in light order.
std::vector<ShadowMap> render_shadow_maps(par::Executor& executor, const Scene& scene,
                                          int size = 512);

// Pass "shadow_map": one distance map per light.
struct ShadowMapPass {
  static constexpr const char* description =
      "One distance map per light (a cube around point and spot lights, one far face for a "
      "directional light), read by the 3×3 PCF shadow test of direct_light (SURVEY §4 distance maps).";
  const Scene* scene = nullptr;
  int size = 512;
  void parameters(par::Params& p) const { p.set("size", size); }
  ShadowMaps operator()(par::NodeContext& c) const;
};

}  // namespace speculum::raster
