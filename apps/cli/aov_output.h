// `render --aov albedo,normal,...`: the G-buffer fields a denoiser or a compositor reads,
// written as named layers of the output EXR beside the beauty image (R, G, B, A):
//   albedo.R/G/B    base colour (texture applied), 0 on the background
//   normal.X/Y/Z    world-space shading normal, 0 on the background
//   depth.Z         camera-space depth along the view axis (not the ray length), +inf on
//                   the background (what compositors expect of an empty Z sample)
//   position.X/Y/Z  world-space position, 0 on the background
//   roughness.Y     perceptual roughness, 0 on the background
// With k×k supersampling each pixel averages its k² samples, background counting as 0 (so
// edges are antialiased like the beauty, as denoisers want); depth and position come from
// the nearest covered sample instead, since an average of two surfaces' depths is neither.
#pragma once

#include <string>
#include <vector>

#include "core/scene.h"
#include "raster/gbuffer.h"

namespace speculum::cli {

// The layers `--aov` knows, in the order they are written.
const std::vector<std::string>& aov_names();

// Parses "albedo,normal,depth" (any order, no repeats) into layer names; throws InputError
// naming --aov and the known names (with "did you mean") for an unknown one.
std::vector<std::string> parse_aovs(const std::string& list);

// The channels of `aovs` at the output size (the G-buffer's size / k), interleaved, and their
// names "albedo.R", ..., in the order of `aovs`.
struct AovLayers {
  std::vector<std::string> names;
  std::vector<float> data;  // names.size() floats per pixel
};
AovLayers make_aov_layers(const raster::GBuffer& gbuffer, int k, const Camera& camera,
                          const std::vector<std::string>& aovs);

}  // namespace speculum::cli
