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

// The reflector maps of a technique whose maps only the camera's samples read, each along a
// direction (envmap_reflect): none for reflectors the camera does not see, only the tiles of
// the faces those lookups reach, each map sized from its reflector's footprint in the
// G-buffer (raster/reflector_maps.h MapSizing). Searched maps: raster::searched_distance_maps.
inline raster::MapSizing camera_read_maps() {
  raster::MapSizing m;
  m.from_footprint = true;
  m.skip_unseen = true;
  m.reads = raster::MapSizing::Reads::direction;
  return m;
}

// composite (direct + specular) → resolve (k×k) → tonemap.
FrameOutputs add_output_passes(par::Graph& graph, const FrameSettings& settings,
                               const par::Resource<ImageRGBA>& direct,
                               const par::Resource<ImageRGBA>& specular);

}  // namespace speculum::pipeline
