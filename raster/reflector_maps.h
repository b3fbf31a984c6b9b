// Dynamic environment maps (SURVEY §3.1): for every specular object, the scene without it
// rendered into a cube map (colour = direct light + ambient, and distance) around a
// reference point o, then mip-mapped with glossy prefiltering. o is the centre of the
// object's bounding box, except for flat reflectors (smallest box side < 5% of the largest),
// whose box centre may sit under other objects (a floor under a vase): there o is the
// centroid of the reflector's samples in the camera's G-buffer, lifted off the surface by
// 1% of the box diagonal along their mean normal.
#pragma once

#include <functional>
#include <vector>

#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/shadow_map.h"

namespace speculum::raster {

struct ReflectorMaps {
  std::vector<int> map_of_object;     // per object: index into maps, -1 when not a reflector
  std::vector<CubeMap> cubes;         // colour + distance, as rendered
  std::vector<EnvironmentMap> maps;   // the same colour, prefiltered for lookups
  std::vector<glm::vec3> centres;     // reference point o of each map
  const EnvironmentMap* for_object(std::uint32_t object) const {
    if (object >= map_of_object.size() || map_of_object[object] < 0) return nullptr;
    return &maps[map_of_object[object]];
  }
};

enum class ReflectorSelection { all, not_planar_mirrors, refractors };
const char* to_string(ReflectorSelection which);

// Specular objects: at least one triangle's material reflects or refracts
// (is_specular(surface_params(material))).
// `camera_view` (may be null) is the camera's G-buffer, used for flat reflectors.
// `which` selects the reflectors that get a map: every specular object; all but the planar
// mirrors (planar_mirror_plane), for a technique that renders those exactly by another pass;
// or the refractors only, for a technique that traces reflections but not refraction.
// `add_light` (may be empty) adds light to each face's direct light before the composite,
// from the face's G-buffer (the caustics technique gathers its caustics there).
using FaceLight = std::function<ImageRGBA(const GBuffer& face, const ImageRGBA& direct)>;
// Objects flagged in `skip` (indexed by object id; may be null) get no map either: a
// technique that handles them otherwise (vertex-projection's mirrors).
ReflectorMaps render_reflector_maps(par::Executor& executor, const Scene& scene,
                                    const std::vector<ShadowMap>& shadows,
                                    const EnvironmentMap& env, int size = 256,
                                    const GBuffer* camera_view = nullptr,
                                    ReflectorSelection which = ReflectorSelection::all,
                                    const FaceLight& add_light = {},
                                    const std::vector<std::uint8_t>* skip = nullptr);

// Pass "reflector_cube_maps": render_reflector_maps with the camera's G-buffer.
struct ReflectorCubeMapsPass {
  static constexpr const char* description =
      "Per specular object a colour + distance cube map at its reference point, the object "
      "itself left out (SURVEY §3.1, §4.2).";
  const Scene* scene = nullptr;
  int size = 256;
  ReflectorSelection which = ReflectorSelection::all;
  void parameters(par::Params& p) const {
    p.set("size", size);
    p.set("reflectors", to_string(which));
  }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows,
                           const EnvironmentMap& environment, const GBuffer& gbuffer) const;
};

}  // namespace speculum::raster
