// A sensor under a robot base (issue 13): the base-estop load profile replayed through ftd; the
// overload rule sees the emergency stop and nothing before it.
#include <gtest/gtest.h>
#include <modbus/modbus.h>

#include <array>
#include <chrono>
#include <cmath>
#include <thread>

#include "firmware/register_map.hpp"
#include "firmware/status_bits.hpp"
#include "measurement/recording.hpp"
#include "measurement/wrench.hpp"
#include "sim/load_profile.hpp"
#include "sim/sensor_description.hpp"
#include "tests/support/temp_dir.hpp"
#include "tests/system/ftd_process.hpp"

namespace ftstack {
namespace {

// The e-stop's keyframe time: where the load first reaches the rated Fz (the profile's peak).
double EstopTime(const sim::LoadProfile& p, const Wrench& rated) {
  for (std::size_t i = 0; i < p.key_times_s().size(); ++i) {
    if (std::abs(p.key_loads()[i](2)) >= 0.999 * rated(2)) return p.key_times_s()[i];
  }
  return -1;
}

TEST(FtdBase, EmergencyStopOfABaseProfileIsOneOverloadEvent) {
  const Wrench rated = sim::DefaultSensorDescription().model->rated();
  const sim::LoadProfile p = sim::MakeProfile("base-estop", rated, 7);
  const double t_stop = EstopTime(p, rated);
  ASSERT_GT(t_stop, 3.0);
  // The last 3 s of pick-and-place before the stop, the stop and its ring-down, at 1 kHz.
  const double t0 = t_stop - 3.0;
  const test::TempDir tmp("ftd_base");
  const std::string path = (tmp.path() / "base.csv").string();
  Recording rec;
  std::vector<double> t;
  std::array<std::vector<double>, 6> w;
  for (double s = t0; s <= t_stop + 2.0; s += 1e-3) {
    t.push_back(s - t0);
    const Wrench l = p.LoadAt(s);
    for (int k = 0; k < 6; ++k) w[static_cast<std::size_t>(k)].push_back(l(k));
  }
  rec.SetColumn("t", t);
  for (int k = 0; k < 6; ++k)
    rec.SetColumn(WrenchColumns()[static_cast<std::size_t>(k)], w[static_cast<std::size_t>(k)]);
  WriteRecording(path, rec);

  test::FtdProcess ftd({"--replay", path, "--rate-hz", "1000", "--modbus-tcp", "127.0.0.1:0"});
  ASSERT_GT(ftd.port(), 0) << ftd.Stderr();
  modbus_t* c = modbus_new_tcp("127.0.0.1", ftd.port());
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(modbus_connect(c), 0);
  std::array<std::uint16_t, fw::kInputRegisterCount> r{};
  auto read = [&] {
    return modbus_read_input_registers(c, 0, fw::kInputRegistersV2, r.data()) ==
           fw::kInputRegistersV2;
  };
  auto wait_sequence = [&](std::uint32_t n) {
    for (int i = 0; i < 20000; ++i) {
      if (read() && fw::UnpackU32(&r[fw::kInSequence]) >= n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    return false;
  };
  // 2.5 s of pick-and-place (combined share ≤ 0.9): no overload.
  ASSERT_TRUE(wait_sequence(2500));
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusOverload, 0);
  EXPECT_EQ(fw::UnpackU32(&r[fw::kInOverloadEvents]), 0u);
  // After the stop (3.0 s) and its ring-down: one event. The peak Fz is well above anything of
  // the pick-and-place (≤ 53 % of rated) but below the applied 100 %: with all six components at
  // rated at once, bridges of the built-in sensor clip (saturation, itself an overload).
  ASSERT_TRUE(wait_sequence(4500));
  EXPECT_EQ(fw::UnpackU32(&r[fw::kInOverloadEvents]), 1u);
  EXPECT_GE(fw::UnpackFloat32(&r[fw::kInPeaks + 4]), 0.8 * rated(2));
  EXPECT_EQ(r[fw::kInStatus] & fw::kStatusOverload, 0);  // back at the static load
  modbus_close(c);
  modbus_free(c);
  EXPECT_EQ(ftd.Stop(), 0);
}

}  // namespace
}  // namespace ftstack
