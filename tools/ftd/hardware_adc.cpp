#include "tools/ftd/hardware_adc.hpp"

namespace ftstack::tools {

std::unique_ptr<hal::Adc> MakeHardwareAdc(const HardwareAdcOptions& options, std::string* error) {
  *error = "--adc " + options.kind + ": hardware backends are not built into this version";
  return nullptr;
}

}  // namespace ftstack::tools
