// Test helper: runs the built ftcal with arguments; returns its exit code and output.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace ftstack::test {

/// Runs `ftcal ARGS` (stdout and stderr into *out); exit code, or -1 if it did not exit.
inline int RunFtcal(const std::string& args, std::string* out) {
  const std::string cmd = std::string(FTSTACK_BIN_DIR) + "/ftcal " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  char buf[4096];
  while (p != nullptr && std::fgets(buf, sizeof buf, p) != nullptr) *out += buf;
  const int status = p != nullptr ? pclose(p) : -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace ftstack::test
