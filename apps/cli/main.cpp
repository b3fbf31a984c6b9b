// speculum: render, inspect, profile and compare GPU reflection techniques on the CPU.
#include <malloc.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "apps/cli/commands.h"
#include "core/did_you_mean.h"
#include "core/error.h"
#include "parallel/graph.h"
#include "parallel/interrupt.h"

namespace {

// Ctrl-C: the run stops at the next chunk boundary (parallel/interrupt.h) and main exits 130
// without writing; a second Ctrl-C ends the process at once (nothing is ever renamed into
// place half-written: outputs go through temporary files).
extern "C" void on_sigint(int) {
  speculum::par::request_interrupt();
  std::signal(SIGINT, SIG_DFL);
}

// CLI11's message on one line (its own newlines folded; app.exit's "Run with --help" line is
// replaced by a short hint).
std::string one_line(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  for (char& c : text)
    if (c == '\n') c = ' ';
  return text;
}

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  return names;
}

// The argument that is a typo of a subcommand ("rendr"), when none was recognised (CLI11
// reports that as an unexpected argument or a missing subcommand); "" otherwise.
std::string subcommand_typo(const CLI::App& app, int argc, char** argv) {
  if (!app.get_subcommands().empty()) return "";
  const std::vector<std::string> names = subcommand_names(app);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.empty() || arg[0] == '-') continue;
    if (!speculum::closest_name(arg, names).empty()) return arg;
  }
  return "";
}

// The subcommand a command line names: its first word that is one ("" when none is).
std::string subcommand_named(const CLI::App& app, int argc, char** argv) {
  const std::vector<std::string> names = subcommand_names(app);
  for (int i = 1; i < argc; ++i)
    if (std::find(names.begin(), names.end(), argv[i]) != names.end()) return argv[i];
  return "";
}

}  // namespace

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

  // A frame allocates and frees images and planes of a few MB each (per pass, per cube
  // face). glibc serves blocks that large with fresh mappings and unmaps them on free, so
  // every frame faulted its pages in again, zeroed, often on one thread between two
  // kernels (about a tenth of a cube-map technique's CPU). Freed memory now stays in the
  // heap for the next frame's blocks; the peak resident size is unchanged (one frame's).
  // One arena for all threads: a worker thread's arena is a set of 64 MiB heaps, each
  // unmapped as soon as it is all free, which a frame's churn of images does, so the next
  // frame faulted them in again (refraction's reflector maps: 48 ms of serial gaps). A
  // frame makes about 3000 allocations, so one arena's lock costs nothing.
  // Not for `bench`: its builds are timed on fresh memory, as a program building once
  // sees it, and it measures against yardsticks that run with glibc's defaults.
  if (subcommand_named(app, argc, argv) != "bench") {
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    mallopt(M_ARENA_MAX, 1);
  }

  std::signal(SIGINT, on_sigint);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version: CLI11 prints them
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other error (CLI11's own adds a second one).
    const std::string typo = subcommand_typo(app, argc, argv);
    if (!typo.empty())
      std::fprintf(stderr, "speculum: unknown subcommand '%s' (did you mean '%s'?)\n", typo.c_str(),
                   speculum::closest_name(typo, subcommand_names(app)).c_str());
    else
      std::fprintf(stderr, "speculum: %s (see --help)\n", one_line(e.what()).c_str());
    return 2;
  } catch (const par::Interrupted&) {
    std::fprintf(stderr, "speculum: interrupted (Ctrl-C); the output under way was not written\n");
    return 130;
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
    } catch (const par::Interrupted&) {
      std::fprintf(stderr, "speculum: interrupted (Ctrl-C); the output under way was not written\n");
      return 130;
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
