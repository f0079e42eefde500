// `ftsim pivot` — placeholder until the pivot solver lands (issue 3).
#include <cstdio>
#include <cstdlib>

#include "tools/ftsim/commands.hpp"

namespace ftstack::tools {

void AddPivotCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("pivot", "crossed-strip flexure pivot (not yet available)");
  cmd->callback([] {
    std::fprintf(stderr, "ftsim pivot: not available in this build yet\n");
    std::exit(2);
  });
}

}  // namespace ftstack::tools
