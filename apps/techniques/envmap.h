// Pipeline recipes: how raster/ (and later trace/) nodes are wired into a job graph for one
// technique. Each recipe reads like the list of its passes (STYLE.md, pbrt-v4 wavefront).
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph.h"

namespace speculum::pipeline {

struct FrameSettings {
  int width = 640;
  int height = 480;
  int supersample = 1;  // k: k×k samples per pixel (feed-forward techniques)
  int spp = 1;          // samples per pixel as asked (= k² for feed-forward techniques)
  Camera camera;
  std::uint32_t seed = 0;
  int shadow_map_size = 512;
  int cube_map_size = 256;   // per-reflector dynamic environment maps
  int environment_size = 0;  // 0: from the environment image
  float exposure = 1.0f;
  // Technique parameters (each technique reads the ones it documents; `render` sets them
  // from --alpha, --bounces and the repeatable --param name=value).
  float alpha = 0.0f;  // yu-lod: LOD threshold of YU eq.7; 0: LOD off
  int bounces = 1;     // ray-hierarchy and recursive techniques: specular bounces
  std::map<std::string, double> params;
  // params[name] when given, else `fallback`.
  double param(const std::string& name, double fallback) const {
    const auto it = params.find(name);
    return it == params.end() ? fallback : it->second;
  }
};

// The graph's resource names that callers read back.
inline constexpr const char* kRadiance = "radiance";      // ImageRGBA, linear, width × height
inline constexpr const char* kDisplay = "display";        // ImageRGBA, tone-mapped

// --technique envmap (SURVEY §3.1):
//   environment → shadow_map → visibility → gbuffer → reflector_cube_maps → direct_light
//   → envmap_reflect → composite → resolve → tonemap
// The scene pointer must outlive the graph's runs.
void add_envmap_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

// --technique reference: the reference tracer (trace/reference_tracer.h) → tonemap.
void add_reference_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings);

}  // namespace speculum::pipeline
