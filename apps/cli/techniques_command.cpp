// `speculum techniques`: one line per technique (name and summary), then its parameters
// with their defaults and valid ranges, from the technique table.
#include <algorithm>
#include <cstdio>
#include <string>

#include "apps/cli/commands.h"
#include "apps/techniques/technique_table.h"

namespace speculum::cli {

void add_techniques_command(CLI::App& app, GlobalOptions&) {
  auto* cmd = app.add_subcommand("techniques", "List the rendering techniques, one per line");
  cmd->footer("Example: speculum techniques   (then: speculum render --technique NAME)");
  cmd->callback([] {
    int width = 0;  // names in one aligned column
    for (const auto& t : pipeline::techniques()) width = std::max(width, int(t.name.size()));
    for (const auto& t : pipeline::techniques()) {
      std::printf("%-*s  %s\n", width, t.name.c_str(), t.summary.c_str());
      std::fputs(t.describe_params(std::string(width + 4, ' ') + "--param ").c_str(), stdout);
    }
  });
}

}  // namespace speculum::cli
