// `speculum bench`: the parent of the benchmark subcommands (`bench trace`, and `bench
// raster` from the raster helper). Each child registers itself from its own cmd_bench_*.cpp
// through an add_bench_*_subcommand(bench, global) declared in apps/cli/commands.h: to add one,
// declare it there and call it below.
#include "apps/cli/commands.h"

namespace speculum::cli {

void add_bench_command(CLI::App& app, GlobalOptions& global) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: trace (BVH vs Embree), ...");
  bench->footer("Example: speculum bench raster bench:spheres-room --repeat 5\n"
                "         speculum bench trace --help   (ray files and meshes for the trace benchmark)");
  bench->require_subcommand(1);
  add_bench_trace_subcommand(*bench, global);
  add_bench_raster_subcommand(*bench, global);
}

}  // namespace speculum::cli
