// The tare history end to end: ftd's simulated sensor holds five different loads at five
// temperatures (a --sim-profile), a tare is asked for in each hold — over Modbus with mbpoll, and
// once over RDT (UDP) —, and the history (input 210–289) read back with mbpoll must hold the last
// four: number, who asked, when, the temperature and the load the profile applied, per axis. A
// tare on a converter without a temperature input records none (NaN), not the simulator's.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/support/temp_dir.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/mbpoll.hpp"
#include "tests/system/sim_noise.hpp"

namespace ftstack {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kHoldS = 8.0;  ///< each load is held this long (simulated), after a 0.5 s ramp

/// One hold of the profile: the load (N, N·m, sensor frame) and the temperature.
struct Hold {
  std::array<double, 6> wrench;
  double temp_c;
};
const std::vector<Hold>& Holds() {
  static const std::vector<Hold> h = {
      {{10, -5, 120, 0.5, -0.2, 0.1}, 22.0},   {{-30, 15, -80, -1.0, 0.8, -0.3}, 24.0},
      {{0, 40, 200, 2.0, 0, 0.6}, 21.0},       {{25, 25, -150, 0, -1.5, -0.5}, 23.0},
      {{-60, -10, 60, -0.4, 1.2, 0.25}, 20.0},
  };
  return h;
}
/// Hold i starts (its ramp ends) at this simulated time.
double HoldStart(std::size_t i) { return 1.0 + (kHoldS + 0.5) * static_cast<double>(i) + 0.5; }

std::string Profile(const test::TempDir& dir) {
  std::string k = "{\"t_s\":0,\"wrench\":[0,0,0,0,0,0],\"temp_C\":20}";
  auto frame = [](double t, const Hold& h) {
    std::string s = ",{\"t_s\":" + std::to_string(t) + ",\"wrench\":[";
    for (std::size_t a = 0; a < 6; ++a) s += (a ? "," : "") + std::to_string(h.wrench[a]);
    return s + "],\"temp_C\":" + std::to_string(h.temp_c) + "}";
  };
  for (std::size_t i = 0; i < Holds().size(); ++i) {
    k += frame(HoldStart(i), Holds()[i]) + frame(HoldStart(i) + kHoldS, Holds()[i]);
  }
  const std::string path = (dir.path() / "holds.json").string();
  std::ofstream(path) << "{\"schema\":\"ftstack-profile/1\",\"keyframes\":[" << k
                      << "],\"rate_hz\":1000}";
  return path;
}

class Mbpoll {
 public:
  explicit Mbpoll(int port) : port_(port) {}
  std::map<int, double> Read(const std::string& type, int addr, int count) {
    std::string out;
    const std::string cmd = "mbpoll -m tcp -p " + std::to_string(port_) + " -a 1 -t " + type +
                            " -B -0 -r " + std::to_string(addr) + " -c " + std::to_string(count) +
                            " -1 127.0.0.1";
    if (test::RunShell(cmd, &out) != 0) ADD_FAILURE() << cmd << "\n" << out;
    return test::ParseMbpoll(out);
  }
  bool Tare() {
    std::string out;
    return test::RunShell(
               "mbpoll -m tcp -p " + std::to_string(port_) + " -a 1 -t 4 -0 -r 0 127.0.0.1 1",
               &out) == 0;
  }
  /// The simulated time of the newest sample, s: its sequence (inputs 2–3, one per sample at
  /// decimation 1) ÷ the rate. (Inputs 4–5 are wall-clock conversion times under --sim-speed.)
  double SimSeconds() {
    return static_cast<double>(static_cast<std::uint32_t>(Read("3:int", 2, 1).at(2))) / kRateHz;
  }

 private:
  int port_;
};

/// Sends RDT command 0x0042 (set software bias: a tare) to ftd's RDT port.
void RdtSetBias(int port) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  const std::uint8_t req[8] = {0x12, 0x34, 0x00, 0x42, 0, 0, 0, 0};
  (void)sendto(fd, req, sizeof req, 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
  close(fd);
}

int RdtPort(const test::FtdProcess& ftd) { return ftd.ServedPort("RDT"); }

/// What the test asked for and when.
struct Asked {
  int source = 0;
  double from_s = 0, to_s = 0;  ///< simulated time before the request and after the tare completed
};

TEST(FtdTareHistory, LastFourTaresReadBackWithTheLoadTimeTemperatureAndSourceApplied) {
  test::TempDir dir;
  // Speed 3: a tare asked 2 s into a hold has 6 s of simulated time (2 s of wall clock, many
  // mbpoll round trips on a loaded machine) to complete before the hold ends.
  test::FtdProcess ftd({"--modbus-tcp", "127.0.0.1:0", "--print-hz", "0", "--rate-hz", "1000",
                        "--sim-speed", "3", "--sim-profile", Profile(dir), "--sim-span-s", "60",
                        "--rdt", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  const int rdt = RdtPort(ftd);
  ASSERT_GT(rdt, 0) << ftd.Stderr();
  Mbpoll m(ftd.port());
  // Nothing tared yet: four empty slots.
  for (const auto& [addr, v] : m.Read("3", 210, 80)) EXPECT_EQ(v, 0) << addr;

  std::vector<Asked> asked;
  for (std::size_t i = 0; i < Holds().size(); ++i) {
    // Into the hold (2 s settled), then ask: hold 2 (the third) over RDT, the others over Modbus.
    const auto wait_until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (m.SimSeconds() < HoldStart(i) + 2.0 && std::chrono::steady_clock::now() < wait_until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    Asked a;
    a.from_s = m.SimSeconds();
    a.source = i == 2 ? 2 : 1;
    if (i == 2) {
      RdtSetBias(rdt);
    } else {
      ASSERT_TRUE(m.Tare());
    }
    // The tare completes after 0.1 s of samples; tare_count (189) says so.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (m.Read("3", 189, 1).at(189) < static_cast<double>(i + 1) &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    a.to_s = m.SimSeconds();
    ASSERT_EQ(m.Read("3", 189, 1).at(189), static_cast<double>(i + 1)) << "tare " << i + 1;
    ASSERT_LT(a.to_s, HoldStart(i) + kHoldS) << "the tare left its hold: the machine is too slow";
    asked.push_back(a);
  }

  // The history, newest first: tares 5, 4, 3, 2 (the first fell off the end).
  const test::SimNoise noise = test::DeriveSimNoise();
  for (int k = 0; k < 4; ++k) {
    const int base = 210 + 20 * k;
    const std::size_t tare = Holds().size() - 1 - static_cast<std::size_t>(k);  // 0-based
    const Hold& h = Holds()[tare];
    EXPECT_EQ(m.Read("3:int", base, 1).at(base), static_cast<double>(tare + 1)) << "slot " << k;
    const auto src = m.Read("3", base + 2, 2);
    EXPECT_EQ(src.at(base + 2), asked[tare].source) << "slot " << k;
    EXPECT_EQ(src.at(base + 3), 0) << "reserved, slot " << k;
    const double t = m.Read("3:int", base + 4, 1).at(base + 4);
    EXPECT_GE(t, std::floor(asked[tare].from_s)) << "slot " << k;
    EXPECT_LE(t, asked[tare].to_s) << "slot " << k;
    const auto f = m.Read("3:float", base + 6, 7);
    EXPECT_NEAR(f.at(base + 6), h.temp_c, 0.01) << "slot " << k;
    for (std::size_t a = 0; a < 6; ++a) {
      // The tare's mean over 100 samples: 5σ/√100 of noise, the core's fixed-point error, float32
      // rounding and, away from 20 °C, the simulated body's sensitivity drift, which the built-in
      // calibration (made at 20 °C) leaves in: modulus −3e-4/K and gauge factor +1e-4/K
      // (sim/sensors/default.json), 4e-4/K, bounded here by 5e-4/K. The newest tare is at 20 °C:
      // there the bound is the noise and the arithmetic alone.
      const double tol = 5 * noise.sigma[a] / 10 + noise.fixed_error[a] +
                         std::fabs(h.wrench[a]) * (1e-6 + 5e-4 * std::fabs(h.temp_c - 20.0));
      EXPECT_NEAR(f.at(base + 8 + 2 * static_cast<int>(a)), h.wrench[a], tol)
          << "slot " << k << " axis " << a;
    }
  }
  std::printf("tares at simulated time");
  for (const Asked& a : asked) std::printf(" [%.2f, %.2f] s", a.from_s, a.to_s);
  std::printf("\n");
}

TEST(FtdTareHistory, ATareWithoutATemperatureRecordsNoneNotAGuess) {
  // --sim-no-temperature: the simulated converter has no temperature input (as an HX711) while the
  // simulator's body sits at 20 °C. A tare over Modbus must then record the documented "none" —
  // NaN in its history slot (216–217), 0 as tare_temp_c (187–188), NaN as temperature_c (30–31) —
  // and not the simulator's 20 °C, which the same run with a temperature must read.
  const std::array<double, 6> load = {10, -5, 120, 0.5, -0.2, 0.1};
  const test::SimNoise noise = test::DeriveSimNoise();
  for (const bool none : {true, false}) {
    std::vector<std::string> args = {"--modbus-tcp", "127.0.0.1:0",           "--print-hz", "0",
                                     "--sim-wrench", "10,-5,120,0.5,-0.2,0.1"};
    if (none) args.emplace_back("--sim-no-temperature");
    test::FtdProcess ftd(args);
    ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
    Mbpoll m(ftd.port());
    const double temp_now = m.Read("3:float", 30, 1).at(30);
    ASSERT_TRUE(m.Tare());
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (m.Read("3", 189, 1).at(189) < 1 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_EQ(m.Read("3", 189, 1).at(189), 1) << "the tare did not complete; none = " << none;
    EXPECT_EQ(m.Read("3:int", 210, 1).at(210), 1) << none;  // tare number 1
    EXPECT_EQ(m.Read("3", 212, 1).at(212), 1) << none;      // asked over Modbus
    const auto f = m.Read("3:float", 216, 7);
    const double tare_temp = m.Read("3:float", 187, 1).at(187);
    if (none) {
      EXPECT_TRUE(std::isnan(temp_now)) << temp_now;
      EXPECT_TRUE(std::isnan(f.at(216))) << "the tare recorded " << f.at(216) << " °C";
      EXPECT_EQ(tare_temp, 0.0);
    } else {
      EXPECT_NEAR(temp_now, 20.0, 0.01);
      EXPECT_NEAR(f.at(216), 20.0, 0.01);
      EXPECT_NEAR(tare_temp, 20.0, 0.01);
    }
    // The load it removed, as in the test above at 20 °C: noise of the 0.1 s mean and arithmetic.
    for (std::size_t a = 0; a < 6; ++a) {
      const double tol = 5 * noise.sigma[a] / 10 + noise.fixed_error[a] + std::fabs(load[a]) * 1e-6;
      EXPECT_NEAR(f.at(218 + 2 * static_cast<int>(a)), load[a], tol) << "axis " << a << " " << none;
    }
  }
}

}  // namespace
}  // namespace ftstack
