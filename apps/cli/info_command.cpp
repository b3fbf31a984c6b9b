// `speculum info FILE|NAME`: counts, bounds, material kinds and objects of a scene.
#include <array>
#include <cstdio>
#include <memory>
#include <string>

#include "apps/cli/commands.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

struct InfoOptions {
  std::string scene;
  std::uint64_t size = 0;
  std::size_t max_objects = 20;
};

void print_info(const InfoOptions& o) {
  LoadReport report;
  SceneOptions so;
  so.size = o.size;
  so.report = &report;
  const Scene s = load_scene(o.scene, so);
  const Bounds b = s.bounds();
  std::printf("scene:       %s\n", s.name.c_str());
  std::printf("triangles:   %zu\n", s.mesh.triangle_count());
  std::printf("vertices:    %zu\n", s.mesh.vertex_count());
  std::printf("objects:     %zu\n", s.objects.size());
  std::array<std::size_t, 4> kinds{};
  for (const auto& m : s.materials) ++kinds[static_cast<std::size_t>(m.kind())];
  std::printf("materials:   %zu (diffuse %zu, glossy %zu, mirror %zu, refractor %zu)\n",
              s.materials.size(), kinds[0], kinds[1], kinds[2], kinds[3]);
  std::printf("textures:    %zu\n", s.textures.size());
  std::array<std::size_t, 3> lights{};
  for (const auto& l : s.lights) ++lights[static_cast<std::size_t>(l.type)];
  std::printf("lights:      %zu (point %zu, spot %zu, directional %zu)\n", s.lights.size(),
              lights[0], lights[1], lights[2]);
  std::printf("cameras:     %zu", s.cameras.size());
  for (const auto& c : s.cameras) std::printf(" '%s'", c.name.c_str());
  std::printf("\n");
  std::printf("bounds:      (%g, %g, %g) .. (%g, %g, %g)\n", b.lo.x, b.lo.y, b.lo.z, b.hi.x,
              b.hi.y, b.hi.z);
  if (s.environment.has_image())
    std::printf("environment: %dx%d equirect (%s) x %g\n", s.environment.equirect.width,
                s.environment.equirect.height, s.environment.source.c_str(),
                s.environment.intensity);
  else
    std::printf("environment: constant (%g, %g, %g)\n", s.environment.constant.x,
                s.environment.constant.y, s.environment.constant.z);
  std::printf("material list:\n");
  for (const auto& m : s.materials)
    std::printf("  %-24s %-9s roughness %.2f metallic %.2f%s\n", m.name.c_str(), to_string(m.kind()),
                m.roughness, m.metallic, m.transmission > 0 ? " transmissive" : "");
  std::printf("object list:\n");
  for (std::size_t i = 0; i < s.objects.size() && i < o.max_objects; ++i) {
    const auto& obj = s.objects[i];
    std::printf("  %-24s %9u triangles  material '%s'\n", obj.name.c_str(), obj.triangle_count,
                s.materials[obj.material].name.c_str());
  }
  if (s.objects.size() > o.max_objects)
    std::printf("  ... %zu more (--objects N to list more)\n", s.objects.size() - o.max_objects);
  if (!report.warnings.empty() || report.skipped_primitives) {
    std::printf("warnings:    %zu (skipped primitives: %llu)\n", report.warnings.size(),
                static_cast<unsigned long long>(report.skipped_primitives));
    for (const auto& w : report.warnings) std::printf("  %s\n", w.c_str());
  }
}

}  // namespace

void add_info_command(CLI::App& app, GlobalOptions&) {
  auto opts = std::make_shared<InfoOptions>();
  auto* cmd = app.add_subcommand(
      "info",
      "Print a scene's counts (triangles, vertices, materials, lights, cameras, textures),\n"
      "bounds, material kinds and objects.\n"
      "SCENE is a .gltf/.glb/.obj/.ply/.off/.stl file or a built-in name (`scenes list`).\n"
      "Example: speculum info glass-sphere:size=100k");
  cmd->add_option("scene", opts->scene, "Scene file or built-in scene name")->required();
  cmd->add_option("--size", opts->size,
                  "Approximate triangle count for built-in scenes (0: the scene's default)")
      ->capture_default_str();
  cmd->add_option("--objects", opts->max_objects, "List at most this many objects")
      ->capture_default_str();
  cmd->callback([opts] { print_info(*opts); });
}

}  // namespace speculum::cli
