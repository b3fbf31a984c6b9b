// The passes every feed-forward technique's frame shares: the surface passes before its
// specular layer (environment, shadow_map, visibility, gbuffer, direct_light) and the output
// passes after it (composite, resolve, tonemap). A recipe adds these and its own
// specular-layer passes in between.
#pragma once

#include <string>

#include "apps/techniques/frame_settings.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"

namespace speculum::pipeline {

// What a technique reads in the shared passes (shown by `inspect`); empty: the pass's own text.
struct SurfacePassNotes {
  std::string visibility;
  std::string gbuffer;
  std::string shadow_map;
};

struct SurfaceResources {
  par::Resource<raster::EnvironmentMap> environment;
  par::Resource<raster::ShadowMaps> shadow_maps;
  par::Resource<raster::VisibilityBuffer> visibility;  // width·k × height·k
  par::Resource<raster::GBuffer> gbuffer;
  par::Resource<ImageRGBA> direct;
};

// environment → shadow_map → visibility → gbuffer → direct_light.
SurfaceResources add_surface_passes(par::Graph& graph, const Scene* scene,
                                    const FrameSettings& settings,
                                    const SurfacePassNotes& notes = {});

// The reflector maps of a technique whose maps only the camera's samples read: none for
// reflectors the camera does not see, only the faces those samples reach, and with
// `by_direction` (looked up along a direction, envmap_reflect; otherwise searched,
// distance_map_reflect with `lobe_directions` sub-lobes) each sized from its reflector's
// footprint in the G-buffer (raster/reflector_maps.h MapSizing).
inline raster::MapSizing camera_read_maps(bool by_direction, int lobe_directions = 8) {
  raster::MapSizing m;
  m.from_footprint = by_direction;
  m.skip_unseen = true;
  m.reads = by_direction ? raster::MapSizing::Reads::direction : raster::MapSizing::Reads::search;
  m.lobe_directions = lobe_directions;
  return m;
}

// Maps searched before their colour is shaded (shade_reflector_maps, where the searches
// read): their distances alone, on every face (bounding the faces searches reach costs more
// than rendering the few it leaves out), each face's visibility kept. `skip_unseen`: no map
// for a reflector the camera does not see (when only the camera's samples search them).
inline raster::MapSizing searched_distance_maps(bool skip_unseen) {
  raster::MapSizing m;
  m.skip_unseen = skip_unseen;
  m.colour_read = false;
  m.keep_visibility = true;
  return m;
}

// composite (direct + specular) → resolve (k×k) → tonemap.
FrameOutputs add_output_passes(par::Graph& graph, const FrameSettings& settings,
                               const par::Resource<ImageRGBA>& direct,
                               const par::Resource<ImageRGBA>& specular);

}  // namespace speculum::pipeline
