// Crash-safe calibration writes (issue 15): the real `ftcal install` killed at every step, and torn
// slot files; afterwards exactly one valid calibration is active and the real ftd starts with it.
#include <gtest/gtest.h>
#include <modbus/modbus.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "calibration/file/cal_file.hpp"
#include "calibration/file/slots.hpp"
#include "firmware/register_map.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/sensor_description.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/builtin_adc.hpp"
#include "tests/system/ftd_process.hpp"

extern char** environ;

namespace ftstack {
namespace {

namespace fs = std::filesystem;

/// Every crash-injection point of CalSlots::Install, in execution order.
const char* const kSteps[] = {"slot-write",     "slot-fsync",   "slot-rename",  "slot-dirsync",
                              "read-back",      "active-write", "active-fsync", "active-rename",
                              "active-dirsync", "done"};
/// Steps after which the new calibration is the active one (the `active` rename happened).
bool NewIsActiveAfter(const std::string& step) {
  return step == "active-dirsync" || step == "done";
}

/// Runs `ftcal install CAL --slots DIR` with FTSTACK_CRASH_AT=crash_at ("" = none); returns the
/// wait status.
int RunInstall(const std::string& cal, const std::string& dir, const std::string& crash_at) {
  std::vector<std::string> args{std::string(FTSTACK_BIN_DIR) + "/ftcal", "install", cal, "--slots",
                                dir};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::string(*e).rfind("FTSTACK_CRASH_AT=", 0) != 0) env_s.emplace_back(*e);
  }
  if (!crash_at.empty()) env_s.push_back("FTSTACK_CRASH_AT=" + crash_at);
  std::vector<char*> envp;
  for (std::string& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

std::uint32_t CrcField(const std::string& path) {
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  return static_cast<std::uint32_t>(std::stoul(j.at("crc32").get<std::string>(), nullptr, 16));
}

void Truncate(const std::string& path) {
  std::string text;
  {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text.substr(0, text.size() / 2);
}

/// The real ftd on the slot directory: its active slot (register 57) and CRC (72–73) over Modbus.
void ExpectFtdStartsWith(const std::string& dir, char slot, std::uint32_t crc,
                         const std::string& what) {
  test::FtdProcess ftd({"--cal-dir", dir, "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << what << ": " << ftd.Stderr();
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", ftd.port());
  ASSERT_NE(ctx, nullptr);
  modbus_set_response_timeout(ctx, 1, 0);
  ASSERT_EQ(modbus_connect(ctx), 0) << what;
  std::uint16_t r[fw::kInputRegisterCount] = {};
  int rc = -1;
  for (int i = 0; i < 200 && rc != static_cast<int>(fw::kInputRegistersV2); ++i) {
    rc = modbus_read_input_registers(ctx, 0, fw::kInputRegistersV2, r);
    if (rc < 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  modbus_close(ctx);
  modbus_free(ctx);
  ASSERT_EQ(rc, static_cast<int>(fw::kInputRegistersV2)) << what;
  EXPECT_EQ(r[fw::kInCalSlot], slot == 'A' ? 0 : 1) << what << "\n" << ftd.Stderr();
  EXPECT_EQ(fw::UnpackU32(&r[fw::kInCalCrc]), crc) << what;
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusCalInvalid, 0) << what;
  EXPECT_EQ(ftd.Stop(), 0) << what;
}

class FtcalCrash : public ::testing::Test {
 protected:
  void SetUp() override {
    const sim::SensorDescription desc = sim::DefaultSensorDescription();
    const hal::AdcInfo adc = test::BuiltinSimAdc().info;
    for (const char* serial : {"first", "second", "new"}) {
      cal::CalFile f = sim::IdealCalibration(*desc.model, adc);
      f.serial = serial;
      cal::SaveCalFile(tmp_ / (std::string(serial) + ".json"), f);
    }
  }
  /// A slot directory after two clean installs: A holds "first", B "second" (active).
  std::string TwoInstalls(const std::string& name) const {
    const std::string dir = tmp_ / name;
    cal::CalSlots slots(dir);
    EXPECT_EQ(slots.InstallFromPath(tmp_ / "first.json"), 'A');
    // Installs are seconds apart in use; here apart by more than the file system's clock tick
    // (modification times decide when the `active` record is lost).
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_EQ(slots.InstallFromPath(tmp_ / "second.json"), 'B');
    return dir;
  }
  /// Exactly one valid active calibration: `active` names `slot`, that file verifies and holds
  /// `serial`; LoadActive agrees without a note; ftd starts on it.
  void ExpectActive(const std::string& dir, char slot, const std::string& serial,
                    const std::string& what, bool expect_clean_record = true) const {
    const cal::CalSlots slots(dir);
    if (expect_clean_record) {
      EXPECT_EQ(slots.active(), slot) << what;
    }
    char used = 0;
    std::string note;
    EXPECT_EQ(slots.LoadActive(&used, &note).serial, serial) << what;
    EXPECT_EQ(used, slot) << what;
    if (expect_clean_record) {
      EXPECT_EQ(note, "") << what;
    } else {
      EXPECT_NE(note, "") << what;  // the fallback says why
    }
    ExpectFtdStartsWith(dir, slot, CrcField(slots.SlotPath(slot)), what);
  }

  test::TempDir tmp_{"ftcal_crash"};
};

TEST_F(FtcalCrash, KillAtEveryStepOfInstallLeavesExactlyOneValidActiveCalibration) {
  for (const char* step : kSteps) {
    const std::string dir = TwoInstalls(std::string("kill_") + step);
    const int status = RunInstall(tmp_ / "new.json", dir, step);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
        << step << ": ftcal was not killed at its crash point (status " << status << ")";
    if (NewIsActiveAfter(step)) {
      ExpectActive(dir, 'A', "new", step);  // the oldest slot took the new calibration
    } else {
      ExpectActive(dir, 'B', "second", step);  // the previous calibration, untouched
      EXPECT_EQ(cal::LoadCalFile(dir + "/cal_B.json").serial, "second") << step;
    }
    // The directory stays usable: a clean install after the crash completes and switches.
    const int again = RunInstall(tmp_ / "new.json", dir, "");
    ASSERT_TRUE(WIFEXITED(again) && WEXITSTATUS(again) == 0) << step;
    const cal::CalSlots slots(dir);
    char used = 0;
    std::string note;
    EXPECT_EQ(slots.LoadActive(&used, &note).serial, "new") << step;
    EXPECT_EQ(note, "") << step;
  }
}

TEST_F(FtcalCrash, TornSlotFilesAndATornActiveRecordStillResolveToOneValidCalibration) {
  {  // the active slot's file torn: the previous calibration (slot A) is used
    const std::string dir = TwoInstalls("torn_active_slot");
    Truncate(dir + "/cal_B.json");
    ExpectActive(dir, 'A', "first", "torn cal_B.json (active)", false);
    // A new install never overwrites the slot in use: it goes into the torn one.
    const int st = RunInstall(tmp_ / "new.json", dir, "");
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    ExpectActive(dir, 'B', "new", "install after torn cal_B.json");
    EXPECT_EQ(cal::LoadCalFile(dir + "/cal_A.json").serial, "first");
  }
  {  // the inactive slot's file torn: nothing changes
    const std::string dir = TwoInstalls("torn_inactive_slot");
    Truncate(dir + "/cal_A.json");
    ExpectActive(dir, 'B', "second", "torn cal_A.json (inactive)");
  }
  {  // the `active` record torn (empty): the slot written last
    const std::string dir = TwoInstalls("torn_record");
    std::ofstream(dir + "/active", std::ios::trunc).flush();
    ExpectActive(dir, 'B', "second", "empty active record", false);
    const int st = RunInstall(tmp_ / "new.json", dir, "");
    ASSERT_TRUE(WIFEXITED(st) && WEXITSTATUS(st) == 0);
    ExpectActive(dir, 'A', "new", "install after an empty active record");
  }
}

}  // namespace
}  // namespace ftstack
