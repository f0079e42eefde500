// Construction of the hardware ADC backends (HX711 over GPIO, SPI delta-sigma) for ftd.
#pragma once

#include <memory>
#include <string>

#include "hal/adc.hpp"

namespace ftstack::tools {

/// Options of ftd that select and wire a hardware ADC.
struct HardwareAdcOptions {
  std::string kind;      ///< "hx711" or "spi"
  std::string gpiochip;  ///< --gpiochip /dev/gpiochipN (hx711; data-ready line for spi)
  std::string spidev;    ///< --spidev /dev/spidevB.C (spi)
  int channels = 6;
};

/// Opens the backend; nullptr with a one-line reason in *error when it cannot.
std::unique_ptr<hal::Adc> MakeHardwareAdc(const HardwareAdcOptions& options, std::string* error);

}  // namespace ftstack::tools
