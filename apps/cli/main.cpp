// speculum: render, inspect, profile and compare GPU reflection techniques on the CPU.
#include <cstdio>
#include <exception>
#include <string>

#include "apps/cli/commands.h"
#include "core/error.h"
#include "parallel/graph.h"

int main(int argc, char** argv) {
  using namespace speculum;
  CLI::App app{
      "speculum — a deterministic CPU renderer for specular and glossy reflections,\n"
      "refractions and caustics: each GPU technique is a pass in a job graph.\n"
      "Example: speculum render sphere-in-room -o out.png",
      "speculum"};
  app.set_version_flag("--version", "speculum 0.1.0");
  app.require_subcommand(1);
  cli::GlobalOptions global;
  app.add_option("--threads", global.threads, "Worker threads (0: all cores; 1: synchronous)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_option("--lanes", global.lanes, "SIMD lane width 1, 4, 8 or 16 (0: widest built)")
      ->check(CLI::IsMember({0, 1, 4, 8, 16}))
      ->capture_default_str();
  app.add_flag("--quiet,-q", global.quiet, "No progress output or warnings on stderr");
  // The global options may also follow the subcommand (`speculum bench trace m.ply --threads 2`):
  // a subcommand hands options it does not know to its parent, and every subcommand, nested
  // ones included, inherits this setting when it is added below.
  app.fallthrough();

  cli::add_scenes_command(app, global);
  cli::add_info_command(app, global);
  cli::add_render_command(app, global);
  cli::add_techniques_command(app, global);
  cli::add_bench_command(app, global);
  cli::add_experiment_command(app, global);
  cli::add_inspect_command(app, global);
  cli::add_profile_command(app, global);
  cli::add_compare_command(app, global);
  cli::add_matrix_command(app, global);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "speculum: %s\n", e.what());
    return 2;
  } catch (const cli::ExitStatus& e) {  // a command's own verdict (compare: 1 = outside the bound)
    return e.code;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "speculum: out of memory (input too large?)\n");
    return 2;
  } catch (const par::NodeError& e) {
    // A pass failed: bad input found inside a pass (a degenerate camera, an absurd size) is
    // still bad input, named by its own message; anything else names the pass.
    try {
      std::rethrow_exception(e.cause());
    } catch (const InputError& input) {
      std::fprintf(stderr, "speculum: %s\n", input.what());
      return 2;
    } catch (const std::bad_alloc&) {
      std::fprintf(stderr, "speculum: out of memory in %s (input too large?)\n", e.node().c_str());
      return 2;
    } catch (...) {
    }
    std::fprintf(stderr, "speculum: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "speculum: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
