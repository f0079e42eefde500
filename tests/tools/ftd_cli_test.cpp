// ftd as a program: bad options and unusable files give exit 2 and one line naming the problem.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <algorithm>

#include "tests/system/ftd_process.hpp"

namespace ftstack {
namespace {

struct BadCase {
  std::vector<std::string> args;
  std::string mentions;  ///< text the one-line reason must contain
};

TEST(FtdCli, BadInputGivesExit2AndOneLineNamingIt) {
  // (An unusable calibration file is not among them: a field device comes up without it and
  // says why — tests/system/ftd_modbus_test.cpp, FtdModbus.UnusableCalibrationFiles….)
  const std::vector<BadCase> cases = {
      {{"--modbus-tcp", "127.0.0.1:99999"}, "99999"},
      {{"--modbus-tcp", "127.0.0.1"}, "HOST:PORT"},
      {{"--modbus-rtu", "/nonexistent/tty"}, "/nonexistent/tty"},
      {{"--sim-wrench", "1,2,3,4,5,nan"}, "nan"},
      {{"--sim-wrench", "1,2,3"}, "6 values"},
      {{"--log", "/nonexistent/dir/rec.csv"}, "/nonexistent/dir/rec.csv"},
  };
  for (const BadCase& c : cases) {
    std::vector<std::string> args = c.args;
    args.insert(args.end(), {"--duration-s", "0.2", "--print-hz", "0"});
    test::FtdProcess p(args, false);
    EXPECT_EQ(p.Wait(10.0), 2) << c.args[0] << " " << c.args[1];
    const std::string err = p.Stderr();
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
    EXPECT_NE(err.find(c.mentions), std::string::npos) << err;
    EXPECT_EQ(err.rfind("ftd: ", 0), 0u) << err;
  }
}

TEST(FtdCli, PortInUseIsAOneLineError) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)), 0);
  ASSERT_EQ(listen(fd, 1), 0);
  socklen_t len = sizeof(a);
  ASSERT_EQ(getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len), 0);
  const std::string where = "127.0.0.1:" + std::to_string(ntohs(a.sin_port));
  test::FtdProcess p({"--modbus-tcp", where, "--duration-s", "0.2"}, false);
  EXPECT_EQ(p.Wait(10.0), 2);
  EXPECT_NE(p.Stderr().find(where), std::string::npos) << p.Stderr();
  close(fd);
}

}  // namespace
}  // namespace ftstack
