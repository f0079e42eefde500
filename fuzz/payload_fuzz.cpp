// libFuzzer harness: the payload file parser (calibration/payload_file) — any text is either
// accepted as a finite, CRC-valid payload or refused with PayloadFileError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "calibration/file/payload_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ftstack::cal::PayloadFile p = ftstack::cal::ParsePayloadFile(text, "fuzz.json");
    if (!(p.mass_kg > 0) || !std::isfinite(p.mass_kg)) std::abort();  // accepted must be usable
  } catch (const ftstack::cal::PayloadFileError&) {
  }
  return 0;
}
