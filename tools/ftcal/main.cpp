// ftcal — calibration command line: apply (fixed-point core on a recording), verify.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "calibration/apply.hpp"
#include "calibration/cal_file.hpp"
#include "sim/recording.hpp"

int main(int argc, char** argv) {
  using namespace ftstack;
  CLI::App app{"ftcal — fit, apply, import and verify force/torque calibrations"};
  app.require_subcommand(1);
  std::string cal_path;
  std::string in_path;
  std::string out_path;
  auto* apply = app.add_subcommand("apply", "run the firmware's fixed-point core on a recording");
  apply->add_option("--cal", cal_path, "calibration file")->required();
  apply->add_option("--in", in_path, "recording with b* columns")->required();
  apply->add_option("--out", out_path, "output recording t,Fx,Fy,Fz,Mx,My,Mz")->required();
  auto* verify = app.add_subcommand("verify", "check a calibration file's integrity");
  verify->add_option("cal", cal_path, "calibration file")->required();
  CLI11_PARSE(app, argc, argv);
  try {
    if (*apply) {
      const cal::CalFile cal = cal::LoadCalFile(cal_path);
      sim::ReadOptions opt;
      opt.require_bridges = true;
      const sim::Recording in = sim::ReadRecording(in_path, opt);
      sim::WriteRecording(out_path, cal::ApplyCalibration(cal, in));
      std::fprintf(stderr, "ftcal: wrote %zu rows to %s\n", in.rows(), out_path.c_str());
    } else if (*verify) {
      const cal::CalFile cal = cal::LoadCalFile(cal_path);
      fw::LoadReport rep{};
      (void)cal::ToFixed(cal, cal.adc, &rep);
      std::printf("%s: OK (schema %s, %d channels, serial %s, CRC valid)\n", cal_path.c_str(),
                  cal::kCalSchema, cal.cal.channel_count, cal.serial.c_str());
      std::printf(
          "worst-case fixed-point error: Fx %.3g N, Fy %.3g N, Fz %.3g N, Mx %.3g N·m, "
          "My %.3g N·m, Mz %.3g N·m\n",
          rep.worst_case_error_si[0], rep.worst_case_error_si[1], rep.worst_case_error_si[2],
          rep.worst_case_error_si[3], rep.worst_case_error_si[4], rep.worst_case_error_si[5]);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ftcal: %s\n", e.what());
    return 1;
  }
  return 0;
}
