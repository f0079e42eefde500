// Test helper: runs the real ftd binary on a free loopback port and stops it by PID.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace ftstack::test {

/// A child ftd process. Its stderr goes to a file; with --modbus-tcp 127.0.0.1:0 the port it bound
/// is read from its "serving Modbus TCP on HOST:PORT" line. `wrapper` (absolute path first) runs
/// ftd through a program that execs it, e.g. setpriv, so that the PID stays ftd's.
class FtdProcess {
 public:
  explicit FtdProcess(std::vector<std::string> args, bool want_tcp = true,
                      std::vector<std::string> wrapper = {}) {
    char tmpl[] = "/tmp/ftd_test_stderr_XXXXXX";
    const int fd = mkstemp(tmpl);
    stderr_path_ = tmpl;
    std::vector<std::string> argv_s = wrapper;
    argv_s.push_back(std::string(FTSTACK_BIN_DIR) + "/ftd");
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, fd, STDERR_FILENO);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    if (posix_spawn(&pid_, argv[0], &fa, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
    close(fd);
    if (want_tcp) port_ = WaitForPort();
  }
  ~FtdProcess() {
    if (pid_ > 0 && !reaped_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    std::remove(stderr_path_.c_str());
  }
  FtdProcess(const FtdProcess&) = delete;
  FtdProcess& operator=(const FtdProcess&) = delete;

  [[nodiscard]] int port() const { return port_; }
  /// The port of a "serving WHAT on HOST:PORT" line on stderr (e.g. "RDT"), waiting up to 5 s;
  /// -1 when none appears.
  [[nodiscard]] int ServedPort(const std::string& what) const {
    const std::regex re("serving " + what + " on [^:]+:([0-9]+)");
    for (int i = 0; i < 500; ++i) {
      std::smatch m;
      const std::string err = Stderr();
      if (std::regex_search(err, m, re)) return std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  [[nodiscard]] pid_t pid() const { return pid_; }
  [[nodiscard]] bool alive() const { return pid_ > 0 && !reaped_ && kill(pid_, 0) == 0; }

  /// Sends `sig` and waits (up to 10 s) for the exit; returns the exit status (-1: no clean exit).
  int Stop(int sig = SIGTERM) {
    if (pid_ <= 0 || reaped_) return -1;
    kill(pid_, sig);
    return Wait(10.0);
  }
  /// Waits up to `timeout_s` for the process to exit by itself; exit status or -1.
  int Wait(double timeout_s) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        reaped_ = true;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }
  [[nodiscard]] std::string Stderr() const {
    std::ifstream in(stderr_path_);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

 private:
  /// Up to 60 s: a sanitizer build composing a long simulated profile on a loaded machine takes
  /// more than 10 s before it serves; a process that dies ends the wait at once.
  int WaitForPort() {
    const std::regex re("serving Modbus TCP on [^:]+:([0-9]+)");
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (std::chrono::steady_clock::now() < deadline && alive()) {
      std::smatch m;
      const std::string err = Stderr();
      if (std::regex_search(err, m, re)) return std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return -1;
  }

  pid_t pid_ = -1;
  int port_ = -1;
  bool reaped_ = false;
  std::string stderr_path_;
};

}  // namespace ftstack::test
