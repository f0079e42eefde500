// The SPI transfer interface ADC drivers use (one device, one chip select, full duplex).
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/adc.hpp"

namespace ftstack::hal::spi {

/// One SPI peripheral behind its own chip select. Mode, clock rate and word size are fixed when
/// the device is opened; a transfer is one chip-select-low period.
class SpiDevice {
 public:
  virtual ~SpiDevice() = default;
  SpiDevice() = default;
  SpiDevice(const SpiDevice&) = delete;
  SpiDevice& operator=(const SpiDevice&) = delete;

  /// Shifts out tx[0 … len) while shifting in rx[0 … len), chip select held for the whole
  /// transfer. kOk, kReadError (the bus driver failed), kUnavailable (device not open).
  [[nodiscard]] Status Transfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) {
    return DoTransfer(tx, rx, len);
  }

 private:
  virtual Status DoTransfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) = 0;
};

}  // namespace ftstack::hal::spi
