// libFuzzer harness: the ATI DAQ .cal (XML) reader. Refusals are CalFileError.
#include <cstdint>
#include <string>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/ati.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)ftstack::cal::ParseAtiCal(text, "fuzz.cal");
  } catch (const ftstack::cal::CalFileError&) {
  }
  return 0;
}
