// `speculum experiment NAME`: the paper-reproduction sweeps (YU Fig.9, the SURVEY
// techniques, ROGER's ray hierarchy and vertex projection). Each experiment is a child subcommand in its own file
// techniques, SURVEY §6 caustics, ROGER's ray hierarchy). Each experiment is a child subcommand in its own file
// of apps/experiments/, registered here.
#include "apps/cli/commands.h"

namespace speculum::cli {

void add_experiment_command(CLI::App& app, GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "experiment", "Reproduce a paper's measurements: sweeps that print a table (or --json rows)");
  cmd->require_subcommand(1);
  cmd->footer("Example: speculum experiment NAME --help   (NAME: one of the subcommands above)");
  // One line per experiment (apps/cmd_experiment_*.cpp):
  add_experiment_survey_subcommand(*cmd, global);
  add_experiment_ray_hierarchy_subcommand(*cmd, global);
  add_experiment_cone_tracing_subcommand(*cmd, global);
  add_experiment_yu_fig9_subcommand(*cmd, global);
  add_experiment_vertex_projection_subcommand(*cmd, global);
  add_experiment_soff_subcommand(*cmd, global);
  add_experiment_caustics_subcommand(*cmd, global);
  (void)global;
}

}  // namespace speculum::cli
