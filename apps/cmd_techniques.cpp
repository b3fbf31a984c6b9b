// `speculum techniques`: one line per technique (name and summary).
#include <cstdio>

#include "apps/cli.h"
#include "apps/pipeline_techniques.h"

namespace speculum::cli {

void add_techniques_command(CLI::App& app, GlobalOptions&) {
  auto* cmd = app.add_subcommand("techniques", "List the rendering techniques, one per line");
  cmd->footer("Example: speculum techniques   (then: speculum render --technique NAME)");
  cmd->callback([] {
    for (const auto& t : pipeline::techniques())
      std::printf("%-12s %s\n", t.name.c_str(), t.summary.c_str());
  });
}

}  // namespace speculum::cli
