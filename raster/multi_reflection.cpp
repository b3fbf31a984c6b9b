// Inter-object multiple reflections by rounds of cube-map re-rendering: see multi_reflection.h.
#include "raster/multi_reflection.h"

#include <glm/geometric.hpp>

#include "raster/composite.h"
#include "raster/direct_light.h"

namespace speculum::raster {

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
