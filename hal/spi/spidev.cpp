#include "hal/spi/spidev.hpp"

#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "hal/errno_text.hpp"

namespace ftstack::hal::spi {

Spidev::~Spidev() {
  if (fd_ >= 0) close(fd_);
}

Status Spidev::Fail(const char* what, int err) {
  std::snprintf(
      error_.data(), error_.size(), "SPI device %s: %s: %s", path_.data(), what,
      err == ENOTTY || err == EINVAL ? "not an spidev device" : hal::ErrnoText(err).c_str());
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  return Status::kUnavailable;
}

Status Spidev::Open(const char* path, std::uint8_t mode, std::uint32_t speed_hz) {
  std::snprintf(path_.data(), path_.size(), "%s", path != nullptr ? path : "");
  if (fd_ >= 0) return Fail("already open", EBUSY);
  if (mode > 3 || speed_hz == 0) return Fail("bad mode or clock rate", EINVAL);
  fd_ = open(path_.data(), O_RDWR | O_CLOEXEC);
  if (fd_ < 0) return Fail("cannot open", errno);
  // spidev nodes are character devices of the fixed major 153 (SPIDEV_MAJOR); checking that
  // first gives the same answer under qemu-user, which does not emulate unknown ioctls.
  struct stat st {};
  constexpr unsigned kSpidevMajor = 153;
  if (fstat(fd_, &st) != 0) return Fail("cannot stat", errno);
  if (!S_ISCHR(st.st_mode) || major(st.st_rdev) != kSpidevMajor) return Fail("open", ENOTTY);
  const std::uint8_t m = mode;
  const std::uint8_t bits = 8;
  if (ioctl(fd_, SPI_IOC_WR_MODE, &m) != 0) return Fail("cannot set the SPI mode", errno);
  if (ioctl(fd_, SPI_IOC_WR_BITS_PER_WORD, &bits) != 0) {
    return Fail("cannot set 8-bit words", errno);
  }
  if (ioctl(fd_, SPI_IOC_WR_MAX_SPEED_HZ, &speed_hz) != 0) {
    return Fail("cannot set the clock rate", errno);
  }
  speed_hz_ = speed_hz;
  error_[0] = '\0';
  return Status::kOk;
}

Status Spidev::DoTransfer(const std::uint8_t* tx, std::uint8_t* rx, std::size_t len) {
  if (fd_ < 0) return Status::kUnavailable;
  spi_ioc_transfer xfer{};
  xfer.tx_buf = reinterpret_cast<std::uintptr_t>(tx);
  xfer.rx_buf = reinterpret_cast<std::uintptr_t>(rx);
  xfer.len = static_cast<std::uint32_t>(len);
  xfer.speed_hz = speed_hz_;
  xfer.bits_per_word = 8;
  return ioctl(fd_, SPI_IOC_MESSAGE(1), &xfer) == static_cast<int>(len) ? Status::kOk
                                                                        : Status::kReadError;
}

}  // namespace ftstack::hal::spi
