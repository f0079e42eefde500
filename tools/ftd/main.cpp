// ftd — the sensor daemon: ADC backend → firmware core → live readings (and Modbus, see issue 5).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>

#include "calibration/cal_file.hpp"
#include "calibration/ideal.hpp"
#include "firmware/sampler.hpp"
#include "hal/sim/sim_adc.hpp"
#include "sim/default_sensor.hpp"
#include "sim/simulated_sensor.hpp"
#include "sim/wrench_source.hpp"
#include "tools/common.hpp"
#include "tools/ftd/hardware_adc.hpp"

namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

}  // namespace

int main(int argc, char** argv) {
  using namespace ftstack;
  CLI::App app{"ftd — force/torque sensor daemon (firmware main loop on a board or host)"};
  std::string adc_kind = "sim";
  std::string sim_wrench;
  std::string replay;
  unsigned rate_hz = 1000;
  std::string cal_path;
  std::string modbus_tcp;
  std::string modbus_rtu;
  unsigned baud = 19200;
  std::string parity = "N";
  unsigned unit_id = 1;
  std::string log_path;
  double duration_s = 0;
  std::uint64_t seed = 1;
  double print_hz = 5;
  std::string gpiochip;
  std::string spidev;
  app.add_option("--adc", adc_kind, "ADC backend: sim, hx711, spi")
      ->check(CLI::IsMember({"sim", "hx711", "spi"}));
  app.add_option("--sim-wrench", sim_wrench, "constant applied wrench FX,FY,FZ,MX,MY,MZ (N, N·m)");
  app.add_option("--replay", replay, "play the wrench columns of a recording")
      ->check(CLI::ExistingFile);
  app.add_option("--rate-hz", rate_hz, "sample rate, Hz")->check(CLI::Range(1u, 100000u));
  app.add_option("--cal", cal_path, "calibration file (default: the simulated sensor's own)");
  app.add_option("--modbus-tcp", modbus_tcp, "serve Modbus TCP on HOST:PORT");
  app.add_option("--modbus-rtu", modbus_rtu, "serve Modbus RTU on a serial DEVICE");
  app.add_option("--baud", baud, "RTU baud rate");
  app.add_option("--parity", parity, "RTU parity N|E|O")->check(CLI::IsMember({"N", "E", "O"}));
  app.add_option("--unit-id", unit_id, "Modbus unit id")->check(CLI::Range(1u, 247u));
  app.add_option("--log", log_path, "write samples to a recording (CSV)");
  app.add_option("--gpiochip", gpiochip, "GPIO chip for --adc hx711");
  app.add_option("--spidev", spidev, "SPI device for --adc spi");
  app.add_option("--duration-s", duration_s,
                 "stop after this many seconds (0: run until signalled)");
  app.add_option("--seed", seed, "noise seed of the simulated ADC");
  app.add_option("--print-hz", print_hz, "rate of the live reading line (0: quiet)");
  app.get_option("--sim-wrench")->excludes(app.get_option("--replay"));
  CLI11_PARSE(app, argc, argv);

  if (adc_kind != "sim") {
    std::string error;
    tools::HardwareAdcOptions hw{adc_kind, gpiochip, spidev, 6};
    if (tools::MakeHardwareAdc(hw, &error) == nullptr) {
      std::fprintf(stderr, "ftd: %s\n", error.c_str());
      return 2;
    }
  }
  if (!modbus_tcp.empty() || !modbus_rtu.empty()) {
    std::fprintf(stderr,
                 "ftd: note: Modbus serving is not in this build yet; showing readings only\n");
  }

  std::unique_ptr<sim::SensorModel> model = sim::MakeDefaultSensor();
  std::unique_ptr<sim::WrenchSource> source;
  try {
    if (!replay.empty()) {
      sim::ReadOptions opt;
      opt.required = {"t"};
      opt.require_wrench = true;
      source = sim::ReplayWrench(sim::ReadRecording(replay, opt));
    } else {
      sim::Wrench w = sim::Wrench::Zero();
      if (!sim_wrench.empty()) {
        const auto a = tools::ParseWrench(sim_wrench);
        for (int i = 0; i < 6; ++i) w(i) = a[static_cast<std::size_t>(i)];
      }
      source = std::make_unique<sim::ConstantWrench>(w);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return 2;
  }
  sim::SimulatedSensor sensor(*model, *source);
  hal::sim::SimAdcParams params;
  params.seed = seed;
  params.realtime = true;
  params.noise_rms_mvv = sim::kDefaultNoiseMvv;
  hal::sim::SimAdc adc(sensor, params);
  fw::WrenchCore core;
  fw::Sampler sampler(adc, core);
  hal::AdcConfig cfg;
  cfg.channel_count = static_cast<std::uint8_t>(model->channel_count());
  cfg.rate_hz = rate_hz;
  if (const hal::Status s = sampler.Start(cfg); s != hal::Status::kOk) {
    std::fprintf(stderr, "ftd: ADC configuration failed: %s\n", hal::ToString(s));
    return 1;
  }
  try {
    const cal::CalFile cal = cal_path.empty() ? cal::IdealCalibration(*model, sampler.info())
                                              : cal::LoadCalFile(cal_path);
    fw::LoadReport rep{};
    core.SetCalibration(cal::ToFixed(cal, sampler.info(), &rep));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftd: %s\n", e.what());
    return 2;
  }

  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  const bool tty = isatty(STDOUT_FILENO) != 0;
  const std::uint64_t print_every =
      print_hz > 0 ? std::max<std::uint64_t>(1, static_cast<std::uint64_t>(rate_hz / print_hz)) : 0;
  const std::uint64_t max_samples =
      duration_s > 0 ? static_cast<std::uint64_t>(duration_s * rate_hz) : 0;
  std::uint64_t n = 0;
  fw::PublishedSample p{};
  while (!g_stop) {
    const hal::Status s = sampler.Step(p);
    if (s == hal::Status::kEndOfData) break;
    ++n;
    if (print_every != 0 && n % print_every == 0) {
      std::printf(
          "%st=%9.3f s  seq=%-8u Fx=%9.3f Fy=%9.3f Fz=%9.3f N  Mx=%8.4f My=%8.4f Mz=%8.4f N·m"
          "  status=0x%04x%s",
          tty ? "\r" : "", p.timestamp_us * 1e-6, p.sequence, p.wrench[0] * fw::kForceLsbN,
          p.wrench[1] * fw::kForceLsbN, p.wrench[2] * fw::kForceLsbN,
          p.wrench[3] * fw::kMomentLsbNm, p.wrench[4] * fw::kMomentLsbNm,
          p.wrench[5] * fw::kMomentLsbNm, p.status, tty ? "" : "\n");
      std::fflush(stdout);
    }
    if (max_samples != 0 && n >= max_samples) break;
  }
  if (tty) std::printf("\n");
  return 0;
}
