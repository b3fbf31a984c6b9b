// The `environment` node: the scene's environment (equirect image or constant) resampled
// into a mip-mapped cube map whose coarser levels are glossy-prefiltered with Phong lobes,
// plus its 9 spherical-harmonic coefficients for diffuse ambient light (SURVEY §3.1;
// irradiance from SH after Ramamoorthi & Hanrahan 2001).
#pragma once

#include <array>
#include <vector>

#include <glm/vec3.hpp>

#include "core/scene.h"
#include "core/vec3_lanes.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/cube_map.h"

namespace speculum::raster {

struct EnvironmentMap {
  // levels[l][face]: (size >> l)² texels; level l is prefiltered with a lobe whose
  // half-power angle is one level-l texel (level 0: unfiltered).
  std::vector<std::array<ImageRGBA, kCubeFaces>> levels;
  int size = 0;
  std::array<glm::vec3, 9> sh{};  // radiance SH coefficients, bands 0..2

  // Radiance arriving along -d (d: unit direction leaving the scene) through a Phong lobe of
  // exponent n (≥ 1e6: mirror): trilinear across the levels matching the lobe width.
  glm::vec3 radiance(const glm::vec3& d, float phong_exponent) const;
  // radiance(d[j], phong_exponent[j]) for j < count (1..8), each with the scalar call's bits;
  // directions that read the same levels are looked up together in lanes.
  void radiance8(const glm::vec3* d, const float* phong_exponent, int count, glm::vec3* out) const;
  // Irradiance E(n) on a surface with unit normal n from the SH coefficients.
  glm::vec3 irradiance(const glm::vec3& n) const;
  // irradiance() at eight normals, each lane with its bits.
  Vec3Lanes<8> irradiance8(const Vec3Lanes<8>& n) const;
};

// Mip levels and glossy prefiltering of given level-0 faces (e.g. a rendered cube map's
// colour, for the dynamic environment maps of SURVEY §3.1); SH only when asked. level_count
// > 0 keeps only the finest level_count levels (see levels_for_lobes); 0 builds all.
// `face_mask` (bit f: face f) limits the prefiltering to those faces; the others' coarser
// levels stay black (for a map whose other faces nothing reads: lookup_reach). `tiles` (may
// be null) limits it further to the texels over read tiles (CubeTileMask::covers): a texel
// that a lookup within lookup_reach of a read tile depends on lies over a read tile at every
// level, so what is left black is never read.
// A map prefiltered before from other level-0 faces, whose texels environment_from_faces takes
// instead of prefiltering them again where their inputs are the same: `from`, prefiltered with
// face mask `faces` and tiles `tiles` (null: every texel of those faces), and per level l ≥ 1
// `changed[l]`, tiles (CubeTileMask::covers at level l) over every level-l texel whose inputs
// may differ from `from`'s. A texel `from` prefiltered and no changed tile covers has the
// bits `from` has (prefiltering is a function of a texel's inputs alone).
struct PrefilterReuse {
  const EnvironmentMap* from = nullptr;
  unsigned faces = 0;
  const CubeTileMask* tiles = nullptr;
  std::vector<CubeTileMask> changed;  // [level]; level 0 unused
};

EnvironmentMap environment_from_faces(par::Executor& executor,
                                      std::array<ImageRGBA, kCubeFaces> faces, bool with_sh,
                                      int level_count = 0, unsigned face_mask = 0x3fu,
                                      const CubeTileMask* tiles = nullptr, const PrefilterReuse* reuse = nullptr);

// The angle from the centre of a level-`level` texel (level ≥ 1, on a map of side `size`)
// within which lie the centres of all level-(level − 1) texels its prefiltering reads: the
// step's widest lobe sample and its bilinear taps (clamped ones at a face's edge included).
float prefilter_reach(int size, int level);

// An angle around d within which every level-0 texel lies that radiance(d, n) on a map of
// side `size` with `level_count` levels depends on: the bilinear taps of the levels it reads
// and, below them, the widest sample of every prefiltering step of the cascade (plus one
// texel's diagonal per level). A face no lookup comes that close to is never read.
float lookup_reach(int size, int level_count, float phong_exponent);

// How many levels (finest first) EnvironmentMap::radiance can read on a map of side `size`
// for lobes of exponent ≥ min_phong_exponent (≥ 1e6: mirror, level 0 only; ≤ 0: all of
// them). Prefiltering only those gives the same radiance for those lobes: a reflector whose
// materials are all mirrors needs no prefiltering at all.
int levels_for_lobes(int size, float min_phong_exponent);

// size 0: picks from the image (a quarter of the equirect width, 16..512; 8 for constants).
EnvironmentMap build_environment(par::Executor& executor, const Environment& env, int size = 0);

// Pass "environment": the scene's environment as a mip-mapped cube map (SURVEY §3.1).
struct EnvironmentPass {
  static constexpr const char* description =
      "Resamples the scene environment into a mip-mapped cube map whose coarser levels are "
      "Phong-prefiltered for glossy lookups, plus 9 SH coefficients for ambient light (SURVEY §3.1).";
  const Scene* scene = nullptr;
  int size = 0;  // 0: from the image
  void parameters(par::Params& p) const { p.set("size", size); }
  EnvironmentMap operator()(par::NodeContext& c) const;
};

}  // namespace speculum::raster
