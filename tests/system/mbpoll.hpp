// mbpoll, the independent Modbus client of the system tests: run it, read its "[ref]: value" lines.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <map>
#include <sstream>
#include <string>

namespace ftstack::test {

/// Runs a shell command, returns its exit status and combined output.
inline int RunShell(const std::string& cmd, std::string* output) {
  std::FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return -1;
  char buf[512];
  output->clear();
  while (std::fgets(buf, sizeof(buf), p) != nullptr) *output += buf;
  const int status = pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// mbpoll's "[ref]: value" lines.
inline std::map<int, double> ParseMbpoll(const std::string& out) {
  std::map<int, double> v;
  std::istringstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    int ref = 0;
    double value = 0;
    if (std::sscanf(line.c_str(), "[%d]: %lf", &ref, &value) == 2) v[ref] = value;
  }
  return v;
}

}  // namespace ftstack::test
