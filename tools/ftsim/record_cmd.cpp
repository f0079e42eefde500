// `ftsim record` — placeholder until recordings with effects land (issue 3/7).
#include <cstdio>
#include <cstdlib>

#include "tools/ftsim/commands.hpp"

namespace ftstack::tools {

void AddRecordCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("record", "simulated recordings (not yet available)");
  cmd->callback([] {
    std::fprintf(stderr, "ftsim record: not available in this build yet\n");
    std::exit(2);
  });
}

}  // namespace ftstack::tools
