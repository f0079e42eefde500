#include <cstdio>

#include "tools/diag/cli.hpp"

namespace ftstack::diag {

void AddDemoCommand(CLI::App& app, int* exit_code) {
  static std::string effect;
  auto* d = app.add_subcommand(
      "demo", "make a concealed-effect recording with the simulator and diagnose it");
  d->add_option("EFFECT", effect, "effect name from the vocabulary")->required();
  d->callback([exit_code] {
    std::fprintf(stderr, "ftdiag demo: needs `ftsim record --effect`, not in this build yet\n");
    *exit_code = 2;
  });
}

}  // namespace ftstack::diag
