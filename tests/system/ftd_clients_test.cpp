// ftd with independent clients: the README's mbpoll examples (TCP), and RTU over a socat pty pair.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "calibration/file/cal_file.hpp"
#include "firmware/register_map.hpp"
#include "sim/default_sensor.hpp"
#include "sim/ideal_calibration.hpp"
#include "tests/system/builtin_adc.hpp"
#include "tests/system/ftd_process.hpp"
#include "tests/system/mbpoll.hpp"

namespace ftstack {
namespace {

using test::ParseMbpoll;
using test::RunShell;

/// The mbpoll command lines of the README (text before a '#' comment).
std::vector<std::string> ReadmeMbpollLines(const std::string& mode) {
  std::ifstream in(std::string(FTSTACK_SOURCE_DIR) + "/README.md");
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("mbpoll -m " + mode, 0) != 0) continue;
    const std::size_t hash = line.find('#');
    if (hash != std::string::npos) line = line.substr(0, hash);
    while (!line.empty() && line.back() == ' ') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

/// One-sample noise per axis of the built-in sensor (ADC noise and quantisation through the
/// calibration matrix), as in test_ftd_modbus.
std::array<double, 6> SampleSigma() {
  const auto model = sim::MakeDefaultSensor();
  const test::BuiltinAdc builtin = test::BuiltinSimAdc();
  const hal::AdcInfo adc = builtin.info;
  const cal::CalFile c = sim::IdealCalibration(*model, adc);
  const double q = adc.full_scale_nvv * 1e-6 / adc.max_counts;
  const double var = builtin.noise_rms_mvv * builtin.noise_rms_mvv + q * q / 12.0;
  std::array<double, 6> s{};
  for (std::size_t i = 0; i < 6; ++i) {
    double s2 = 0;
    for (std::size_t ch = 0; ch < 6; ++ch) s2 += c.cal.matrix[i][ch] * c.cal.matrix[i][ch] * var;
    s[i] = std::sqrt(s2);
  }
  return s;
}

TEST(FtdClients, ReadmeMbpollExamplesWork) {
  const std::vector<std::string> lines = ReadmeMbpollLines("tcp");
  ASSERT_GE(lines.size(), 6u) << "README lost its mbpoll examples";
  const std::array<double, 6> applied = {10.0, 0.0, -50.0, 0.0, 0.5, 0.0};
  test::FtdProcess ftd({"--sim-wrench", "10,0,-50,0,0.5,0", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  const std::array<double, 6> sigma = SampleSigma();
  const std::string port = "-p " + std::to_string(ftd.port());
  bool saw_float = false, saw_int = false, saw_status = false, saw_mvv = false;
  for (const std::string& l : lines) {
    SCOPED_TRACE(l);
    ASSERT_NE(l.find("-p 1502"), std::string::npos);
    std::string out;
    ASSERT_EQ(RunShell(Replace(l, "-p 1502", port), &out), 0) << out;
    const auto v = ParseMbpoll(out);
    if (l.find("-t 3:float -B -r 7 -c 6") != std::string::npos) {
      ASSERT_EQ(v.size(), 6u) << out;
      // One unfiltered sample: 5σ noise; mbpoll prints about 5 significant digits.
      for (int a = 0; a < 6; ++a) {
        EXPECT_NEAR(v.at(7 + 2 * a), applied[a], 5 * sigma[a] + 1e-4 * std::fabs(applied[a]) + 1e-3)
            << "axis " << a;
      }
      saw_float = true;
    } else if (l.find("-t 3:int -B -r 19 -c 6") != std::string::npos) {
      ASSERT_EQ(v.size(), 6u) << out;
      for (int a = 0; a < 6; ++a) {
        EXPECT_NEAR(v.at(19 + 2 * a), applied[a] * 1e3, 5e3 * sigma[a] + 1.0) << "axis " << a;
      }
      saw_int = true;
    } else if (l.find("-t 3 -r 1 -c 2") != std::string::npos) {
      ASSERT_EQ(v.size(), 2u) << out;
      EXPECT_EQ(v.at(1), 3.0);  // map version
      EXPECT_EQ(static_cast<int>(v.at(2)) & fw::kStatusSimulated, fw::kStatusSimulated);
      saw_status = true;
    } else if (l.find("-r 45 -c 6") != std::string::npos) {
      ASSERT_EQ(v.size(), 6u) << out;
      for (const auto& [ref, mvv] : v) EXPECT_LT(std::fabs(mvv), 3.90625) << ref;
      saw_mvv = true;
    }
  }
  EXPECT_TRUE(saw_float && saw_int && saw_status && saw_mvv);
  // The README's writes took effect: filter 64, tare active, tool point 0.1 m along z.
  modbus_t* c = modbus_new_tcp("127.0.0.1", ftd.port());
  ASSERT_EQ(modbus_connect(c), 0);
  std::uint16_t h[16] = {};
  ASSERT_EQ(modbus_read_registers(c, fw::kHoldFilterLength, 1, h), 1);
  EXPECT_EQ(h[0], 64);
  ASSERT_EQ(modbus_read_registers(c, fw::kHoldTransform, 6, h), 6);
  EXPECT_FLOAT_EQ(fw::UnpackFloat32(&h[4]), 0.1f);
  // The tare completes after 0.1 s of samples: polled (a loaded machine may take longer than a
  // fixed sleep to sample them), with a deadline far above it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  do {
    ASSERT_EQ(modbus_read_input_registers(c, fw::kInStatus, 1, h), 1);
    if ((h[0] & fw::kStatusTareActive) != 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  } while (std::chrono::steady_clock::now() < deadline);
  EXPECT_NE(h[0] & fw::kStatusTareActive, 0);
  modbus_close(c);
  modbus_free(c);
  // An illegal address: mbpoll exits 1 and names the exception.
  std::string out;
  EXPECT_EQ(RunShell("mbpoll -m tcp " + port + " -a 1 -t 3 -r 1001 -c 1 -1 127.0.0.1", &out), 1);
  EXPECT_NE(out.find("Illegal data address"), std::string::npos) << out;
  EXPECT_EQ(RunShell("mbpoll -m tcp " + port + " -a 1 -t 4 -r 2 127.0.0.1 0", &out), 1);
  EXPECT_NE(out.find("Illegal data value"), std::string::npos) << out;
  EXPECT_EQ(ftd.Stop(), 0);
}

/// CRC-16/MODBUS (reflected 0xA001, initial 0xFFFF), low byte first on the line.
std::uint16_t Crc16Modbus(const std::vector<std::uint8_t>& bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc ^= b;
    for (int k = 0; k < 8; ++k) crc = (crc & 1u) != 0 ? (crc >> 1) ^ 0xA001u : crc >> 1;
  }
  return crc;
}

/// A socat pseudo-terminal pair: the slave opens `a`, clients `b`. Stopped by PID.
class PtyPair {
 public:
  PtyPair() {
    char dir[] = "/tmp/ftd_pty_XXXXXX";
    dir_ = mkdtemp(dir);
    a_ = dir_ + "/A";
    b_ = dir_ + "/B";
    std::vector<std::string> args = {"socat", "pty,raw,echo=0,link=" + a_,
                                     "pty,raw,echo=0,link=" + b_};
    std::vector<char*> argv;
    for (auto& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    if (posix_spawnp(&pid_, "socat", &fa, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&fa);
    struct stat st {};
    for (int i = 0; i < 500 && (stat(a_.c_str(), &st) != 0 || stat(b_.c_str(), &st) != 0); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  ~PtyPair() {
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      waitpid(pid_, nullptr, 0);
    }
    std::remove(a_.c_str());
    std::remove(b_.c_str());
    rmdir(dir_.c_str());
  }
  [[nodiscard]] bool ok() const { return pid_ > 0; }
  const std::string& a() const { return a_; }
  const std::string& b() const { return b_; }

 private:
  pid_t pid_ = -1;
  std::string dir_, a_, b_;
};

TEST(FtdClients, RtuOverPtyPairServesTheMapAndSurvivesGarbage) {
  PtyPair pty;
  ASSERT_TRUE(pty.ok());
  test::FtdProcess ftd({"--sim-wrench", "0,25,100,-1,0,0.3", "--modbus-rtu", pty.a(), "--baud",
                        "38400", "--parity", "E", "--unit-id", "3"},
                       false);
  const std::string banner = "serving Modbus RTU on " + pty.a();
  for (int i = 0; i < 500 && ftd.Stderr().find(banner) == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_NE(ftd.Stderr().find(banner), std::string::npos) << ftd.Stderr();
  const std::array<double, 6> applied = {0.0, 25.0, 100.0, -1.0, 0.0, 0.3};
  const std::array<double, 6> sigma = SampleSigma();

  modbus_t* c = modbus_new_rtu(pty.b().c_str(), 38400, 'E', 8, 1);
  ASSERT_NE(c, nullptr);
  modbus_set_slave(c, 3);
  modbus_set_response_timeout(c, 1, 0);
  ASSERT_EQ(modbus_connect(c), 0);
  std::uint16_t r[fw::kInputRegisterCount] = {};
  ASSERT_EQ(modbus_read_input_registers(c, 0, fw::kInputRegistersV2, r), fw::kInputRegistersV2);
  EXPECT_EQ(r[fw::kInMapVersion], 3);  // docs/spec/modbus-map.md
  EXPECT_EQ(r[fw::kInBridgeCount], 6);
  for (std::size_t a = 0; a < 6; ++a) {
    EXPECT_NEAR(fw::UnpackFloat32(&r[fw::kInWrenchFloat + 2 * a]), applied[a], 5 * sigma[a] + 1e-3)
        << "axis " << a;
  }
  EXPECT_EQ(modbus_read_input_registers(c, fw::kInputAddressSpan, 1, r), -1);
  EXPECT_EQ(errno, EMBXILADD);
  EXPECT_EQ(modbus_write_register(c, fw::kHoldCalSlot, 1), -1);
  EXPECT_EQ(errno, EMBXILVAL);
  ASSERT_EQ(modbus_write_register(c, fw::kHoldDecimation, 10), 1);
  ASSERT_EQ(modbus_read_registers(c, fw::kHoldDecimation, 1, r), 1);
  EXPECT_EQ(r[0], 10);
  // A broadcast (unit 0) write is executed without a reply; another unit id gets no answer.
  // (libmodbus 3.1.6 as a client still waits for a confirmation of a broadcast and reports a
  // timeout; only the effect is checked.)
  modbus_set_response_timeout(c, 0, 300000);
  modbus_set_slave(c, 0);
  (void)modbus_write_register(c, fw::kHoldDecimation, 7);
  modbus_set_slave(c, 9);
  EXPECT_EQ(modbus_read_registers(c, fw::kHoldDecimation, 1, r), -1);
  EXPECT_EQ(errno, ETIMEDOUT);
  // On a multi-drop bus unit 9 would now answer, and a slave skips that reply as not addressed
  // to it: play unit 9's reply onto the line as the bus would carry it.
  std::vector<std::uint8_t> reply9 = {0x09, 0x03, 0x02, 0x00, 0x2A};
  const std::uint16_t crc = Crc16Modbus(reply9);
  reply9.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  reply9.push_back(static_cast<std::uint8_t>(crc >> 8));
  ASSERT_EQ(write(modbus_get_socket(c), reply9.data(), reply9.size()),
            static_cast<ssize_t>(reply9.size()));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  modbus_set_response_timeout(c, 1, 0);
  modbus_set_slave(c, 3);
  modbus_flush(c);
  ASSERT_EQ(modbus_read_registers(c, fw::kHoldDecimation, 1, r), 1);
  EXPECT_EQ(r[0], 7);

  // Garbage on the line, then a normal request is answered again.
  std::mt19937 rng(9);
  for (int burst = 0; burst < 5; ++burst) {
    std::vector<std::uint8_t> junk(10 + rng() % 60);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    std::vector<std::uint8_t> raw = junk;
    ASSERT_EQ(write(modbus_get_socket(c), raw.data(), raw.size()),
              static_cast<ssize_t>(raw.size()));
    std::this_thread::sleep_for(std::chrono::milliseconds(250));  // > the slave's byte timeout
    modbus_flush(c);
    ASSERT_EQ(modbus_read_input_registers(c, 0, 2, r), 2) << "burst " << burst;
    EXPECT_EQ(r[0], 3);  // map version
  }
  modbus_close(c);
  modbus_free(c);

  // The README's RTU example, pointed at the pty (its parity and unit changed to this slave's).
  const std::vector<std::string> lines = ReadmeMbpollLines("rtu");
  ASSERT_EQ(lines.size(), 1u);
  std::string cmd = Replace(lines[0], "/dev/ttyUSB0", pty.b());
  cmd =
      Replace(Replace(Replace(cmd, "-b 19200", "-b 38400"), "-P none", "-P even"), "-a 1", "-a 3");
  std::string out;
  ASSERT_EQ(RunShell(cmd, &out), 0) << out;
  const auto v = ParseMbpoll(out);
  ASSERT_EQ(v.size(), 6u) << out;
  EXPECT_NEAR(v.at(9), 25.0, 5 * sigma[1] + 1e-3);
  EXPECT_EQ(ftd.Stop(), 0);
}

}  // namespace
}  // namespace ftstack
