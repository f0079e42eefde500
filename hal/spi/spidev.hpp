// The Linux spidev backend of the SPI transfer interface (/dev/spidevB.C).
#pragma once

#include <array>
#include <cstdint>

#include "hal/gpio/line.hpp"
#include "hal/spi/spi_device.hpp"

namespace ftstack::hal::spi {

/// A /dev/spidevB.C node. Open fails with kUnavailable and a one-line reason in error().
class Spidev final : public SpiDevice {
 public:
  Spidev() = default;
  ~Spidev() override;

  /// Opens `path` and sets SPI mode (0 … 3), 8-bit words and the clock rate.
  [[nodiscard]] Status Open(const char* path, std::uint8_t mode, std::uint32_t speed_hz);
  [[nodiscard]] const char* error() const { return error_.data(); }
  [[nodiscard]] bool is_open() const { return fd_ >= 0; }

 private:
  Status DoTransfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) override;
  Status Fail(const char* what, int err);

  int fd_ = -1;
  std::uint32_t speed_hz_ = 0;
  std::array<char, 64> path_{};
  std::array<char, gpio::kErrorTextSize> error_{};
};

}  // namespace ftstack::hal::spi
