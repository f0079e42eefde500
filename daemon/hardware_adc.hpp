// Construction of the hardware ADC backends (HX711 over GPIO, SPI delta-sigma) for ftd.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "daemon/backend.hpp"
#include "daemon/options.hpp"
#include "hal/adc.hpp"

namespace ftstack::daemon {

/// Options of ftd that select and wire a hardware ADC. Fields after `channels` have board
/// defaults (Raspberry Pi 40-pin header, gpiochip0 offsets = BCM numbers) and can be overridden
/// from the environment (ApplyHardwareEnvironment) until ftd has command-line options for them.
struct HardwareAdcOptions {
  std::string kind;      ///< "hx711" or "spi"
  std::string gpiochip;  ///< --gpiochip /dev/gpiochipN (hx711; data-ready line for spi)
  std::string spidev;    ///< --spidev /dev/spidevB.C (spi)
  int channels = 6;
  /// HX711 (PD_SCK, DOUT) line offsets per bridge; equal PD_SCK offsets share one clock line.
  /// FTD_HX711_LINES="5:6,5:13,5:19,5:26,5:12,5:16".
  std::vector<std::pair<unsigned, unsigned>> hx711_lines = {{5, 6},  {5, 13}, {5, 19},
                                                            {5, 26}, {5, 12}, {5, 16}};
  unsigned drdy_line = 25;               ///< ADS131M /DRDY line offset (FTD_DRDY_LINE)
  std::uint32_t spi_speed_hz = 8000000;  ///< SPI clock (FTD_SPI_HZ); the chip allows 25 MHz
  bool ads131m06 = false;                ///< ADS131M06 instead of ADS131M08 (FTD_ADS131M=06)
  std::uint32_t excitation_uv =
      5000000;                ///< bridge excitation of the SPI ADC, µV (FTD_EXCITATION_UV)
  int realtime_priority = 0;  ///< SCHED_FIFO priority of the HX711 reading thread (FTD_RT_PRIORITY)
};

/// Parses "SCK:DOUT,SCK:DOUT,…" (line offsets). Throws std::invalid_argument naming the bad item.
std::vector<std::pair<unsigned, unsigned>> ParseHx711Lines(const std::string& text);

/// Overrides the board fields of `options` from FTD_HX711_LINES, FTD_DRDY_LINE, FTD_SPI_HZ,
/// FTD_ADS131M, FTD_EXCITATION_UV, FTD_RT_PRIORITY when set. Throws std::invalid_argument.
void ApplyHardwareEnvironment(HardwareAdcOptions& options);

/// Opens the converter; throws FtdError with a one-line reason when it cannot (no chip, no
/// permission, missing --gpiochip/--spidev, bad environment value).
[[nodiscard]] std::unique_ptr<hal::Adc> MakeHardwareAdc(const HardwareAdcOptions& options);

/// ftd's backend of --adc hx711|spi (six bridges); throws FtdError as MakeHardwareAdc.
[[nodiscard]] std::unique_ptr<AdcBackend> MakeHardwareBackend(const FtdOptions& opt);

}  // namespace ftstack::daemon
