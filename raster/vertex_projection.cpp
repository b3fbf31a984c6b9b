// ROGER ch.2 vertex projection passes (see vertex_projection.h).
#include "raster/vertex_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "core/camera_rays.h"
#include "core/mesh_processing/halfedge_mesh.h"
#include "core/mesh_processing/mean_curvature.h"
#include "core/mesh_processing/star_shape.h"
#include "core/mesh_processing/subdivision.h"
#include "core/shading.h"
#include "raster/cube_map.h"
#include "raster/direct_light.h"
#include "raster/specular_radiance.h"
#include "raster/triangle_setup.h"
#include "raster/visibility.h"

namespace speculum::raster {

namespace {

constexpr std::uint8_t kOwnVertex = 255;  // a vertex of the reflector itself: not projected

void append_halfedge_mesh(const mesh::HalfedgeMesh& m, std::uint32_t object, std::uint32_t material,
                          ReflectedGeometry& out) {
  TriangleMesh& soup = out.mesh;
  const auto base = static_cast<std::uint32_t>(soup.positions.size());
  for (const auto vh : m.vertices()) {
    const auto p = m.point(vh);
    const auto n = m.normal(vh);
    const auto uv = m.texcoord2D(vh);
    soup.positions.emplace_back(p[0], p[1], p[2]);
    const glm::vec3 nf(n[0], n[1], n[2]);
    const float l = glm::length(nf);
    soup.normals.push_back(l > 0.0f ? nf / l : glm::vec3(0.0f, 1.0f, 0.0f));
    soup.uvs.emplace_back(uv[0], uv[1]);
  }
  for (const auto fh : m.faces()) {
    for (const auto vh : m.fv_range(fh)) soup.indices.push_back(base + static_cast<std::uint32_t>(vh.idx()));
    soup.triangle_material.push_back(material);
    soup.triangle_object.push_back(object);
  }
}

void append_soup_object(const Scene& scene, std::uint32_t object, ReflectedGeometry& out) {
  const TriangleMesh& in = scene.mesh;
  TriangleMesh& soup = out.mesh;
  const Object& o = scene.objects[object];
  for (std::uint32_t t = o.first_triangle; t < o.first_triangle + o.triangle_count; ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = in.indices[3 * t + k];
      soup.indices.push_back(static_cast<std::uint32_t>(soup.positions.size()));
      soup.positions.push_back(in.positions[v]);
      soup.normals.push_back(in.normals[v]);
      soup.uvs.push_back(v < in.uvs.size() ? in.uvs[v] : glm::vec2(0.0f));
    }
    soup.triangle_material.push_back(in.triangle_material[t]);
    soup.triangle_object.push_back(object);
  }
}

}  // namespace

ReflectedGeometry tessellate_reflected(const Scene& scene, double max_edge, std::size_t max_vertices) {
  ReflectedGeometry out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    if (obj.triangle_count == 0) continue;
    bool uniform = true;
    for (std::uint32_t t = obj.first_triangle; uniform && t < obj.first_triangle + obj.triangle_count; ++t)
      uniform = scene.mesh.triangle_material[t] == scene.mesh.triangle_material[obj.first_triangle];
    if (max_edge > 0.0 && uniform) {
      // Unwelded (Weld::Indices): uv and normal seams stay split, so attributes stay single-valued.
      mesh::ObjectMesh om = mesh::build_object_mesh(scene, o, mesh::Weld::Indices);
      if (om.report.manifold() && om.report.degenerate_faces == 0) {
        const std::size_t used = out.mesh.positions.size();
        const std::size_t budget = std::max<std::size_t>(om.mesh.n_vertices(), max_vertices > used ? max_vertices - used : 0);
        const mesh::SplitReport r = mesh::split_long_edges(om.mesh, max_edge, budget);
        out.splits += r.splits;
        out.vertex_budget_reached = out.vertex_budget_reached || r.vertex_budget_reached;
        append_halfedge_mesh(om.mesh, o, scene.mesh.triangle_material[obj.first_triangle], out);
        continue;
      }
    }
    if (max_edge > 0.0) ++out.objects_kept_whole;
    append_soup_object(scene, o, out);
  }
  return out;
}

ReflectorSample ReflectorParam::operator()(const glm::dvec3& u) const {
  ReflectorSample s;
  const CubeCoord c = cube_coord(glm::vec3(u), size);
  // Bilinear over the valid texels among the four nearest (clamped at the face border).
  const double px = std::clamp(double(c.pixel.x) - 0.5, 0.0, double(size - 1));
  const double py = std::clamp(double(c.pixel.y) - 0.5, 0.0, double(size - 1));
  const int x0 = std::min(int(px), size - 1), y0 = std::min(int(py), size - 1);
  const int x1 = std::min(x0 + 1, size - 1), y1 = std::min(y0 + 1, size - 1);
  const double fx = px - x0, fy = py - y0;
  const int xs[4] = {x0, x1, x0, x1}, ys[4] = {y0, y0, y1, y1};
  const double ws[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
  double w = 0.0, r = 0.0;
  glm::dvec3 n(0.0);
  for (int k = 0; k < 4; ++k) {
    const glm::vec4& texel = texels[c.face].at(xs[k], ys[k]);
    const float rk = texel.w;
    if (!std::isfinite(rk) || ws[k] <= 0.0) continue;
    w += ws[k];
    r += ws[k] * rk;
    n += ws[k] * glm::dvec3(glm::vec3(texel));
  }
  if (!(w > 1e-6) || !(glm::length(n) > 0.0)) return s;
  s.valid = true;
  s.point = centre + (r / w) * u;
  s.normal = glm::normalize(n);
  return s;
}

ReflectorParams build_reflector_params(par::Executor& executor, const Scene& scene, int size) {
  ReflectorParams out;
  for (std::uint32_t o = 0; o < scene.objects.size(); ++o) {
    const Object& obj = scene.objects[o];
    if (obj.triangle_count == 0 || scene.materials[obj.material].kind() != MaterialKind::Mirror) continue;
    const mesh::ObjectMesh om = mesh::build_object_mesh(scene, o, mesh::Weld::Positions);
    const mesh::StarShape star = mesh::choose_star_centre(om.mesh);
    if (!star.star_shaped) {
      ++out.not_star_shaped;
      out.skipped.push_back("object '" + obj.name + "' is not star-shaped about its " + star.centre_rule + " (" +
                            std::to_string(star.failing_faces) + " of " + std::to_string(star.faces) +
                            " faces face the wrong way): left to the environment map");
      continue;
    }
    ReflectorParam p;
    p.object = o;
    p.centre = star.centre;
    p.orientation = star.orientation;
    p.size = size;
    p.closed = std::none_of(om.mesh.vertices_begin(), om.mesh.vertices_end(),
                            [&](auto vh) { return om.mesh.is_boundary(vh); });
    if (p.orientation > 0) {
      const std::vector<double> h = mesh::mean_curvature(om.mesh);
      p.convex = std::all_of(h.begin(), h.end(), [](double v) { return v > 0.0; });
    }
    RasterOptions options;
    options.excluded_objects.assign(scene.objects.size(), 1);
    options.excluded_objects[o] = 0;
    Bounds b;
    for (const auto vh : om.mesh.vertices()) b.grow(glm::vec3(mesh::to_glm(om.mesh.point(vh))));
    const CubeDepthRange range = cube_depth_range(glm::length(b.extent()));
    const glm::vec3 centre(p.centre);
    for (int face = 0; face < kCubeFaces; ++face) {
      const Camera cam = cube_face_camera(face, centre, range.znear, range.zfar);
      const VisibilityBuffer vis = render_visibility(executor, scene, cam, size, size, options);
      Buffer2D<glm::vec4>& texels = p.texels[face];
      texels = Buffer2D<glm::vec4>(size, size, glm::vec4(0.0f, 0.0f, 0.0f, std::numeric_limits<float>::infinity()));
      executor.parallel_for("reflector_param.texels", texels.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) {
          const std::uint32_t t = vis.triangle.pixels[i];
          if (t == kNoId) continue;
          const glm::vec2 bc = vis.bary.pixels[i];
          const std::uint32_t* idx = &scene.mesh.indices[3 * std::size_t(t)];
          const float r = glm::length(visible_position(scene.mesh, vis, i) - centre);
          const glm::vec3 n = (1.0f - bc.x - bc.y) * scene.mesh.normals[idx[0]] + bc.x * scene.mesh.normals[idx[1]] +
                              bc.y * scene.mesh.normals[idx[2]];
          const float l = glm::length(n);
          texels.pixels[i] = glm::vec4(l > 0.0f ? n / l : glm::vec3(0.0f), r);
        }
      });
    }
    for (const Buffer2D<glm::vec4>& face : p.texels)
      for (const glm::vec4& texel : face.pixels)
        if (std::isfinite(texel.w)) p.max_radius = std::max(p.max_radius, double(texel.w));
    out.reflectors.push_back(std::move(p));
  }
  return out;
}

ProjectedVertices project_vertices(par::Executor& executor, const ReflectedGeometry& geometry,
                                   const ReflectorParams& params, const Camera& camera, int width, int height,
                                   const FermatSettings& settings, ProjectionStats* stats) {
  const TriangleMesh& m = geometry.mesh;
  const std::size_t n = m.vertex_count();
  // The object of each vertex (tessellate appends objects one after another).
  std::vector<std::uint32_t> vertex_object(n, kNoId);
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) vertex_object[m.indices[3 * t + k]] = m.triangle_object[t];
  const glm::mat4 vp = projection_matrix(camera, width, height) * view_matrix(camera);
  const glm::dvec3 eye(camera.eye);
  auto project = [&](const glm::dvec3& p) {
    const glm::vec4 c = vp * glm::vec4(glm::vec3(p), 1.0f);
    if (!(c.w > 0.0f)) return glm::dvec2(std::numeric_limits<double>::infinity());
    return glm::dvec2((double(c.x) / c.w * 0.5 + 0.5) * width, (double(c.y) / c.w * 0.5 + 0.5) * height);
  };
  ProjectedVertices out;
  out.vertices = n;
  const std::size_t reflectors = params.reflectors.size();
  out.clip.assign(reflectors, std::vector<glm::vec4>(n, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f)));
  out.status.assign(reflectors, std::vector<std::uint8_t>(n, kOwnVertex));
  out.extremum.assign(reflectors, std::vector<std::uint8_t>(n, 0));
  out.iterations.assign(reflectors, std::vector<std::uint8_t>(n, 0));
  for (std::size_t r = 0; r < reflectors; ++r) {
    const ReflectorParam& param = params.reflectors[r];
    FermatSettings own = settings;
    if (param.orientation < 0) own.max_start_side = std::min(own.max_start_side, 0.1);
    if (param.convex) own.classify = false;
    own.closed = param.closed;
    executor.parallel_for("vertex_project.secant", n, 256, [&](std::size_t begin, std::size_t end) {
      for (std::size_t v = begin; v < end; ++v) {
        if (vertex_object[v] == param.object || vertex_object[v] == kNoId) continue;
        const glm::dvec3 vertex(m.positions[v]);
        const FermatResult f = fermat_project(param, param.centre, eye, vertex, project, own);
        ProjectionStatus status = f.status;
        glm::vec4 clip(0.0f, 0.0f, 0.0f, 1.0f);
        if (status == ProjectionStatus::Converged) {
          const glm::vec4 c = vp * glm::vec4(glm::vec3(f.point), 1.0f);
          if (c.w > 0.0f) {
            const float path = float(glm::length(f.point - eye) + glm::length(vertex - f.point));
            clip = glm::vec4(c.x / c.w * path, c.y / c.w * path, 0.0f, path);
          } else {
            status = ProjectionStatus::Hidden;  // behind the camera: not seen in this reflector
          }
        }
        out.clip[r][v] = clip;
        out.status[r][v] = static_cast<std::uint8_t>(status);
        out.extremum[r][v] = static_cast<std::uint8_t>(f.extremum);
        out.iterations[r][v] = static_cast<std::uint8_t>(std::min(f.iterations, 255));
      }
    });
  }
  if (stats) {
    // Serial sums of per-vertex records: the same counts for every thread count.
    for (std::size_t r = 0; r < reflectors; ++r)
      for (std::size_t v = 0; v < n; ++v) {
        const std::uint8_t s = out.status[r][v];
        if (s == kOwnVertex) continue;
        ++stats->projections;
        stats->iterations += out.iterations[r][v];
        switch (static_cast<ProjectionStatus>(s)) {
          case ProjectionStatus::Converged: {
            ++stats->converged;
            ++stats->histogram[std::min<std::size_t>(out.iterations[r][v], 32)];
            const auto e = static_cast<PathExtremum>(out.extremum[r][v]);
            if (e == PathExtremum::Minimum) ++stats->minima;
            else if (e == PathExtremum::Maximum) ++stats->maxima;
            else ++stats->saddles;
            break;
          }
          case ProjectionStatus::NotConverged: ++stats->not_converged; break;
          case ProjectionStatus::OffReflector: ++stats->off_reflector; break;
          case ProjectionStatus::Hidden: ++stats->hidden; break;
        }
      }
  }
  return out;
}

namespace {

// Whether the ray p + t d (t > 0) meets the reflector again: marched in 64 steps over twice
// the largest radius plus |p − O|.
bool hits_itself(const ReflectorParam& param, const glm::dvec3& p, const glm::dvec3& d, glm::dvec3& hit,
                 glm::dvec3& normal) {
  const double reach = 2.0 * param.max_radius + glm::length(p - param.centre);
  constexpr int kSteps = 64;
  // A hit is a crossing from inside r(u) to outside it: a ray leaving the mirror's outer
  // (convex) side starts outside and meets nothing.
  bool inside = false;
  for (int k = 1; k <= kSteps; ++k) {
    const glm::dvec3 x = p + (reach * k / kSteps) * d;
    const glm::dvec3 q = x - param.centre;
    const double l = glm::length(q);
    if (!(l > 0.0)) continue;
    const ReflectorSample s = param(q / l);
    if (!s.valid) continue;
    const bool now_inside = l < glm::length(s.point - param.centre);
    if (inside && !now_inside) {
      hit = s.point;
      normal = s.normal;
      return true;
    }
    inside = now_inside;
  }
  return false;
}

bool vertex_projection_sample(const GBuffer& g, std::size_t i) {
  const SurfaceParams& s = g.surface[i];
  return g.covered(i) && !s.is_refractor() && s.is_mirror_lobe();
}

}  // namespace

ReflectedLayer rasterize_reflected(par::Executor& executor, const ReflectedGeometry& geometry,
                                   const ProjectedVertices& projected, const ReflectorParams& params,
                                   const GBuffer& gbuffer, ReflectedTriangleStats* stats) {
  const TriangleMesh& m = geometry.mesh;
  ReflectedLayer layer;
  layer.width = gbuffer.width;
  layer.height = gbuffer.height;
  layer.triangle = IdBuffer(gbuffer.width, gbuffer.height, kNoId);
  layer.bary = Buffer2D<glm::vec2>(gbuffer.width, gbuffer.height, glm::vec2(0.0f));
  layer.iterations = ImageF(gbuffer.width, gbuffer.height, 0.0f);
  const Viewport viewport{gbuffer.width, gbuffer.height};
  ReflectedTriangleStats local;
  for (std::size_t r = 0; r < params.reflectors.size(); ++r) {
    const ReflectorParam& param = params.reflectors[r];
    bool seen = false;
    for (std::size_t i = 0; i < gbuffer.object.size() && !seen; ++i) seen = gbuffer.object.pixels[i] == param.object;
    if (!seen) continue;
    // The triangles whose three vertices have a visible reflection. On a reflector seen from
    // its centre's side (a bowl) they must also be of one kind — all minima (the near zone)
    // or all maxima (the far zone), §2.3.3; a closed reflector's saddles are ordinary
    // reflections in its saddle-shaped parts.
    const bool zoned = param.orientation < 0;
    std::vector<std::uint32_t> indices, original;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      if (m.triangle_object[t] == param.object) continue;
      const std::uint32_t* idx = &m.indices[3 * t];
      bool unprojected = false, hidden = false, middle = false;
      const std::uint8_t e0 = projected.extremum[r][idx[0]];
      for (int k = 0; k < 3; ++k) {
        const auto s = static_cast<ProjectionStatus>(projected.status[r][idx[k]]);
        if (s == ProjectionStatus::Hidden) hidden = true;
        else if (s != ProjectionStatus::Converged) unprojected = true;
        else if (zoned && (projected.extremum[r][idx[k]] != e0 ||
                           projected.extremum[r][idx[k]] == static_cast<std::uint8_t>(PathExtremum::Saddle)))
          middle = true;
      }
      if (unprojected) ++local.unprojected;
      else if (hidden) ++local.hidden;
      else if (middle) ++local.middle_zone;
      else {
        indices.insert(indices.end(), idx, idx + 3);
        original.push_back(static_cast<std::uint32_t>(t));
      }
    }
    local.drawn += original.size();
    if (original.empty()) continue;
    std::vector<ScreenVertex> vertices(m.vertex_count());
    executor.parallel_for("reflected_triangles.vertices", vertices.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t v = b; v < e; ++v) vertices[v] = make_screen_vertex(projected.clip[r][v], viewport);
    });
    // The "object" of each listed triangle is its index in the reflected geometry.
    const VisibilityBuffer vis =
        rasterize_screen_vertices(executor, vertices, indices, original, gbuffer.width, gbuffer.height);
    executor.parallel_for("reflected_triangles.stencil", layer.triangle.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (gbuffer.object.pixels[i] != param.object || !vertex_projection_sample(gbuffer, i)) continue;
        const std::uint32_t t = vis.object.pixels[i];
        if (t == kNoId) continue;
        layer.triangle.pixels[i] = t;
        layer.bary.pixels[i] = vis.bary.pixels[i];
        const std::uint32_t* idx = &m.indices[3 * std::size_t(t)];
        layer.iterations.pixels[i] = float(std::max({projected.iterations[r][idx[0]], projected.iterations[r][idx[1]],
                                                     projected.iterations[r][idx[2]]}));
      }
    });
  }
  for (std::size_t i = 0; i < layer.triangle.size(); ++i) local.samples += layer.triangle.pixels[i] != kNoId;
  if (stats) *stats = local;
  return layer;
}

ImageRGBA shade_reflected(par::Executor& executor, const Scene& scene, const ReflectedGeometry& geometry,
                          const ReflectedLayer& layer, const ReflectorParams& params, const GBuffer& g,
                          const ShadowMaps& shadows, const EnvironmentMap& env, const ImageRGBA& fallback) {
  ImageRGBA out = fallback;
  const TriangleMesh& m = geometry.mesh;
  std::vector<int> projected;  // by object id: its parameterization's index, −1: none
  for (std::size_t k = 0; k < params.reflectors.size(); ++k) {
    const std::uint32_t o = params.reflectors[k].object;
    if (projected.size() <= o) projected.resize(o + 1, -1);
    projected[o] = int(k);
  }
  executor.parallel_for("vertex_projection_shade.shade", out.size(), 1024, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint32_t t = layer.triangle.pixels[i];
      if (t == kNoId) {
        const std::uint32_t o = g.object.pixels[i];
        if (o == kNoId || o >= projected.size() || projected[o] < 0 || !vertex_projection_sample(g, i)) continue;
        const ReflectorParam& param = params.reflectors[std::size_t(projected[o])];
        const auto sky = [&](const glm::vec3& d, float exponent) {
          // A concave reflector (O on its mirror side) may see itself: the secondary
          // reflection ROGER §2.3.3 leaves empty, shaded here as the reflector lit directly.
          glm::dvec3 hit, normal;
          if (param.orientation < 0 && hits_itself(param, glm::dvec3(g.position.pixels[i]), glm::dvec3(d), hit, normal))
            return shade_surface(scene, g.surface[i], glm::vec3(hit), glm::vec3(normal), -d, shadows, env);
          return env.radiance(d, exponent);
        };
        out.pixels[i] = glm::vec4(specular_radiance(g.surface[i], g.normal.pixels[i], g.view_direction(i), sky), 1.0f);
        continue;
      }
      const std::uint32_t* idx = &m.indices[3 * std::size_t(t)];
      const glm::vec2 bc = layer.bary.pixels[i];
      const float b0 = 1.0f - bc.x - bc.y;
      const glm::vec3 v = b0 * m.positions[idx[0]] + bc.x * m.positions[idx[1]] + bc.y * m.positions[idx[2]];
      glm::vec3 n = b0 * m.normals[idx[0]] + bc.x * m.normals[idx[1]] + bc.y * m.normals[idx[2]];
      const float nl = glm::length(n);
      n = nl > 0.0f ? n / nl : glm::vec3(0.0f, 1.0f, 0.0f);
      const glm::vec2 uv = b0 * m.uvs[idx[0]] + bc.x * m.uvs[idx[1]] + bc.y * m.uvs[idx[2]];
      const SurfaceParams s = surface_params(scene, m.triangle_material[t], uv);
      // Lit at V and seen from the reflection point P of this sample (ROGER Fig.2.11).
      const glm::vec3 to_p = g.position.pixels[i] - v;
      const float l = glm::length(to_p);
      const glm::vec3 view = l > 0.0f ? to_p / l : n;
      const glm::vec3 radiance = shade_surface(scene, s, v, n, view, shadows, env);
      const float cos_nv = glm::dot(g.normal.pixels[i], g.view_direction(i));
      out.pixels[i] = glm::vec4(specular_reflectance(g.surface[i], cos_nv) * radiance, 1.0f);
    }
  });
  return out;
}

ReflectedGeometry TessellatePass::operator()(par::NodeContext& c) const {
  const double diagonal = glm::length(scene->bounds().extent());
  ReflectedGeometry out = tessellate_reflected(*scene, edge * diagonal, max_vertices);
  c.count("vertices", double(out.mesh.vertex_count()));
  c.count("triangles", double(out.mesh.triangle_count()));
  c.count("splits", double(out.splits));
  c.count("objects_kept_whole", double(out.objects_kept_whole));
  c.count("vertex_budget_reached", out.vertex_budget_reached ? 1.0 : 0.0);
  return out;
}

ReflectorParams ReflectorParamPass::operator()(par::NodeContext& c) const {
  ReflectorParams out = build_reflector_params(c.executor(), *scene, size);
  c.count("reflectors", double(out.reflectors.size()));
  c.count("not_star_shaped", double(out.not_star_shaped));
  return out;
}

ReflectorMaps FallbackCubeMapsPass::operator()(par::NodeContext& c, const ReflectorParams& params,
                                              const ShadowMaps& shadows, const EnvironmentMap& environment,
                                              const GBuffer& gbuffer) const {
  std::vector<std::uint8_t> skip(scene->objects.size(), 0);
  for (const ReflectorParam& p : params.reflectors) skip[p.object] = 1;
  ReflectorMaps maps = render_reflector_maps(c.executor(), *scene, shadows, environment, size, &gbuffer,
                                             ReflectorSelection::all, {}, &skip, sizing);
  c.count("cube_maps", double(maps.cubes.size()));
  c.count("cube_texels", rendered_texels(maps));
  return maps;
}

ProjectedVertices VertexProjectPass::operator()(par::NodeContext& c, const ReflectedGeometry& geometry,
                                                const ReflectorParams& params, const GBuffer& gbuffer) const {
  ProjectionStats stats;
  ProjectedVertices out =
      project_vertices(c.executor(), geometry, params, camera, gbuffer.width, gbuffer.height, settings, &stats);
  c.count("projections", double(stats.projections));
  c.count("converged", double(stats.converged));
  c.count("not_converged", double(stats.not_converged));
  c.count("off_reflector", double(stats.off_reflector));
  c.count("hidden", double(stats.hidden));
  c.count("minima", double(stats.minima));
  c.count("maxima", double(stats.maxima));
  c.count("middle_zone_vertices", double(stats.saddles));
  c.count("iterations", double(stats.iterations));
  // The iteration histogram of the converged projections in bins of four (ROGER §2.3.2:
  // < 5 near the centre, ≤ 20 near silhouettes).
  static constexpr const char* kBins[] = {"iterations_0_4", "iterations_5_8", "iterations_9_12",
                                          "iterations_13_16", "iterations_17_20", "iterations_21_32"};
  double bins[6] = {};
  for (std::size_t k = 0; k <= 32; ++k) bins[k <= 4 ? 0 : std::min<std::size_t>((k - 1) / 4, 5)] += double(stats.histogram[k]);
  for (int b = 0; b < 6; ++b) c.count(kBins[b], bins[b]);
  return out;
}

ReflectedLayer ReflectedTrianglesPass::operator()(par::NodeContext& c, const ReflectedGeometry& geometry,
                                                  const ProjectedVertices& projected, const ReflectorParams& params,
                                                  const GBuffer& gbuffer) const {
  ReflectedTriangleStats stats;
  ReflectedLayer out = rasterize_reflected(c.executor(), geometry, projected, params, gbuffer, &stats);
  c.count("triangles_drawn", double(stats.drawn));
  c.count("triangles_unprojected", double(stats.unprojected));
  c.count("triangles_hidden", double(stats.hidden));
  c.count("triangles_middle_zone", double(stats.middle_zone));
  c.count("reflected_samples", double(stats.samples));
  return out;
}

ImageRGBA VertexProjectionShadePass::operator()(par::NodeContext& c, const ReflectedLayer& layer,
                                                const ReflectedGeometry& geometry, const ReflectorParams& params,
                                                const GBuffer& gbuffer,
                                                const ShadowMaps& shadows, const EnvironmentMap& environment,
                                                const ImageRGBA& fallback) const {
  std::uint64_t fallback_samples = 0;
  for (std::size_t i = 0; i < layer.triangle.size(); ++i)
    fallback_samples += layer.triangle.pixels[i] == kNoId && vertex_projection_sample(gbuffer, i);
  c.count("environment_samples", double(fallback_samples));
  return shade_reflected(c.executor(), *scene, geometry, layer, params, gbuffer, shadows, environment, fallback);
}

}  // namespace speculum::raster
