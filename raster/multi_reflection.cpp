// Inter-object multiple reflections by rounds of cube-map re-rendering: see multi_reflection.h.
#include "raster/multi_reflection.h"

#include <algorithm>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/envmap_reflect.h"

namespace speculum::raster {

namespace {

// Gives a G-buffer other object ids (kNoId: uncovered) for the scope: swapped in, and back.
class ObjectsSwapped {
 public:
  ObjectsSwapped(GBuffer& g, IdBuffer& object) : g_(g), object_(object) { std::swap(g_.object, object_); }
  ~ObjectsSwapped() { std::swap(g_.object, object_); }
  ObjectsSwapped(const ObjectsSwapped&) = delete;
  ObjectsSwapped& operator=(const ObjectsSwapped&) = delete;

 private:
  GBuffer& g_;
  IdBuffer& object_;
};

// composite(direct, specular) of a specular image black (0, 0, 0, 1) but at texels
// texel[j], where it holds seen[j]: the same sums, without that image.
ImageRGBA composite_at(par::Executor& executor, const ImageRGBA& direct, const std::vector<std::uint32_t>& texel,
                       const ImageRGBA& seen) {
  ImageRGBA out(direct.width, direct.height);
  executor.parallel_for("composite.add", out.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) out.pixels[i] = glm::vec4(glm::vec3(direct.pixels[i]) + glm::vec3(0.0f), 1.0f);
  });
  executor.parallel_for("composite.add_seen", texel.size(), 8192, [&](std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      const std::size_t i = texel[j];
      out.pixels[i] = glm::vec4(glm::vec3(direct.pixels[i]) + glm::vec3(seen.pixels[j]), 1.0f);
    }
  });
  return out;
}

}  // namespace

ReflectorMaps rerender_reflector_maps(par::Executor& executor, const Scene& scene,
                                      const std::vector<ShadowMap>& shadows,
                                      const EnvironmentMap& env, const ReflectorMaps& current,
                                      const DistanceSearchOptions& options,
                                      DistanceReflectStats* stats,
                                      const std::vector<MapFaceLayers>* layers,
                                      const std::vector<unsigned>* faces_needed) {
  ReflectorMaps next;
  next.map_of_object = current.map_of_object;
  next.centres = current.centres;
  next.faces = current.faces;
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  // Reflectors seen in a cube face are a few texels wide: one search along each lobe's axis.
  DistanceSearchOptions face_search = options;
  face_search.lobe_directions = 1;
  for (std::size_t o = 0; o < current.map_of_object.size(); ++o) {
    const int m = current.map_of_object[o];
    if (m < 0) continue;
    if (layers && static_cast<std::size_t>(m) < layers->size()) {
      const MapFaceLayers& kept = (*layers)[m];
      const CubeMap& was = current.cubes[m];
      CubeMap cube;
      cube.size = was.size;
      cube.centre = was.centre;
      cube.distance = was.distance;
      const unsigned needed = faces_needed && static_cast<std::size_t>(m) < faces_needed->size() ? (*faces_needed)[m] : 0x3fu;
      if (faces_needed) next.faces[m] = needed;
      for (int f = 0; f < kCubeFaces; ++f) {
        ImageRGBA specular(was.size, was.size, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        if (kept.direct[f].size() == 0 || !((needed >> f) & 1u)) {  // left out: black
          cube.colour[f] = std::move(specular);
          continue;
        }
        const ImageRGBA seen = distance_map_reflect(executor, kept.specular[f], env, current, face_search, stats);
        for (std::size_t k = 0; k < kept.specular_texel[f].size(); ++k)
          specular.pixels[kept.specular_texel[f][k]] = seen.pixels[k];
        cube.colour[f] = composite(executor, kept.direct[f], specular);
      }
      next.cubes.push_back(std::move(cube));
      continue;
    }
    // Same cube set-up as render_reflector_maps (reflector_maps.cpp).
    CubeMapOptions opt;
    opt.size = current.cubes[m].size;
    opt.set_depth_range(depth_range);
    opt.raster.excluded_objects.assign(scene.objects.size(), 0);
    opt.raster.excluded_objects[o] = 1;
    next.cubes.push_back(render_cube_map(
        executor, scene, current.centres[m], opt, [&](const GBuffer& g, const Camera& cam, int, const std::vector<std::uint8_t>*) {
          return composite(executor, direct_light(executor, scene, g, cam, shadows, env),
                           distance_map_reflect(executor, g, env, current, face_search, stats));
        }));
  }
  // map_of_object numbers maps in object order, as render_reflector_maps does.
  // Each map keeps the levels its reflector's materials read (render_reflector_maps).
  for (std::size_t k = 0; k < next.cubes.size(); ++k)
    next.maps.push_back(environment_from_faces(executor, next.cubes[k].colour, false,
                                               static_cast<int>(current.maps[k].levels.size()),
                                               k < next.faces.size() ? next.faces[k] : 0x3fu));
  return next;
}

ReflectorMaps render_multi_reflection_maps(par::Executor& executor, const Scene& scene,
                                           const std::vector<ShadowMap>& shadows,
                                           const EnvironmentMap& env, int size,
                                           const GBuffer* camera_view, int rounds,
                                           const DistanceSearchOptions& options,
                                           DistanceReflectStats* stats) {
  std::vector<MapFaceLayers> layers;
  ReflectorMaps maps = render_reflector_maps(executor, scene, shadows, env, size, camera_view, ReflectorSelection::all,
                                             {}, nullptr, {}, rounds > 1 ? &layers : nullptr);
  if (rounds <= 1) return maps;
  // The faces each round's maps need, from the last round back: the last round's are what
  // the camera's searches reach; round k's, what the specular texels of round k+1's needed
  // faces reach with their searches (faces_read, whose bound the culling tests prove).
  const std::size_t count = maps.cubes.size();
  std::vector<std::uint32_t> object_of(count, 0);
  for (std::size_t o = 0; o < maps.map_of_object.size(); ++o)
    if (maps.map_of_object[o] >= 0) object_of[static_cast<std::size_t>(maps.map_of_object[o])] = static_cast<std::uint32_t>(o);
  const auto levels = [&](std::size_t m) { return static_cast<int>(maps.maps[m].levels.size()); };
  std::vector<std::vector<unsigned>> needed(static_cast<std::size_t>(rounds) + 1, std::vector<unsigned>(count, 0x3fu));
  if (camera_view) {
    MapSizing camera_reads;
    camera_reads.reads = MapSizing::Reads::search;
    camera_reads.lobe_directions = options.lobe_directions;
    std::vector<std::vector<std::uint32_t>> samples_of(count);
    for (std::size_t i = 0; i < camera_view->object.size(); ++i) {
      const std::uint32_t o = camera_view->object.pixels[i];
      if (o < maps.map_of_object.size() && maps.map_of_object[o] >= 0)
        samples_of[static_cast<std::size_t>(maps.map_of_object[o])].push_back(static_cast<std::uint32_t>(i));
    }
    for (std::size_t m = 0; m < count; ++m)
      needed[rounds][m] = faces_read(executor, *camera_view, samples_of[m], maps.centres[m], maps.cubes[m].size, levels(m),
                                     camera_reads);
  }
  MapSizing face_reads;  // the faces' texels search with one direction per lobe
  face_reads.reads = MapSizing::Reads::search;
  face_reads.lobe_directions = 1;
  for (int k = rounds - 1; k >= 2; --k)
    for (std::size_t a = 0; a < count; ++a) {
      unsigned mask = 0;
      for (std::size_t b = 0; b < count && mask != 0x3fu; ++b)
        for (int f = 0; f < kCubeFaces && mask != 0x3fu; ++f) {
          if (!((needed[k + 1][b] >> f) & 1u)) continue;
          const GBuffer& texels = layers[b].specular[f];
          std::vector<std::uint32_t> of_a;
          for (std::size_t i = 0; i < texels.object.size(); ++i)
            if (texels.object.pixels[i] == object_of[a]) of_a.push_back(static_cast<std::uint32_t>(i));
          if (!of_a.empty())
            mask |= faces_read(executor, texels, of_a, maps.centres[a], maps.cubes[a].size, levels(a), face_reads);
        }
      needed[k][a] = mask;
    }
  for (int k = 2; k <= rounds; ++k)
    maps = rerender_reflector_maps(executor, scene, shadows, env, maps, options, stats, &layers, &needed[k]);
  return maps;
}

ReflectorMaps render_multi_reflection_maps_where_read(par::Executor& executor, const Scene& scene,
                                                      const std::vector<ShadowMap>& shadows,
                                                      const EnvironmentMap& env, const ReflectorMaps& distances,
                                                      const DistanceSearches& camera, int rounds,
                                                      const DistanceSearchOptions& options,
                                                      DistanceReflectStats* stats) {
  const std::size_t count = distances.cubes.size();
  DistanceSearchOptions face_search = options;  // as rerender_reflector_maps searches
  face_search.lobe_directions = 1;
  const CubeDepthRange depth_range = scene_cube_depth_range(scene);
  CubeMapScratch scratch;
  // Each face's specular texels (the reflectors it shows), compacted, with their texel indices:
  // resolved only where the visible material can be specular (specular, or with a texture that
  // may make it so at some texels: is_specular reads the roughness and the transmission alone,
  // which only the metallic-roughness and transmission textures change).
  std::vector<std::uint8_t> may_be_specular(scene.materials.size(), 0);
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& mat = scene.materials[i];
    may_be_specular[i] = is_specular(surface_params(mat)) || mat.metallic_roughness_texture.valid() ||
                         mat.transmission_texture.valid();
  }
  std::vector<MapFaceLayers> layers(count);
  for (std::size_t m = 0; m < count; ++m) {
    CubeTileMask candidates = tile_mask_for_reads(distances.cubes[m].size, 1);  // one texel a tile
    for (int f = 0; f < kCubeFaces; ++f) {
      const IdBuffer& triangle = distances.cubes[m].visibility[f].triangle;
      std::vector<std::uint8_t>& texels = candidates.tiles[f];
      executor.parallel_for("multi_reflection_maps.candidates", triangle.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t t = triangle.pixels[i];
          texels[i] = t != kNoId && may_be_specular[scene.mesh.triangle_material[t]];
        }
      });
    }
    shade_cube_faces(executor, scene, distances.cubes[m], kept_face_options(distances, m, depth_range, candidates),
                     [&](const GBuffer& g, const Camera&, int face, const std::vector<std::uint8_t>*) {
                       layers[m].specular[face] = specular_texels(executor, g, layers[m].specular_texel[face]);
                       return ImageRGBA{};
                     },
                     &scratch);
  }
  // From the last round back: read[k][m] the tiles of round k's map m that are read (the
  // camera reads the last round), and the searches round k's texels on them make in round k − 1.
  std::vector<std::vector<CubeTileMask>> read(static_cast<std::size_t>(rounds) + 1);
  read[rounds] = camera.tiles;
  // A round's searches on a face: its specular texels' object ids, kNoId for those on unread
  // tiles (empty: none read), swapped into the face's texels to search and look up.
  struct FaceSearches {
    IdBuffer object;
    DistanceSearches found;
  };
  std::vector<std::vector<std::array<FaceSearches, kCubeFaces>>> searched(
      static_cast<std::size_t>(rounds) + 1, std::vector<std::array<FaceSearches, kCubeFaces>>(count));
  DistanceReflectStats st;
  for (int k = rounds; k >= 2; --k) {
    read[k - 1] = tile_masks_for_reads(distances);
    for (std::size_t m = 0; m < count; ++m)
      for (int f = 0; f < kCubeFaces; ++f) {
        GBuffer& texels = layers[m].specular[f];
        const std::vector<std::uint32_t>& texel = layers[m].specular_texel[f];
        if (texel.empty() || !((distances.faces[m] >> f) & 1u)) continue;
        FaceSearches& s = searched[k][m][f];
        s.object = texels.object;
        const std::uint32_t size = static_cast<std::uint32_t>(distances.cubes[m].size);
        constexpr std::size_t kChunk = 4096;
        std::vector<std::uint8_t> any_in(par::Executor::chunk_count(texel.size(), kChunk), 0);
        executor.parallel_for("multi_reflection_maps.read_texels", texel.size(), kChunk, [&](std::size_t begin, std::size_t end) {
          for (std::size_t j = begin; j < end; ++j) {
            const int x = static_cast<int>(texel[j] % size), y = static_cast<int>(texel[j] / size);
            if (read[k][m].covers(f, 0, x, y)) any_in[begin / kChunk] = 1;
            else s.object.pixels[j] = kNoId;
          }
        });
        if (std::find(any_in.begin(), any_in.end(), std::uint8_t(1)) == any_in.end()) {
          s.object = IdBuffer{};
          continue;
        }
        // A texel's searches are the same in every round (the same distances): those the next
        // round searched too are taken from it.
        const FaceSearches* later = k < rounds ? &searched[k + 1][m][f] : nullptr;
        const ObjectsSwapped round_texels(texels, s.object);
        s.found = later && later->object.width > 0
                      ? distance_map_search_reusing(executor, texels, distances, face_search, later->object,
                                                    later->found, &read[k - 1])
                      : distance_map_search(executor, texels, distances, face_search, nullptr, &read[k - 1]);
        st += s.found.stats;
      }
  }
  // Round 1, and the direct light of every tile any round reads (the same in every round).
  std::vector<CubeTileMask> any_round = read[1];
  for (int k = 2; k <= rounds; ++k) merge_reads(any_round, read[k]);
  std::vector<std::array<ImageRGBA, kCubeFaces>> direct(count);
  ReflectorMaps maps;
  maps.map_of_object = distances.map_of_object;
  for (std::size_t m = 0; m < count; ++m) {
    std::array<ImageRGBA, kCubeFaces> colour = shade_cube_faces(
        executor, scene, distances.cubes[m], kept_face_options(distances, m, depth_range, any_round[m]),
        [&](const GBuffer& g, const Camera& cam, int face, const std::vector<std::uint8_t>* texels) {
          direct[m][face] = direct_light(executor, scene, g, cam, shadows, env, texels);
          // Other reflectors seen in round 1's maps show the environment (render_reflector_maps).
          return composite(executor, direct[m][face], envmap_reflect(executor, g, env));
        },
        &scratch);
    maps.maps.push_back(environment_from_faces(executor, colour, false, distances.levels[m],
                                               distances.faces[m] & read[1][m].faces(), &read[1][m]));
    maps.cubes.emplace_back().colour = std::move(colour);
  }
  // Rounds 2 ..: the direct light plus what round k's searches find in round k − 1's maps.
  // A round's map differs from the round before's only where its searches found other colour,
  // so its prefiltered texels whose inputs did not change are taken from that round's.
  std::vector<unsigned> faces_before(count);
  for (std::size_t m = 0; m < count; ++m) faces_before[m] = distances.faces[m] & read[1][m].faces();
  for (int k = 2; k <= rounds; ++k) {
    ReflectorMaps next;
    next.map_of_object = distances.map_of_object;
    for (std::size_t m = 0; m < count; ++m) {
      const int size = distances.cubes[m].size;
      const unsigned faces = distances.faces[m] & read[k][m].faces();
      CubeMap& cube = next.cubes.emplace_back();
      for (int f = 0; f < kCubeFaces; ++f) {
        if (!((faces >> f) & 1u) || direct[m][f].size() == 0) {
          cube.colour[f] = ImageRGBA(size, size, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
          continue;
        }
        FaceSearches& s = searched[k][m][f];
        if (s.object.width > 0) {
          const ObjectsSwapped round_texels(layers[m].specular[f], s.object);
          const ImageRGBA seen = distance_map_lookup(executor, layers[m].specular[f], env, maps, s.found, face_search);
          cube.colour[f] = composite_at(executor, direct[m][f], layers[m].specular_texel[f], seen);
        } else {
          cube.colour[f] = composite_at(executor, direct[m][f], {}, ImageRGBA{});
        }
      }
      const PrefilterReuse reuse =
          prefilter_reuse(executor, cube.colour, faces, &read[k][m], maps.maps[m], faces_before[m], &read[k - 1][m],
                          distances.levels[m]);
      // The last round's faces are the result's colour too; the others' only level 0.
      std::array<ImageRGBA, kCubeFaces> level0 = k == rounds ? cube.colour : std::move(cube.colour);
      next.maps.push_back(environment_from_faces(executor, std::move(level0), false, distances.levels[m], faces, &read[k][m], &reuse));
      faces_before[m] = faces;
    }
    maps = std::move(next);
  }
  for (std::size_t m = 0; m < count; ++m) {
    maps.cubes[m].size = distances.cubes[m].size;
    maps.cubes[m].centre = distances.cubes[m].centre;
    maps.cubes[m].distance = distances.cubes[m].distance;
    maps.faces.push_back(distances.faces[m] & read[rounds][m].faces());
  }
  maps.centres = distances.centres;
  maps.levels = distances.levels;
  maps.refracts = distances.refracts;
  maps.tiles = std::move(read[rounds]);
  if (stats) *stats += st;
  return maps;
}

ReflectorMaps MultiReflectionWhereReadPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                       const EnvironmentMap& environment,
                                                       const ReflectorMaps& distances,
                                                       const DistanceSearches& camera) const {
  DistanceReflectStats st;
  ReflectorMaps maps = render_multi_reflection_maps_where_read(c.executor(), *scene, shadows, environment, distances,
                                                               camera, rounds, search, &st);
  count_maps(c, maps);
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("fallback_search_missed", st.missed);
  return maps;
}

ReflectorMaps MultiReflectionMapsPass::operator()(par::NodeContext& c, const ShadowMaps& shadows,
                                                  const EnvironmentMap& environment,
                                                  const GBuffer& gbuffer,
                                                  const ReflectorMaps* previous) const {
  DistanceReflectStats st;
  ReflectorMaps maps =
      lagged && previous
          ? rerender_reflector_maps(c.executor(), *scene, shadows, environment, *previous, search, &st)
          : render_multi_reflection_maps(c.executor(), *scene, shadows, environment, size, &gbuffer,
                                         lagged ? 1 : rounds, search, &st);
  c.count("cube_maps", maps.cubes.size());
  c.count("searches", st.searches);
  c.count("distance_lookups", st.lookups);
  c.count("fallback_search_missed", st.missed);
  return maps;
}

}  // namespace speculum::raster
