// `speculum scenes list|export` — placeholder until the built-in scene library lands.
#include "apps/cli.h"

namespace speculum::cli {

void add_scenes_command(CLI::App& app, GlobalOptions&) {
  auto* cmd = app.add_subcommand("scenes", "List or export the built-in procedural scenes");
  cmd->require_subcommand(1);
  cmd->add_subcommand("list", "List the built-in scenes");
}

void add_info_command(CLI::App& app, GlobalOptions&) {
  app.add_subcommand("info", "Print a scene's counts, bounds and material kinds");
}

}  // namespace speculum::cli
