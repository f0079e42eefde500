// libFuzzer harness: the calibration file loader (JSON, CRC, fixed-point proof). Refusals are
// CalFileError; an accepted file converts to the firmware's integer form.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "calibration/file/cal_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ftstack::cal::CalFile f = ftstack::cal::ParseCalFile(text, "fuzz.json");
    for (std::size_t r = 0; r < 6; ++r) {
      for (std::size_t c = 0; c < f.cal.channel_count; ++c) {
        if (!std::isfinite(f.cal.matrix[r][c])) std::abort();
      }
    }
    const ftstack::fw::FixedCalibration fixed = ftstack::cal::ToFixed(f, f.adc);
    if (!fixed.valid) std::abort();
  } catch (const ftstack::cal::CalFileError&) {
  }
  return 0;
}
