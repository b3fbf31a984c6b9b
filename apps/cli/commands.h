// The speculum command line: global options and the subcommand registration hooks.
// Each subcommand lives in its own *_command.cpp (apps/cli, inspect, bench, experiments) and
// is added by main.cpp.
#pragma once

#include <CLI/CLI.hpp>

namespace speculum::cli {

struct GlobalOptions {
  int threads = 0;  // 0: all cores
  int lanes = 0;    // 0: the widest the build's ISA supports
  bool quiet = false;
};

// Each add_* adds one subcommand (with its own --help) to `app`.
void add_scenes_command(CLI::App& app, GlobalOptions& global);
void add_info_command(CLI::App& app, GlobalOptions& global);
void add_render_command(CLI::App& app, GlobalOptions& global);
void add_techniques_command(CLI::App& app, GlobalOptions& global);
// inspect / profile (apps/inspect/) and compare (compare_command.cpp): the tools that show
// and judge a technique's passes.
void add_inspect_command(CLI::App& app, GlobalOptions& global);
void add_profile_command(CLI::App& app, GlobalOptions& global);
void add_compare_command(CLI::App& app, GlobalOptions& global);
// matrix (apps/matrix/): every technique × scene, timed and judged against cached references.
void add_matrix_command(CLI::App& app, GlobalOptions& global);
// Thrown by a command whose result is an exit status (compare: 1 when outside the bound);
// main returns `code` without printing anything more.
struct ExitStatus {
  int code = 1;
};

// `bench` parent (apps/bench/bench_command.cpp) and its children, one per bench_*_command.cpp.
void add_bench_command(CLI::App& app, GlobalOptions& global);
void add_bench_trace_subcommand(CLI::App& bench, GlobalOptions& global);
void add_bench_raster_subcommand(CLI::App& bench, GlobalOptions& global);

// `experiment` parent (apps/experiments/experiment_command.cpp) and its children, one per experiments/*.cpp.
void add_experiment_command(CLI::App& app, GlobalOptions& global);
void add_experiment_yu_fig9_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_survey_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_ray_hierarchy_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_cone_tracing_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_vertex_projection_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_soff_subcommand(CLI::App& experiment, GlobalOptions& global);
void add_experiment_caustics_subcommand(CLI::App& experiment, GlobalOptions& global);

}  // namespace speculum::cli
