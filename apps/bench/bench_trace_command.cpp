// `speculum bench trace`: traces a SPRY ray file against a PLY mesh with our BVH (and with
// Embree 3 when built with it, in the same run) and prints one JSON object; `--emit-rays`
// writes ray files for a camera and `--make-mesh spheres:N` writes the test mesh (N
// UV-spheres in a box room).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <memory>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "apps/cli/camera_options.h"
#include "apps/cli/json_output.h"
#include "core/error.h"
#include "core/sampling.h"
#include "core/scene_loader.h"
#include "trace/bvh.h"
#include "trace/packet_traversal.h"
#include "trace/ray_file.h"
#include "trace/ray_generation.h"
#include "trace/traversal.h"

#ifdef SPECULUM_HAVE_EMBREE
#include <embree3/rtcore.h>
#endif

namespace speculum::cli {
namespace {

struct BenchTraceOptions {
  std::string mesh;
  std::string rays;
  std::string emit;
  std::string make_mesh;
  std::string output;
  int repeat = 5;
  int width = 1024, height = 1024;
  std::string eye, target, up;  // x,y,z (empty: default)
  float fov = 60.0f;
  std::uint32_t seed = 1;
  bool json = false;
  bool no_embree = false;
  std::string kernel = "packet";
  int image_width = 0;  // --image-width (0: detected, see camera_image_width)
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Process CPU time (all threads), ms: on a shared, loaded machine the ratio of CPU times
// is a steadier A/B figure than wall clock (which includes waiting for a core).
double cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// N UV-spheres (about 10.2K triangles each) on a grid inside an inward-facing box room,
// written as binary little-endian PLY.
void make_spheres_mesh(const std::string& spec, const std::string& path) {
  const std::string prefix = "spheres:";
  if (spec.rfind(prefix, 0) != 0) throw InputError("--make-mesh", "expected spheres:N, got '" + spec + "'");
  int n = 0;
  try {
    n = std::stoi(spec.substr(prefix.size()));
  } catch (...) {
    throw InputError("--make-mesh", "bad sphere count in '" + spec + "'");
  }
  if (n < 1 || n > 10000) throw InputError("--make-mesh", "sphere count must be 1..10000");
  const int rings = 51, segs = 102;
  const int grid = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const float half = 10.0f, spacing = 2.0f * half / grid, radius = 0.45f * spacing;
  std::vector<glm::vec3> v;
  std::vector<std::uint32_t> f;
  for (int s = 0; s < n; ++s) {
    const glm::vec3 c(-half + spacing * (s % grid + 0.5f), -1.0f, -half + spacing * (s / grid + 0.5f));
    const auto base = static_cast<std::uint32_t>(v.size());
    v.push_back(c + glm::vec3(0, radius, 0));
    for (int r = 1; r < rings; ++r)
      for (int k = 0; k < segs; ++k) {
        const float th = kPi * r / rings, ph = 2 * kPi * k / segs;
        v.push_back(c + radius * glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
      }
    v.push_back(c - glm::vec3(0, radius, 0));
    auto ring = [&](int r, int k) { return base + 1 + static_cast<std::uint32_t>((r - 1) * segs + k % segs); };
    const std::uint32_t south = base + 1 + static_cast<std::uint32_t>((rings - 1) * segs);
    for (int k = 0; k < segs; ++k) {
      f.insert(f.end(), {base, ring(1, k + 1), ring(1, k)});
      f.insert(f.end(), {south, ring(rings - 1, k), ring(rings - 1, k + 1)});
      for (int r = 1; r + 1 < rings; ++r) {
        f.insert(f.end(), {ring(r, k), ring(r, k + 1), ring(r + 1, k)});
        f.insert(f.end(), {ring(r, k + 1), ring(r + 1, k + 1), ring(r + 1, k)});
      }
    }
  }
  // The room: floor, ceiling and four walls, facing inwards.
  const glm::vec3 lo(-half, -2.0f, -half), hi(half, 6.0f, half);
  const auto b = static_cast<std::uint32_t>(v.size());
  for (int i = 0; i < 8; ++i) v.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  const std::uint32_t quads[6][4] = {{0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    f.insert(f.end(), {b + q[0], b + q[1], b + q[2]});
    f.insert(f.end(), {b + q[0], b + q[2], b + q[3]});
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot create mesh file");
    out << "ply\nformat binary_little_endian 1.0\ncomment speculum bench trace --make-mesh " << spec
        << "\nelement vertex " << v.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "element face " << f.size() / 3 << "\nproperty list uchar int vertex_indices\nend_header\n";
    out.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * sizeof(glm::vec3)));
    for (std::size_t t = 0; t < f.size(); t += 3) {
      const unsigned char three = 3;
      out.write(reinterpret_cast<const char*>(&three), 1);
      out.write(reinterpret_cast<const char*>(&f[t]), 12);
    }
    if (!out) throw InputError(path, "write failed");
  }
  std::rename(tmp.c_str(), path.c_str());
  std::printf("%s: %zu vertices, %zu triangles\n", path.c_str(), v.size(), f.size() / 3);
}

struct Checksum {
  std::uint64_t hits = 0, prim_sum = 0;
  double t_sum = 0.0;
};

Checksum checksum(const trace::HitStream& h) {
  Checksum c;
  for (std::size_t i = 0; i < h.triangle.size(); ++i)
    if (h.triangle[i] != trace::kNoHit) {
      ++c.hits;
      c.prim_sum += h.triangle[i];
      c.t_sum += h.t[i];
    }
  return c;
}

#ifdef SPECULUM_HAVE_EMBREE
struct EmbreeFigures {
  double build_ms = 0, mrays1 = 0, mrays16 = 0;
  double build_cpu_ms = 0, trace1_cpu_ms = 0;  // medians of process CPU time
  Checksum sum, sum16;  // rtcIntersect1's and rtcIntersect16's hits
};

EmbreeFigures run_embree(const Scene& scene, const trace::RayStream& rays, int image_width, int repeat,
                         par::Executor& ex) {
  EmbreeFigures fig;
  const std::string config = "threads=" + std::to_string(ex.threads());
  RTCDevice device = rtcNewDevice(config.c_str());
  if (!device) throw std::runtime_error("embree: rtcNewDevice failed");
  // Embree reads vertices as 16-byte loads: one float of padding after the last vertex.
  std::vector<float> verts(scene.mesh.positions.size() * 3 + 4, 0.0f);
  std::memcpy(verts.data(), scene.mesh.positions.data(), scene.mesh.positions.size() * sizeof(glm::vec3));
  std::vector<double> build, build_cpu;
  RTCScene rs = nullptr;
  for (int k = 0; k < repeat; ++k) {
    if (rs) rtcReleaseScene(rs);
    rs = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, verts.data(), 0, 12,
                               scene.mesh.positions.size());
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, scene.mesh.indices.data(), 0, 12,
                               scene.mesh.indices.size() / 3);
    rtcCommitGeometry(g);
    rtcAttachGeometry(rs, g);
    rtcReleaseGeometry(g);
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    ex.run([&] { rtcCommitScene(rs); });
    build.push_back(ms_since(t0));
    build_cpu.push_back(cpu_ms() - c0);
  }
  fig.build_ms = median(build);
  fig.build_cpu_ms = median(build_cpu);
  const std::size_t n = rays.size();
  trace::HitStream hits;
  hits.resize(n);
  // Rays we treat as invalid (non-finite, zero direction) are made inactive for Embree too
  // (tfar < tnear), so both sides see the same work and Embree never sees a NaN.
  auto active_tfar = [&](std::size_t i) {
    const float v[8] = {rays.ox[i], rays.oy[i], rays.oz[i], rays.dx[i], rays.dy[i], rays.dz[i], rays.tmin[i], rays.tmax[i]};
    bool ok = rays.dx[i] != 0.0f || rays.dy[i] != 0.0f || rays.dz[i] != 0.0f;
    for (float x : v) ok = ok && !std::isnan(x);
    for (int k = 0; k < 6; ++k) ok = ok && std::isfinite(v[k]);
    return ok ? rays.tmax[i] : -std::numeric_limits<float>::infinity();
  };
  auto fill = [&](RTCRayHit& rh, std::size_t i) {
    rh.ray.org_x = rays.ox[i]; rh.ray.org_y = rays.oy[i]; rh.ray.org_z = rays.oz[i];
    rh.ray.dir_x = rays.dx[i]; rh.ray.dir_y = rays.dy[i]; rh.ray.dir_z = rays.dz[i];
    rh.ray.tnear = rays.tmin[i]; rh.ray.tfar = active_tfar(i);
    rh.ray.mask = 0xffffffffu; rh.ray.time = 0; rh.ray.flags = 0; rh.ray.id = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  };
  std::vector<double> t1, t16, t1_cpu;
  for (int k = 0; k < repeat; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    ex.parallel_for("embree_intersect1", n, trace::kRayChunk, [&](std::size_t b, std::size_t e) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      for (std::size_t i = b; i < e; ++i) {
        RTCRayHit rh;
        fill(rh, i);
        rtcIntersect1(rs, &ctx, &rh);
        const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        hits.triangle[i] = hit ? rh.hit.primID : trace::kNoHit;
        hits.t[i] = hit ? rh.ray.tfar : 0.0f;
      }
    });
    t1.push_back(ms_since(t0));
    t1_cpu.push_back(cpu_ms() - c0);
  }
  fig.sum = checksum(hits);
  // rtcIntersect16 is fed as Embree's own programs feed it: rays of a camera image (one per
  // pixel, row-major, image_width wide) in 4x4 pixel blocks, whose rays share a node path;
  // other ray sets in runs of 16 consecutive rays. slots[16 p + l]: the ray of lane l of
  // packet p, or -1 for an idle lane.
  std::vector<std::int64_t> slots;
  if (image_width > 0) {
    const std::size_t w = static_cast<std::size_t>(image_width), h = n / w;
    for (std::size_t by = 0; by < h; by += 4)
      for (std::size_t bx = 0; bx < w; bx += 4)
        for (std::size_t dy = 0; dy < 4; ++dy)
          for (std::size_t dx = 0; dx < 4; ++dx)
            slots.push_back(by + dy < h && bx + dx < w ? static_cast<std::int64_t>((by + dy) * w + bx + dx) : -1);
  } else {
    for (std::size_t i = 0; i < (n + 15) / 16 * 16; ++i) slots.push_back(i < n ? static_cast<std::int64_t>(i) : -1);
  }
  const std::size_t packets = slots.size() / 16;
  for (int k = 0; k < repeat; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    ex.parallel_for("embree_intersect16", packets, trace::kRayChunk / 16, [&](std::size_t b, std::size_t e) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      if (image_width > 0) ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      for (std::size_t p = b; p < e; ++p) {
        alignas(64) RTCRayHit16 rh;
        alignas(64) int valid[16];
        for (int l = 0; l < 16; ++l) {
          const std::int64_t slot = slots[16 * p + l];
          const std::size_t i = slot >= 0 ? static_cast<std::size_t>(slot) : 0;
          valid[l] = slot >= 0 ? -1 : 0;
          rh.ray.org_x[l] = rays.ox[i]; rh.ray.org_y[l] = rays.oy[i]; rh.ray.org_z[l] = rays.oz[i];
          rh.ray.dir_x[l] = rays.dx[i]; rh.ray.dir_y[l] = rays.dy[i]; rh.ray.dir_z[l] = rays.dz[i];
          rh.ray.tnear[l] = rays.tmin[i]; rh.ray.tfar[l] = active_tfar(i);
          rh.ray.mask[l] = 0xffffffffu; rh.ray.time[l] = 0; rh.ray.flags[l] = 0; rh.ray.id[l] = 0;
          rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, rs, &ctx, &rh);
        for (int l = 0; l < 16; ++l) {
          const std::int64_t slot = slots[16 * p + l];
          if (slot < 0) continue;
          const bool hit = rh.hit.geomID[l] != RTC_INVALID_GEOMETRY_ID;
          hits.triangle[slot] = hit ? rh.hit.primID[l] : trace::kNoHit;
          hits.t[slot] = hit ? rh.ray.tfar[l] : 0.0f;
        }
      }
    });
    t16.push_back(ms_since(t0));
  }
  fig.sum16 = checksum(hits);
  fig.mrays1 = static_cast<double>(n) / (std::max(median(t1), 1e-6) * 1e3);
  fig.trace1_cpu_ms = median(t1_cpu);
  fig.mrays16 = static_cast<double>(n) / (std::max(median(t16), 1e-6) * 1e3);
  rtcReleaseScene(rs);
  rtcReleaseDevice(device);
  return fig;
}
#endif

// The width of the camera image the rays are, one per pixel in row-major order, or 0 when
// they are not: --image-width when given (its rows must divide the ray count), else
// --width when the count is --width x --height and every ray leaves one point (a pinhole
// camera's primary rays, as --emit-rays primary writes them).
int camera_image_width(const BenchTraceOptions& o, const trace::RayStream& rays) {
  const std::size_t n = rays.size();
  if (o.image_width > 0) {
    if (n % static_cast<std::size_t>(o.image_width) != 0)
      throw InputError("--image-width", std::to_string(n) + " rays are not rows of " + std::to_string(o.image_width));
    return o.image_width;
  }
  if (n == 0 || n != static_cast<std::size_t>(o.width) * static_cast<std::size_t>(o.height)) return 0;
  for (std::size_t i = 1; i < n; ++i)
    if (rays.ox[i] != rays.ox[0] || rays.oy[i] != rays.oy[0] || rays.oz[i] != rays.oz[0]) return 0;
  return o.width;
}

Camera bench_camera(const BenchTraceOptions& o, const Scene& scene) {
  const Bounds b = scene.bounds();
  const glm::vec3 c = b.center(), e = b.extent();
  Camera cam;
  cam.eye = c + glm::vec3(0.0f, 0.25f * e.y, 0.475f * e.z);
  cam.target = c + glm::vec3(0.0f, -0.125f * e.y, 0.0f);
  if (!o.eye.empty()) cam.eye = pipeline::parse_vec3("--eye", o.eye);
  if (!o.target.empty()) cam.target = pipeline::parse_vec3("--target", o.target);
  if (!o.up.empty()) cam.up = pipeline::parse_vec3("--up", o.up);
  cam.vfov_degrees = o.fov;
  return cam;
}

void run_bench_trace(const BenchTraceOptions& o, const GlobalOptions& global) {
  if (!o.make_mesh.empty()) {
    const std::string out = !o.output.empty() ? o.output : o.mesh;
    if (out.empty()) throw InputError("--make-mesh", "give the output file with -o");
    make_spheres_mesh(o.make_mesh, out);
    return;
  }
  if (o.mesh.empty()) throw InputError("bench trace", "no MESH given");
  par::Executor ex(global.threads, global.lanes);
  const Scene scene = load_scene(o.mesh);
  if (!o.emit.empty()) {
    const trace::RaySetKind kind = trace::parse_ray_set_kind(o.emit);
    if (o.output.empty()) throw InputError("--emit-rays", "give the output ray file with -o");
    const trace::Bvh bvh = trace::Bvh::build(scene.mesh, ex);
    const trace::RayStream rays = trace::generate_rays(kind, bvh, bench_camera(o, scene), o.width, o.height, o.seed, ex);
    trace::write_ray_file(o.output, rays);
    if (!global.quiet) std::fprintf(stderr, "%s: %zu %s rays\n", o.output.c_str(), rays.size(), o.emit.c_str());
    return;
  }
  if (o.rays.empty()) throw InputError("bench trace", "no --rays FILE given (or use --emit-rays)");
  if (o.kernel != "packet" && o.kernel != "single")
    throw InputError("--kernel", "expected packet or single, got '" + o.kernel + "'");
  const trace::RayStream rays = trace::read_ray_file(o.rays);
  const int repeat = std::max(1, o.repeat);

  std::vector<double> build_ms, trace_ms, build_cpu, trace_cpu;
  trace::Bvh bvh;
  for (int k = 0; k < repeat; ++k) {
    bvh = {};  // the previous build is released untimed, as the yardstick releases its scene
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    bvh = trace::Bvh::build(scene.mesh, ex);
    build_ms.push_back(ms_since(t0));
    build_cpu.push_back(cpu_ms() - c0);
  }
  trace::HitStream hits;
  trace::TraversalCounters counters;
  // Camera rays go to the packet kernel (and to rtcIntersect16) in 4x4 pixel tiles.
  const int image_width = camera_image_width(o, rays);
  for (int k = 0; k < repeat; ++k) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpu_ms();
    if (o.kernel == "packet")
      trace::closest_hit_stream_packets(bvh, rays, hits, ex, k == 0 ? &counters : nullptr, image_width);
    else trace::closest_hit_stream(bvh, rays, hits, ex, k == 0 ? &counters : nullptr);
    trace_ms.push_back(ms_since(t0));
    trace_cpu.push_back(cpu_ms() - c0);
  }
  const Checksum sum = checksum(hits);
  // Guarded so an empty ray file prints 0, never inf (which is not JSON).
  const double mrays = static_cast<double>(rays.size()) / (std::max(median(trace_ms), 1e-6) * 1e3);
  const double per_ray = 1.0 / std::max<double>(1.0, rays.size());
  OrderedJson j{{"mesh", o.mesh}, {"rays_file", o.rays}, {"triangles", scene.mesh.triangle_count()},
                {"rays", rays.size()}, {"threads", ex.threads()}, {"repeat", repeat}, {"kernel", o.kernel},
                {"packets", o.kernel != "packet" ? "none" : image_width > 0 ? "4x4 pixels" : "8 consecutive rays"},
                {"build_ms", rounded(median(build_ms), 3)}, {"mrays_per_s", rounded(mrays, 3)},
                {"hits", sum.hits}, {"prim_sum", sum.prim_sum}, {"t_sum", rounded(sum.t_sum, 6)},
                {"nodes_per_ray", rounded(static_cast<double>(counters.nodes_visited) * per_ray, 2)},
                {"triangle_tests_per_ray", rounded(static_cast<double>(counters.triangle_tests) * per_ray, 2)},
                {"stack_overflows", counters.stack_overflows},
                {"build_cpu_ms", rounded(median(build_cpu), 3)}, {"trace_cpu_ms", rounded(median(trace_cpu), 3)}};
  // The last build's phases (build_ms covers all of them: refs, binary tree, both layouts).
  const trace::BvhStats& st = bvh.stats();
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(bvh.content_hash()));
  j["bvh"] = {{"hash", hash}, {"leaves", st.leaves}, {"triangle_packs", st.triangle_packs},
              {"wide_nodes", st.wide_nodes}, {"refs_ms", rounded(st.refs_ms, 1)}, {"top_ms", rounded(st.top_ms, 1)},
              {"subtrees_ms", rounded(st.subtrees_ms, 1)}, {"splice_ms", rounded(st.splice_ms, 1)},
              {"layouts_ms", rounded(st.layouts_ms, 1)}};
#ifdef SPECULUM_HAVE_EMBREE
  if (!o.no_embree) {
    const EmbreeFigures e = run_embree(scene, rays, image_width, repeat, ex);
    j["embree"] = {{"version", std::to_string(RTC_VERSION_MAJOR) + "." + std::to_string(RTC_VERSION_MINOR) + "." +
                                   std::to_string(RTC_VERSION_PATCH)},
                   {"build_ms", rounded(e.build_ms, 3)}, {"mrays_per_s_intersect1", rounded(e.mrays1, 3)},
                   {"mrays_per_s_intersect16", rounded(e.mrays16, 3)},
                   {"intersect16_packets", image_width > 0 ? "4x4 pixels" : "16 consecutive rays"},
                   {"intersect16_hits", e.sum16.hits}, {"intersect16_t_sum", rounded(e.sum16.t_sum, 6)},
                   {"hits", e.sum.hits},
                   {"prim_sum", e.sum.prim_sum}, {"t_sum", rounded(e.sum.t_sum, 6)}};
    j["ratio_vs_intersect1"] = rounded(mrays / std::max(e.mrays1, 1e-9), 3);
    j["ratio_vs_intersect16"] = rounded(mrays / std::max(e.mrays16, 1e-9), 3);
    j["build_ratio"] = rounded(median(build_ms) / std::max(e.build_ms, 1e-9), 3);
    // CPU-time ratios (see cpu_ms): throughput ours / rtcIntersect1, build ours / Embree.
    j["cpu_ratio_vs_intersect1"] = rounded(e.trace1_cpu_ms / std::max(median(trace_cpu), 1e-9), 3);
    j["build_cpu_ratio"] = rounded(median(build_cpu) / std::max(e.build_cpu_ms, 1e-9), 3);
  }
#endif
  std::printf("%s\n", json_line(j).c_str());
}

}  // namespace

void add_bench_trace_subcommand(CLI::App& bench, GlobalOptions& global) {
  auto opt = std::make_shared<BenchTraceOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "trace",
      "Trace a SPRY ray file against a PLY mesh (ours, and Embree when built with it); print JSON.\n"
      "  speculum bench trace --make-mesh spheres:100 -o spheres.ply\n"
      "  speculum bench trace spheres.ply --emit-rays primary -o primary.spry\n"
      "  speculum --threads 2 bench trace spheres.ply --rays primary.spry --repeat 5 --json");
  cmd->footer("Example: the three commands above make a mesh, emit primary rays and time them.");
  cmd->add_option("mesh", opt->mesh, "Mesh file (PLY, OBJ, OFF, STL) or built-in scene");
  cmd->add_option("--rays", opt->rays, "SPRY ray file to trace");
  cmd->add_option("--repeat", opt->repeat, "Runs; medians are reported")->check(CLI::Range(1, 1000))->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON object (the only output format)");
  cmd->add_option("--emit-rays", opt->emit, "Write a ray file instead: primary, reflect-cone30 or hemisphere");
  cmd->add_option("--make-mesh", opt->make_mesh, "Write a test mesh instead: spheres:N (N UV-spheres in a box room)");
  cmd->add_option("-o,--output", opt->output, "Output file of --emit-rays / --make-mesh");
  cmd->add_option("--width", opt->width, "Image width for --emit-rays")->check(CLI::Range(1, 65536))->capture_default_str();
  cmd->add_option("--height", opt->height, "Image height for --emit-rays")->check(CLI::Range(1, 65536))->capture_default_str();
  cmd->add_option("--eye", opt->eye, "Camera eye x,y,z (default: inside the mesh bounds)");
  cmd->add_option("--target", opt->target, "Camera target x,y,z");
  cmd->add_option("--up", opt->up, "Camera up x,y,z");
  cmd->add_option("--fov", opt->fov, "Vertical field of view, degrees")->check(CLI::Range(0.01, 179.0))->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the secondary ray directions")->capture_default_str();
  cmd->add_flag("--no-embree", opt->no_embree, "Skip the Embree comparison");
  cmd->add_option("--image-width", opt->image_width,
                  "The rays are a camera image this wide (one per pixel, row-major): our packet kernel and\n"
                  "Embree's rtcIntersect16 get 4x4 pixel packets. Default: detected (--width x --height rays\n"
                  "from one origin)")
      ->check(CLI::Range(1, 65536));
  cmd->add_option("--kernel", opt->kernel,
                  "Our closest-hit kernel: packet (4x4-pixel packets of a camera image, else 8 consecutive rays;\n"
                  "single-ray fallback when incoherent) or single")
      ->capture_default_str();
  cmd->callback([opt, &global] { run_bench_trace(*opt, global); });
}

}  // namespace speculum::cli
