// The refraction technique's recipe: see refraction.h. It wires raster/ passes
// with one trace/ kernel (the per-vertex thickness ray cast of the two-face method).
#include "apps/techniques/frame_passes.h"
#include "apps/techniques/refraction.h"

#include "core/error.h"
#include "raster/composite.h"
#include "raster/direct_light.h"
#include "raster/envmap_reflect.h"
#include "raster/environment.h"
#include "raster/gbuffer.h"
#include "raster/reflector_maps.h"
#include "raster/refraction.h"
#include "raster/shadow_map.h"
#include "raster/visibility.h"
#include "trace/bvh.h"
#include "trace/traversal.h"

namespace speculum::pipeline {

using namespace speculum::raster;
using ShadowMaps = std::vector<ShadowMap>;
using Thickness = std::vector<float>;

std::vector<float> refractor_vertex_thickness(const Scene& scene, par::Executor& executor) {
  const TriangleMesh& m = scene.mesh;
  const std::vector<std::uint8_t> refractors = refractor_objects(scene);
  std::vector<std::uint32_t> indices;
  std::vector<std::uint8_t> vertex_of_refractor(m.positions.size(), 0);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t o = m.triangle_object[t];
    if (o >= refractors.size() || !refractors[o]) continue;
    for (int k = 0; k < 3; ++k) {
      indices.push_back(m.indices[3 * t + k]);
      vertex_of_refractor[m.indices[3 * t + k]] = 1;
    }
  }
  std::vector<float> thickness(m.positions.size(), 0.0f);
  if (indices.empty()) return thickness;
  const trace::Bvh bvh = trace::Bvh::build(m.positions, indices, executor);
  const float scale = glm::length(scene.bounds().extent());
  // Per vertex: the bounding-box centre of its refractor.
  std::vector<Bounds> boxes(scene.objects.size());
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (refractors[m.triangle_object[t]])
      for (int k = 0; k < 3; ++k) boxes[m.triangle_object[t]].grow(m.positions[m.indices[3 * t + k]]);
  std::vector<glm::vec3> centre(m.positions.size(), glm::vec3(0.0f));
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    if (refractors[m.triangle_object[t]])
      for (int k = 0; k < 3; ++k) centre[m.indices[3 * t + k]] = boxes[m.triangle_object[t]].center();
  trace::RayStream rays;
  rays.resize(m.positions.size());
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    Ray r;
    // Nudged towards the refractor's centre so rays from corner vertices do not graze
    // the neighbouring faces' edges (convex refractors).
    r.origin = m.positions[v] + 1e-4f * (centre[v] - m.positions[v]);
    r.direction = vertex_of_refractor[v] && v < m.normals.size() ? -m.normals[v] : glm::vec3(0, 0, 1);
    r.tmin = 1e-5f * scale;  // skip the vertex's own triangles
    r.tmax = vertex_of_refractor[v] ? 3.0e38f : 0.0f;
    rays.set(v, r);
  }
  trace::HitStream hits;
  trace::closest_hit_stream(bvh, rays, hits, executor);
  for (std::size_t v = 0; v < m.positions.size(); ++v)
    if (vertex_of_refractor[v] && hits.triangle[v] != trace::kNoHit) thickness[v] = hits.t[v];
  return thickness;
}

void add_refraction_passes(par::Graph& g, const Scene* scene, const FrameSettings& f) {
  const int sw = f.width * f.supersample, sh = f.height * f.supersample;
  const double method_param = f.param("method", 1.0);
  if (method_param != 0.0 && method_param != 1.0 && method_param != 2.0)
    throw InputError("--param method", "refraction method must be 0 (single interface), 1 "
                                       "(two-face) or 2 (distance impostors)");
  const auto method = static_cast<RefractionMethod>(static_cast<int>(method_param));
  RefractionOptions options;
  options.method = method;
  const double linear = f.param("linear_steps", 16.0), secant = f.param("secant_steps", 4.0);
  const double impostor_size = f.param("impostor_size", 128.0);
  if (!(linear >= 0 && linear <= 1024 && secant >= 0 && secant <= 64))
    throw InputError("--param", "linear_steps must be in [0, 1024] and secant_steps in [0, 64]");
  if (!(impostor_size >= 4 && impostor_size <= 4096))
    throw InputError("--param impostor_size", "must be in [4, 4096]");
  for (DistanceSearchOptions* o : {&options.environment_search, &options.exit_search}) {
    o->linear_steps = static_cast<int>(linear);
    o->linear = o->linear_steps >= 2;
    o->secant_steps = static_cast<int>(secant);
  }

  SurfacePassNotes notes;
  notes.visibility = "Camera visibility buffer: the refractors' front faces (P1).";
  notes.gbuffer = "Camera G-buffer: front-face positions and normals N1 (SURVEY §4.4).";
  add_surface_passes(g, scene, f, notes);

  add_reflector_cube_maps_pass(g, scene, f, "Colour + distance cube map around each specular object, itself left out: "
               "the environment distance map the refracted rays search (SURVEY §4.1, §4.4).");

  g.add("envmap_reflect", [](par::NodeContext& c) {
     c.set_output("specular_envmap", envmap_reflect(c.executor(), c.input<GBuffer>("gbuffer"),
                                                    c.input<EnvironmentMap>("environment"),
                                                    &c.input<ReflectorMaps>("reflector_maps")));
   }).reads<GBuffer>("gbuffer").reads<EnvironmentMap>("environment")
     .reads<ReflectorMaps>("reflector_maps").writes<ImageRGBA>("specular_envmap")
     .describe("Environment-mapped specular layer for the non-refracting reflectors (SURVEY §3.1).");

  if (method == RefractionMethod::TwoFace) {
    g.add("back_faces", [scene, f, sw, sh](par::NodeContext& c) {
       c.set_output("back_faces", render_refractor_back_faces(c.executor(), *scene, f.camera, sw, sh));
     }).writes<GBuffer>("back_faces").param("width", sw).param("height", sh)
       .describe("Refractors alone, front faces culled: back-face position (d_V) and normal "
                 "N2 per sample (two-face method, SURVEY §4.4).");
    g.add("refractor_thickness", [scene](par::NodeContext& c) {
       c.set_output("vertex_thickness", refractor_vertex_thickness(*scene, c.executor()));
     }).writes<Thickness>("vertex_thickness")
       .describe("Per-vertex thickness d_N along −N by BVH ray casts (two-face method, "
                 "SURVEY §4.4).");
  } else if (method == RefractionMethod::DistanceImpostor) {
    const int size = static_cast<int>(impostor_size);
    g.add("refractor_impostors", [scene, size](par::NodeContext& c) {
       auto& imp = c.output<RefractorImpostors>("impostors");
       imp = render_refractor_impostors(c.executor(), *scene, size);
       c.count("impostors", imp.cubes.size());
     }).writes<RefractorImpostors>("impostors").param("size", size)
       .describe("Each refractor alone from its centre: normal + distance cube map searched "
                 "for the exit point (distance impostors, SURVEY §4.4).");
  }

  auto node = g.add("refraction", [scene, f, options, method](par::NodeContext& c) {
    RefractionInputs in;
    in.front = &c.input<GBuffer>("gbuffer");
    in.front_vis = &c.input<VisibilityBuffer>("visibility");
    in.mesh = &scene->mesh;
    in.camera = f.camera;
    in.maps = &c.input<ReflectorMaps>("reflector_maps");
    in.env = &c.input<EnvironmentMap>("environment");
    if (method == RefractionMethod::TwoFace) {
      in.back = &c.input<GBuffer>("back_faces");
      in.vertex_thickness = &c.input<Thickness>("vertex_thickness");
    } else if (method == RefractionMethod::DistanceImpostor) {
      in.impostors = &c.input<RefractorImpostors>("impostors");
    }
    RefractionLayer layer = refract_layer(c.executor(), in, options,
                                          c.input<ImageRGBA>("specular_envmap"));
    c.count("refracted", layer.refracted);
    c.count("total_internal", layer.total_internal);
    c.count("no_exit", layer.no_exit);
    c.count("exit_normal_fallbacks", layer.exit_normal_fallbacks);
    c.set_output("specular", std::move(layer.specular));
  });
  node.reads<GBuffer>("gbuffer").reads<VisibilityBuffer>("visibility")
      .reads<ReflectorMaps>("reflector_maps").reads<EnvironmentMap>("environment")
      .reads<ImageRGBA>("specular_envmap").writes<ImageRGBA>("specular")
      .param("method", static_cast<int>(method))
      .param("linear_steps", options.environment_search.linear_steps)
      .param("secant_steps", options.environment_search.secant_steps)
      .describe("Refractor samples: T1 at the front face, exit by the chosen method, refract "
                "out or total internal reflection, outgoing rays searched in the environment "
                "distance map; exact Fresnel at both interfaces (SURVEY §4.4).");
  if (method == RefractionMethod::TwoFace)
    node.reads<GBuffer>("back_faces").reads<Thickness>("vertex_thickness");
  else if (method == RefractionMethod::DistanceImpostor)
    node.reads<RefractorImpostors>("impostors");

  add_output_passes(g, f);
}

}  // namespace speculum::pipeline
