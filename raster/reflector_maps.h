// Dynamic environment maps (SURVEY §3.1): for every specular object, the scene without it
// rendered into a cube map (colour = direct light + ambient, and distance) around a
// reference point o, then mip-mapped with glossy prefiltering. o is the centre of the
// object's bounding box, except for flat reflectors (smallest box side < 5% of the largest),
// whose box centre may sit under other objects (a floor under a vase): there o is the
// centroid of the reflector's samples in the camera's G-buffer, lifted off the surface by
// 1% of the box diagonal along their mean normal.
#pragma once

#include <array>
#include <functional>
#include <limits>
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
  std::vector<EnvironmentMap> maps;   // the same colour, prefiltered for lookups (no levels
                                      // when only distances are read: MapSizing::colour_read)
  std::vector<glm::vec3> centres;     // reference point o of each map
  std::vector<unsigned> faces;        // bit f: face f rendered (the others black, never read)
  std::vector<CubeTileMask> tiles;    // per map: within those faces, the tiles rendered
                                      // (inactive: all; the others black, never read)
  std::vector<int> levels;            // per map: the levels its colour is prefiltered to
  std::vector<std::uint8_t> refracts; // per map: 1 when its object refracts (paths through it
                                      // read its map anywhere)
  const EnvironmentMap* for_object(std::uint32_t object) const {
    if (object >= map_of_object.size() || map_of_object[object] < 0) return nullptr;
    return &maps[map_of_object[object]];
  }
};

// What one map's faces hold before reflections are added: each rendered face's direct light
// (with any added light) and the G-buffer of its covered specular texels, compacted to one
// row, with their texel indices. A later round that re-renders the same map at the same
// point and size (multi-reflection) starts from these instead of rasterizing, resolving and
// lighting the face again: the geometry and the lights have not changed, so neither have they.
struct MapFaceLayers {
  std::array<ImageRGBA, kCubeFaces> direct;  // empty: face not rendered
  std::array<GBuffer, kCubeFaces> specular;
  std::array<std::vector<std::uint32_t>, kCubeFaces> specular_texel;
};

enum class ReflectorSelection { all, not_planar_mirrors, refractors };
const char* to_string(ReflectorSelection which);

// What a frame reads of the maps, when only the camera's samples read them (no other pass
// looks a map up from elsewhere: envmap, distance-map, refraction).
struct MapSizing {
  // A reflector's side is the cap `size` or less: the smallest power of two (at least
  // kMinFootprintSize) whose texels are finer than a quarter of the angle between the
  // reflected directions of neighbouring camera samples, or than an eighth of the glossy
  // lobe's half-power angle when that is coarser — the map holds what the frame can show,
  // and a glossy map, read only through prefiltered levels, is not rendered much finer than
  // the finest level it is read at. The 5 % finest samples of a reflector decide.
  // Only for maps read along a direction (envmap_reflect): a distance-map search reads
  // distances at the points its rays pass, which the reflected directions' rate does not
  // bound (at 160×120 the mirror ball of sphere-in-room: exact specular mae8 4.76 → 7.11). Refractors
  // keep `size` (a lens magnifies what lies behind it beyond the rate of its first refraction).
  bool from_footprint = false;
  // A reflector whose specular materials are all glossy lobes gets the side its sharpest
  // lobe needs: texels under 0.15 of the half-power angle of its sharpest read (kLobeTexelShare
  // in reflector_maps.cpp), from the materials alone, so it holds for every reader of the map
  // (each a sample of the reflector itself reading through its lobe) and for searches too,
  // whose hits the lobe blurs as much as their colour. Mirrors, refractors and roughness
  // textures keep `size`.
  bool from_lobes = false;
  // Reflectors with no camera sample get no map: nothing would read it.
  bool skip_unseen = false;
  // How the camera's samples read a reflector's map; unless `anywhere`, faces that no read
  // comes near (lookup_reach of its lobe, and for a search every direction from the map's
  // centre to the points of its ray) are not rendered or prefiltered. Refractors' maps keep
  // every face.
  enum class Reads { anywhere, direction, search } reads = Reads::anywhere;
  // With Reads::direction: whether a refractor's map is read only where its camera samples
  // look up the reflected and refracted directions at its surface (specular_radiance, as
  // envmap_reflect does), or also by paths through it (the refraction pass's searches), which
  // may go anywhere.
  bool refractors_read_at_surface = false;
  int lobe_directions = 8;  // search: sub-lobe searches per glossy lobe (distance_map_reflect)
  // Whether anything reads the maps' colour. When only their distances are searched (the
  // caustics' photons, SURVEY §6.1), no face is resolved or shaded and nothing is prefiltered:
  // the cubes hold distances alone.
  bool colour_read = true;
  // With colour_read false: each map keeps its faces' visibility, so that its colour can be
  // shaded afterwards by shade_reflector_maps, on the texels its readers turned out to read
  // (a distance-map search knows where it reads colour only once it has searched).
  bool keep_visibility = false;
};

// Maps searched before their colour is shaded (shade_reflector_maps, where the searches
// read): their distances alone, on every face (bounding the faces searches reach costs more
// than rendering the few it leaves out), each face's visibility kept. `skip_unseen`: no map
// for a reflector the camera does not see (when only the camera's samples search them).
// `from_lobes`: glossy reflectors' maps sized by their lobes (when only samples of the
// reflector itself search its map, through its lobe; not a photon's search).
inline MapSizing searched_distance_maps(bool skip_unseen, bool from_lobes) {
  MapSizing m;
  m.skip_unseen = skip_unseen;
  m.from_lobes = from_lobes;
  m.colour_read = false;
  m.keep_visibility = true;
  return m;
}

// Bit f set: face f of a map centred at `centre` is read by the camera samples `samples` of
// one reflector (G-buffer indices) under `sizing.reads`, on a map of side `size` with
// `level_count` levels; exposed for tests.
unsigned faces_read(par::Executor& executor, const GBuffer& camera_view, const std::vector<std::uint32_t>& samples,
                    const glm::vec3& centre, int size, int level_count, const MapSizing& sizing);
constexpr int kMinFootprintSize = 16;

// Marks the tiles of `mask` (mask.size set; tiles sized on first use) that hold a texel centre
// within angle `margin` of unit direction d, on any face. Exposed for tests.
void mark_tiles_near(CubeTileMask& mask, const glm::vec3& d, float margin);

// The tiles of a map of side `size` (a power of two) with `level_count` levels that the
// lookups along R of the camera samples `samples` of one reflector can reach (every texel
// within lookup_reach of a read direction, or the bilinear taps of a lookup at level 0
// alone), for maps read only along R (Reads::direction). A refractor's sample marks the taps
// of its reflected and refracted directions when `refractors_read_at_surface`, else every
// tile. Exposed for tests.
CubeTileMask tiles_read(par::Executor& executor, const GBuffer& camera_view, const std::vector<std::uint32_t>& samples,
                        int size, int level_count, bool refractors_read_at_surface = false);

// An empty mask for the reads of a map of side `size` (a power of two) with `level_count`
// levels: one-texel tiles when level 0 alone is read (bilinear taps), else kTile.
CubeTileMask tile_mask_for_reads(int size, int level_count);
// tile_mask_for_reads for every map of `maps`, in map order (no tile marked).
std::vector<CubeTileMask> tile_masks_for_reads(const ReflectorMaps& maps);

// Marks in a mask (from tile_mask_for_reads) what lookups EnvironmentMap::radiance(d, n) on
// the map read: the bilinear taps of a lookup that reads level 0 alone, else every texel
// within lookup_reach of d. One marker per thread (it keeps per-call state); any number of
// markers may mark one mask at once: a tile is only ever set, so the mask is the same
// whatever marked what. A reach too wide for the face-plane bound is recorded in the mask's
// coarse cells (CubeTileMask::wide): call settle_wide_reads once the markers are done.
class LookupTileMarker {
 public:
  LookupTileMarker(CubeTileMask& mask, int level_count);
  void mark(const glm::vec3& d, float phong_exponent);  // d: any length, non-zero

 private:
  CubeTileMask& mask_;
  int level_count_;
  float last_exponent_ = std::numeric_limits<float>::quiet_NaN(), margin_ = 0.0f;
  bool level0_ = false;
  bool wide_ = false;   // the reach is recorded per coarse cell (settle_wide_reads)
  unsigned whole_ = 0;  // faces found marked whole
  unsigned marks_ = 0;
  // Per face the last rectangle of tiles this marker marked (x0, y0, x1, y1; empty at first):
  // a neighbouring sample's read usually reaches the same tiles, which are then not walked
  // again.
  std::array<std::array<int, 4>, kCubeFaces> last_marked_{};
};

// Marks the tiles within reach of the coarse cells LookupTileMarker recorded in `mask`: a
// tile whose centre is within the cell's reach plus both one's and the other's angular
// radius of a recorded cell's centre (a texel within reach of a direction in the cell can lie
// no farther); then clears the cells. Named launch "tile_marks.settle_wide".
void settle_wide_reads(par::Executor& executor, CubeTileMask& mask);

// Marks in `into` every tile marked in `from` (masks of the same maps, in map order).
void merge_reads(std::vector<CubeTileMask>& into, const std::vector<CubeTileMask>& from);

// What environment_from_faces can take from `from` (prefiltered with face mask `from_faces`
// and tiles `from_tiles`, may be null: every texel) when it prefilters `level_count` levels of
// `faces` with `face_mask` and `tiles`: per level l ≥ 1 the tiles whose level-l texels' inputs
// may differ, grown level by level from the level-0 tiles where `faces` and from's level 0
// differ by prefilter_reach (the texels' own extents and the tiles' radii added), and from
// the texels one map prefilters and the other does not. Named launches
// "environment.changed_texels" and "environment.changed_tiles".
PrefilterReuse prefilter_reuse(par::Executor& executor, const std::array<ImageRGBA, kCubeFaces>& faces,
                               unsigned face_mask, const CubeTileMask* tiles, const EnvironmentMap& from,
                               unsigned from_faces, const CubeTileMask* from_tiles, int level_count);

// 1 for each object with a specular sample in `camera_view` (what `skip_unseen` keeps).
std::vector<std::uint8_t> seen_reflectors(const Scene& scene, const GBuffer& camera_view);

// The side render_reflector_maps gives each object under `from_footprint` (0: the object
// reads no map in this view), capped at `size`; exposed for tests.
std::vector<int> footprint_sizes(par::Executor& executor, const Scene& scene, const GBuffer& camera_view,
                                 int size);

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
// technique that handles them otherwise (vertex-projection's mirrors). `layers` (may be
// null) receives each map's MapFaceLayers, in map order.
ReflectorMaps render_reflector_maps(par::Executor& executor, const Scene& scene,
                                    const std::vector<ShadowMap>& shadows,
                                    const EnvironmentMap& env, int size = 256,
                                    const GBuffer* camera_view = nullptr,
                                    ReflectorSelection which = ReflectorSelection::all,
                                    const FaceLight& add_light = {},
                                    const std::vector<std::uint8_t>* skip = nullptr,
                                    const MapSizing& sizing = {},
                                    std::vector<MapFaceLayers>* layers = nullptr);

// The colour of maps rendered with MapSizing::keep_visibility (`distances`), shaded and
// prefiltered only over `tiles` (one mask per map, from tile_mask_for_reads, marked by the
// readers): per read texel the same bytes as render_reflector_maps with colour. The maps keep
// `distances`' distances, centres and objects; faces with no read tile are left black, and
// no visibility is kept.
// `add_light` as for render_reflector_maps.
ReflectorMaps shade_reflector_maps(par::Executor& executor, const Scene& scene, const std::vector<ShadowMap>& shadows,
                                   const EnvironmentMap& env, const ReflectorMaps& distances,
                                   std::vector<CubeTileMask> tiles, const FaceLight& add_light = {});

// The options shade_cube_faces takes to shade map m of `distances` (rendered with
// keep_visibility) on `tiles` (kept by the caller while they are used): its side, the depth
// range it was rendered with, and the rendered faces that hold a read tile.
CubeMapOptions kept_face_options(const ReflectorMaps& distances, std::size_t m, const CubeDepthRange& depth_range,
                                 const CubeTileMask& tiles);

// The covered specular samples of `g`, compacted to one row in sample order; `texel`
// receives their indices in g. Launches "specular_texels.keep", "specular_texels/..." (the
// compaction) and "specular_texels.gather".
GBuffer specular_texels(par::Executor& executor, const GBuffer& g, std::vector<std::uint32_t>& texel);

// Texels rendered: the texels of the tiles rendered on the faces each map has.
double rendered_texels(const ReflectorMaps& maps);

// A maps node's counters: cube_maps, and cube_texels (rendered_texels).
void count_maps(par::NodeContext& c, const ReflectorMaps& maps);

// The parameters a maps pass shows (`inspect`, profiles).
void map_parameters(par::Params& p, int size, ReflectorSelection which, const MapSizing& sizing);

// Pass "reflector_cube_maps": render_reflector_maps with the camera's G-buffer.
struct ReflectorCubeMapsPass {
  static constexpr const char* description =
      "Per specular object a colour + distance cube map at its reference point, the object "
      "itself left out (SURVEY §3.1, §4.2).";
  const Scene* scene = nullptr;
  int size = 256;
  ReflectorSelection which = ReflectorSelection::all;
  MapSizing sizing;
  void parameters(par::Params& p) const { map_parameters(p, size, which, sizing); }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows,
                           const EnvironmentMap& environment, const GBuffer& gbuffer) const;
};

// Pass "reflector_distance_maps": the maps of ReflectorCubeMapsPass with their distances
// alone (searched_distance_maps: no colour, each face's visibility kept for the colour pass
// after the searches). Nothing in them is lit, so the pass reads neither the shadow maps nor
// the environment and runs beside the shadow pass. Throws std::logic_error for a sizing that
// shades colour.
struct ReflectorDistanceMapsPass {
  static constexpr const char* description =
      "Per specular object the distances of its cube map at its reference point, the object itself "
      "left out, each face's visibility kept for shading its colour later (SURVEY §4.1, §4.2).";
  const Scene* scene = nullptr;
  int size = 256;
  ReflectorSelection which = ReflectorSelection::all;
  MapSizing sizing;
  void parameters(par::Params& p) const { map_parameters(p, size, which, sizing); }
  ReflectorMaps operator()(par::NodeContext& c, const GBuffer& gbuffer) const;
};

// Pass "reflector_cube_maps" after the searches: the colour of maps rendered with
// keep_visibility, shaded and prefiltered only on the tiles the searches read
// (shade_reflector_maps). `Reads` is what recorded them: any type with the per-map
// `tiles` (DistanceSearches, PlanarMirrorViews).
template <class Reads>
struct ReflectorColourPass {
  static constexpr const char* description =
      "Per specular object the colour of its cube map, shaded and prefiltered only where the "
      "searches read it (SURVEY §3.1, §4.2).";
  const Scene* scene = nullptr;
  void parameters(par::Params& p) const { p.set("tiles", "read by the searches"); }
  ReflectorMaps operator()(par::NodeContext& c, const ShadowMaps& shadows, const EnvironmentMap& environment,
                           const ReflectorMaps& distances, const Reads& reads) const {
    ReflectorMaps maps = shade_reflector_maps(c.executor(), *scene, shadows, environment, distances, reads.tiles);
    count_maps(c, maps);
    return maps;
  }
};

}  // namespace speculum::raster
