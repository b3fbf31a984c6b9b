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

// "512x256 equirect x 0.5" or "constant 0.05 0.05 0.05 x 1", for the export warning.
std::string environment_summary(const Environment& env) {
  char text[160];
  if (env.has_image())
    std::snprintf(text, sizeof text, "%dx%d equirect x %g", env.equirect.width,
                  env.equirect.height, static_cast<double>(env.intensity));
  else
    std::snprintf(text, sizeof text, "constant %g %g %g x %g", static_cast<double>(env.constant.x),
                  static_cast<double>(env.constant.y), static_cast<double>(env.constant.z),
                  static_cast<double>(env.intensity));
  return text;
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
      "Write a scene (built-in name or file) as glTF 2.0: .glb (binary) or .gltf (embedded);\n"
      "the environment goes into the root extras, which only speculum reads back\n"
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
    if (!global.quiet) {
      // What the loader skipped or repaired is not in the export either.
      for (const std::string& w : report.warnings)
        std::fprintf(stderr, "speculum: warning: %s: %s\n", opts->scene.c_str(), w.c_str());
      // Only speculum reads the environment back (gltf_environment.h); a black one loses nothing.
      const Environment& env = scene.environment;
      if (env.intensity != 0.0f && (env.has_image() || env.constant != glm::vec3(0.0f)))
        std::fprintf(stderr,
                     "speculum: warning: %s: the environment (%s) is stored in the root "
                     "extras.speculum_environment; other glTF viewers will not show it\n",
                     opts->output.c_str(), environment_summary(env).c_str());
    }
    if (!global.quiet)
      std::printf("wrote %s: %zu triangles, %zu vertices, %zu materials, %zu textures, "
                  "%zu cameras, %zu lights\n",
                  opts->output.c_str(), scene.mesh.triangle_count(), scene.mesh.vertex_count(),
                  scene.materials.size(), scene.textures.size(), scene.cameras.size(),
                  scene.lights.size());
  });
}

}  // namespace speculum::cli
