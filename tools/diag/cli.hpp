// The ftdiag command line (diagnose, demo): options, progress bar, one-line errors.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "tools/diag/diagnose.hpp"

namespace ftstack::diag {

struct DiagnoseArgs {
  std::string sim;
  std::string model;
  std::string real;
  std::string json;
  std::string html;
  bool no_pairs = false;
  double block_s = 0.5;
};

/// Runs `ftdiag diagnose`; returns the exit code (0 on a completed diagnosis, 2 on bad input) and
/// prints a one-line reason to stderr on failure.
int RunDiagnose(const DiagnoseArgs& args);

/// Registers the subcommands on `app`; their exit code is available from LastExitCode().
void AddCommands(CLI::App& app);
int LastExitCode();
/// Registers `ftdiag demo EFFECT` (demo.cpp).
void AddDemoCommand(CLI::App& app, int* exit_code);

/// Writes the JSON report to a file; throws std::runtime_error naming the file on failure.
void WriteJson(const std::string& path, const nlohmann::json& j);

}  // namespace ftstack::diag
