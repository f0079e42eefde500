// ftd's hardware ADC factory on a machine without GPIO or SPI: clear one-line refusals.
#include "daemon/hardware_adc.hpp"
#include "tests/support/temp_dir.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ftstack::daemon {
namespace {

std::unique_ptr<hal::Adc> Make(const std::string& kind, const std::string& chip,
                               const std::string& spi, std::string* error) {
  HardwareAdcOptions o;
  o.kind = kind;
  o.gpiochip = chip;
  o.spidev = spi;
  try {
    return MakeHardwareAdc(o);
  } catch (const FtdError& e) {  // the one error convention of the daemon's start-up
    *error = e.what();
    return nullptr;
  }
}

TEST(HardwareAdc, Hx711NeedsAGpioChip) {
  std::string error;
  EXPECT_EQ(Make("hx711", "", "", &error), nullptr);
  EXPECT_EQ(error, "--adc hx711 needs --gpiochip /dev/gpiochipN");
}

TEST(HardwareAdc, Hx711OnAnAbsentChipSaysWhichAndWhy) {
  std::string error;
  EXPECT_EQ(Make("hx711", "/dev/gpiochip-absent-7", "", &error), nullptr);
  EXPECT_NE(error.find("/dev/gpiochip-absent-7"), std::string::npos) << error;
  EXPECT_NE(error.find("No such file or directory"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(HardwareAdc, SpiNeedsBothNodesAndNamesTheMissingOne) {
  std::string error;
  EXPECT_EQ(Make("spi", "/dev/gpiochip0", "", &error), nullptr);
  EXPECT_NE(error.find("--spidev"), std::string::npos) << error;
  EXPECT_EQ(Make("spi", "/dev/gpiochip0", "/dev/spidev-absent-0.0", &error), nullptr);
  EXPECT_NE(error.find("/dev/spidev-absent-0.0"), std::string::npos) << error;
  EXPECT_EQ(Make("spi", "/dev/gpiochip0", "/dev/null", &error), nullptr);
  EXPECT_NE(error.find("not an spidev device"), std::string::npos) << error;
}

TEST(HardwareAdc, ParsesHx711LineMaps) {
  const auto lines = ParseHx711Lines("5:6,5:13,17:27");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], (std::pair<unsigned, unsigned>{5, 6}));
  EXPECT_EQ(lines[2], (std::pair<unsigned, unsigned>{17, 27}));
  for (const char* bad : {"", "5", "5:", "5:x", "5:6,", "5:5", "-1:3",
                          "1:2,3:4,5:6,7:8,9:10,11:12,13:14,15:16,17:18"}) {
    EXPECT_THROW(ParseHx711Lines(bad), std::invalid_argument) << bad;
  }
}

TEST(HardwareAdc, BadEnvironmentValueIsReported) {
  setenv("FTD_HX711_LINES", "5:6,7", 1);
  std::string error;
  EXPECT_EQ(Make("hx711", "/dev/gpiochip0", "", &error), nullptr);
  unsetenv("FTD_HX711_LINES");
  EXPECT_NE(error.find("item 2"), std::string::npos) << error;
}

TEST(HardwareAdc, FtdRefusesWithOneLineAndNonZeroExit) {
  const std::string err_path = ftstack::test::ProcessTempDir() + "ftd_hw_err.txt";
  for (const std::string args :
       {"--adc hx711 --gpiochip /dev/gpiochip-absent-3 --rate-hz 80",
        "--adc spi --spidev /dev/spidev-absent-1.0 --gpiochip /dev/gpiochip0"}) {
    const std::string cmd =
        std::string(FTSTACK_BIN_DIR) + "/ftd " + args + " --duration-s 1 2> " + err_path;
    const int rc = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(rc)) << args;
    EXPECT_NE(WEXITSTATUS(rc), 0) << args;
    std::ifstream in(err_path);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    EXPECT_NE(text.find("absent"), std::string::npos) << text;
    EXPECT_NE(text.find("No such file or directory"), std::string::npos) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << text;
  }
}

}  // namespace
}  // namespace ftstack::daemon
