// What a technique's recipe is given (FrameSettings: size, samples, camera, map sizes, the
// technique's parameters) and what every recipe returns (FrameOutputs: the handles of the
// frame's linear radiance and display image).
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/graph.h"

namespace speculum::pipeline {

struct FrameSettings {
  int width = 640;
  int height = 480;
  int supersample = 1;  // k: k×k samples per pixel (feed-forward techniques)
  int spp = 0;          // samples per pixel as asked (= k² for feed-forward techniques);
                        // 0: the technique's default (Technique::default_spp)
  Camera camera;
  std::uint32_t seed = 0;
  int shadow_map_size = 512;
  int cube_map_size = 256;   // per-reflector dynamic environment maps
  int environment_size = 0;  // 0: from the environment image
  float exposure = 1.0f;
  bool auto_exposure = false;  // meter the frame instead (raster/composite.h meter_exposure)
  float alpha = 0.0f;  // yu-lod: LOD threshold of YU eq.7; 0: LOD off
  int bounces = 0;     // specular bounces of ray-hierarchy, the recursive techniques and the
                       // references; 0: each technique's default (1; reference: 8)
  // The technique's parameters (`--param name=value`). Technique::add_passes fills in the
  // defaults of the technique table and checks the ranges before the recipe runs, so a
  // recipe reads every parameter it declares with param(name).
  std::map<std::string, double> params;
  double param(const std::string& name) const {
    const auto it = params.find(name);
    if (it == params.end())
      throw std::logic_error("technique parameter '" + name + "' is not in its technique's table");
    return it->second;
  }
};

// The handles every recipe returns: linear radiance (width × height) and the tone-mapped
// display image a PNG stores.
struct FrameOutputs {
  par::Resource<ImageRGBA> radiance;
  par::Resource<ImageRGBA> display;
};

// The name of the display resource (the tonemap pass's output), for tools that find it in
// captured outputs.
inline constexpr const char* kDisplay = "tonemap";

}  // namespace speculum::pipeline
