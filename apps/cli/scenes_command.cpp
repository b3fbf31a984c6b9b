// `speculum scenes list|export`: the built-in procedural scene library and glTF export.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/cli/commands.h"
#include "core/gltf_writer.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"

namespace speculum::cli {
namespace {

struct ExportOptions {
  std::string scene;
  std::string output;
  std::uint64_t size = 0;
};

void list_scenes() {
  std::printf("Built-in scenes (size: approximate triangle count, %llu..%llu):\n",
              static_cast<unsigned long long>(kMinSceneSize),
              static_cast<unsigned long long>(kMaxSceneSize));
  for (const BuiltinScene& s : builtin_scenes()) {
    std::printf("  %-16s %s\n", s.name, s.description);
    std::printf("  %-16s default size %llu%s%s\n", "",
                static_cast<unsigned long long>(s.default_size),
                *s.extra_params ? "; options: " : "", s.extra_params);
  }
  std::printf("Use NAME, NAME:size=N or NAME:size=N,key=value wherever a scene is expected,\n"
              "e.g. `speculum info bumpy-sphere:size=200k,n=12`.\n");
}

}  // namespace

void add_scenes_command(CLI::App& app, GlobalOptions& global) {
  auto* cmd = app.add_subcommand("scenes", "List or export the built-in procedural scenes");
  cmd->footer("Example: speculum scenes list\n         speculum scenes export glossy-plane plane.glb");
  cmd->require_subcommand(1);
  auto* list = cmd->add_subcommand("list", "List the built-in scenes with descriptions and sizes");
  list->footer("Example: speculum scenes list");
  list->callback(list_scenes);

  auto opts = std::make_shared<ExportOptions>();
  auto* exp = cmd->add_subcommand(
      "export",
      "Write a scene (built-in name or file) as glTF 2.0: .glb (binary) or .gltf (embedded)\n"
      "Example: speculum scenes export living-room room.glb --size 200000");
  exp->add_option("scene", opts->scene, "Built-in scene name (NAME[:size=N,...]) or scene file")
      ->required();
  exp->add_option("output", opts->output, "Output file, .glb or .gltf")->required();
  exp->add_option("--size", opts->size,
                  "Approximate triangle count for built-in scenes (0: the scene's default)")
      ->capture_default_str();
  exp->callback([opts, &global] {
    LoadReport report;
    SceneOptions so;
    so.size = opts->size;
    so.report = &report;
    const Scene scene = load_scene(opts->scene, so);
    write_gltf(scene, opts->output);
    if (!global.quiet)
      std::printf("wrote %s: %zu triangles, %zu vertices, %zu materials, %zu textures, "
                  "%zu cameras, %zu lights\n",
                  opts->output.c_str(), scene.mesh.triangle_count(), scene.mesh.vertex_count(),
                  scene.materials.size(), scene.textures.size(), scene.cameras.size(),
                  scene.lights.size());
  });
}

}  // namespace speculum::cli
