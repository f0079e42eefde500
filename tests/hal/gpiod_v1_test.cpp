// The libgpiod v1 backend on a machine without GPIO: every failure is kUnavailable with a reason.
#include "hal/gpio/gpiod_v1_chip.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

namespace ftstack::hal::gpio {
namespace {

TEST(GpiodV1, MissingChipIsUnavailableWithTheReason) {
  GpiodV1Chip chip;
  const char* path = "/dev/gpiochip-ftstack-test-absent";
  ASSERT_NE(access(path, F_OK), 0);
  EXPECT_EQ(chip.Open(path), Status::kUnavailable);
  EXPECT_FALSE(chip.is_open());
  const std::string err = chip.error();
  EXPECT_NE(err.find(path), std::string::npos) << err;
  EXPECT_NE(err.find("No such file or directory"), std::string::npos) << err;
}

TEST(GpiodV1, AFileThatIsNoGpioChipIsUnavailable) {
  GpiodV1Chip chip;
  EXPECT_EQ(chip.Open("/dev/null"), Status::kUnavailable);
  const std::string err = chip.error();
  EXPECT_NE(err.find("/dev/null"), std::string::npos) << err;
  EXPECT_EQ(err.find('\n'), std::string::npos);
}

TEST(GpiodV1, LinesOfAnUnopenedChipAreUnavailable) {
  GpiodV1Chip chip;
  OutputLine* out = nullptr;
  InputLine* in = nullptr;
  EXPECT_EQ(chip.RequestOutput(3, false, &out), Status::kUnavailable);
  EXPECT_EQ(out, nullptr);
  EXPECT_EQ(chip.RequestInput(4, Edge::kFalling, &in), Status::kUnavailable);
  EXPECT_EQ(in, nullptr);
  EXPECT_NE(std::string(chip.error()).find("line 4"), std::string::npos) << chip.error();
}

TEST(GpiodV1, LookupByNameOfAnAbsentChipIsUnavailable) {
  GpiodV1Chip chip;
  EXPECT_EQ(chip.Open("gpiochip97"), Status::kUnavailable);
  EXPECT_NE(std::string(chip.error()).find("gpiochip97"), std::string::npos) << chip.error();
}

}  // namespace
}  // namespace ftstack::hal::gpio
