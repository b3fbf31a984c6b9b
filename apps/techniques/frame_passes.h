// The passes every feed-forward technique's frame shares: the surface passes before its
// specular layer (environment, shadow_map, visibility, gbuffer, direct_light), the per-reflector
// colour + distance cube maps, and the output passes after it (composite, resolve, tonemap).
// A recipe adds these and its own specular-layer nodes in between (STYLE.md: a recipe reads
// like its list of passes).
#pragma once

#include <string>

#include "apps/techniques/envmap.h"

namespace speculum::pipeline {

// What a technique reads in the shared passes (shown by `inspect`); empty: the generic text.
struct SurfacePassNotes {
  std::string visibility;
  std::string gbuffer;
  std::string shadow_map;
};

// environment → "environment", shadow_map → "shadow_maps", visibility → "visibility" (at
// width·k × height·k), gbuffer → "gbuffer", direct_light → "direct".
void add_surface_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings,
                        const SurfacePassNotes& notes = {});

// reflector_cube_maps → "reflector_maps": per specular object a colour + distance cube map
// at its centre, the object itself left out (SURVEY §3.1, §4.2).
void add_reflector_cube_maps_pass(par::Graph& graph, const Scene* scene,
                                  const FrameSettings& settings, const std::string& description);

// composite ("direct" + `specular`) → "samples", resolve (k×k) → kRadiance, tonemap → kDisplay.
void add_output_passes(par::Graph& graph, const FrameSettings& settings,
                       const std::string& specular = "specular");

}  // namespace speculum::pipeline
