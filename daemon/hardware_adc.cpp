#include "daemon/hardware_adc.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "hal/gpio/gpiod_v1_chip.hpp"
#include "hal/gpio/system_clock.hpp"
#include "hal/hx711/hx711.hpp"
#include "hal/hx711/realtime.hpp"
#include "hal/spi/spidev.hpp"
#include "hal/spi_adc/ads131m.hpp"

namespace ftstack::daemon {
namespace {

unsigned ParseUnsigned(const std::string& text, const std::string& what) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos ||
      text.size() > 9) {
    throw std::invalid_argument(what + ": '" + text + "' is not a non-negative integer");
  }
  return static_cast<unsigned>(std::stoul(text));
}

const char* Env(const char* name) {
  const char* v = std::getenv(name);
  return v != nullptr && *v != '\0' ? v : nullptr;
}

/// The HX711 front end with everything it needs: the gpiochip and its lines, the clock.
class Hx711Board final : public hal::Adc {
 public:
  explicit Hx711Board(const HardwareAdcOptions& options) : options_(options) {}

  /// Opens the chip and requests the lines; false with a reason.
  bool Open(std::string* error) {
    if (chip_.Open(options_.gpiochip.c_str(), "ftd-hx711") != hal::Status::kOk) {
      *error = chip_.error();
      return false;
    }
    if (options_.channels < 1 ||
        options_.hx711_lines.size() < static_cast<std::size_t>(options_.channels)) {
      *error = "--adc hx711: " + std::to_string(options_.channels) + " bridges but " +
               std::to_string(options_.hx711_lines.size()) + " SCK:DOUT line pairs";
      return false;
    }
    std::vector<std::pair<unsigned, hal::gpio::OutputLine*>> clocks;
    for (int i = 0; i < options_.channels; ++i) {
      const auto [sck, dout] = options_.hx711_lines[static_cast<std::size_t>(i)];
      hal::gpio::OutputLine* clock = nullptr;
      for (const auto& [offset, line] : clocks) {
        if (offset == sck) clock = line;
      }
      if (clock == nullptr) {
        if (chip_.RequestOutput(sck, false, &clock) != hal::Status::kOk) {
          *error = chip_.error();
          return false;
        }
        clocks.emplace_back(sck, clock);
      }
      hal::gpio::InputLine* data = nullptr;
      if (chip_.RequestInput(dout, hal::gpio::Edge::kFalling, &data) != hal::Status::kOk) {
        *error = chip_.error();
        return false;
      }
      params_.wiring[static_cast<std::size_t>(i)] = hal::hx711::Wiring{clock, data};
    }
    params_.chip_count = static_cast<std::uint8_t>(options_.channels);
    return true;
  }

 private:
  hal::Status DoConfigure(const hal::AdcConfig& config) override {
    if (config.rate_hz != 10 && config.rate_hz != 80) {
      std::fprintf(stderr, "ftd: --adc hx711: --rate-hz must be 10 or 80 (the RATE pin)\n");
      return hal::Status::kInvalidArgument;
    }
    params_.rate_hz = config.rate_hz;
    adc_ = std::make_unique<hal::hx711::Hx711Adc>(params_, clock_);
    return adc_->Configure(config);
  }
  hal::Status DoWaitDataReady(std::uint32_t timeout_us) override {
    if (adc_ == nullptr) return hal::Status::kNotConfigured;
    if (!realtime_tried_) {  // first call comes from the sampling thread
      realtime_tried_ = true;
      char why[160];
      if (hal::EnterRealtime(options_.realtime_priority, true, why, sizeof why) !=
              hal::Status::kOk ||
          why[0] != '\0') {
        std::fprintf(stderr, "ftd: warning: %s\n", why);
      }
    }
    return adc_->WaitDataReady(timeout_us);
  }
  hal::Status DoRead(hal::AdcSample& out) override {
    return adc_ == nullptr ? hal::Status::kNotConfigured : adc_->Read(out);
  }
  hal::AdcInfo DoInfo() const override { return adc_ == nullptr ? hal::AdcInfo{} : adc_->Info(); }

  HardwareAdcOptions options_;
  hal::gpio::GpiodV1Chip chip_;
  hal::gpio::SystemClock clock_;
  hal::hx711::Hx711Params params_;
  std::unique_ptr<hal::hx711::Hx711Adc> adc_;
  bool realtime_tried_ = false;
};

/// The ADS131M front end: spidev node, /DRDY line on a gpiochip, clock.
class SpiBoard final : public hal::Adc {
 public:
  explicit SpiBoard(const HardwareAdcOptions& options) : options_(options) {}

  bool Open(std::string* error) {
    // ADS131M0x: SPI mode 1 (CPOL 0, CPHA 1).
    if (spi_.Open(options_.spidev.c_str(), 1, options_.spi_speed_hz) != hal::Status::kOk) {
      *error = spi_.error();
      return false;
    }
    if (chip_.Open(options_.gpiochip.c_str(), "ftd-ads131m") != hal::Status::kOk ||
        chip_.RequestInput(options_.drdy_line, hal::gpio::Edge::kFalling, &drdy_) !=
            hal::Status::kOk) {
      *error = std::string(chip_.error()) + " (the ADC's /DRDY line)";
      return false;
    }
    hal::spi_adc::Ads131mParams p;
    p.model = options_.ads131m06 ? hal::spi_adc::Ads131mModel::kAds131m06
                                 : hal::spi_adc::Ads131mModel::kAds131m08;
    p.excitation_uv = options_.excitation_uv;
    adc_ = std::make_unique<hal::spi_adc::Ads131mAdc>(p, spi_, *drdy_, clock_);
    return true;
  }

 private:
  hal::Status DoConfigure(const hal::AdcConfig& config) override {
    const hal::Status s = adc_->Configure(config);
    if (s != hal::Status::kOk && adc_->error()[0] != '\0') {
      std::fprintf(stderr, "ftd: %s\n", adc_->error());
    }
    return s;
  }
  hal::Status DoWaitDataReady(std::uint32_t timeout_us) override {
    return adc_->WaitDataReady(timeout_us);
  }
  hal::Status DoRead(hal::AdcSample& out) override { return adc_->Read(out); }
  hal::AdcInfo DoInfo() const override { return adc_->Info(); }

  HardwareAdcOptions options_;
  hal::spi::Spidev spi_;
  hal::gpio::GpiodV1Chip chip_;
  hal::gpio::InputLine* drdy_ = nullptr;
  hal::gpio::SystemClock clock_;
  std::unique_ptr<hal::spi_adc::Ads131mAdc> adc_;
};

}  // namespace

std::vector<std::pair<unsigned, unsigned>> ParseHx711Lines(const std::string& text) {
  std::vector<std::pair<unsigned, unsigned>> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, end - start);
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) {
      throw std::invalid_argument("HX711 lines: item " + std::to_string(out.size() + 1) + " '" +
                                  item + "' is not SCK:DOUT");
    }
    const std::string where = "HX711 lines: item " + std::to_string(out.size() + 1);
    out.emplace_back(ParseUnsigned(item.substr(0, colon), where),
                     ParseUnsigned(item.substr(colon + 1), where));
    if (out.back().first == out.back().second) {
      throw std::invalid_argument(where + ": SCK and DOUT are the same line");
    }
    start = end + 1;
  }
  if (out.empty() || out.size() > hal::kMaxChannels) {
    throw std::invalid_argument("HX711 lines: 1 to 8 SCK:DOUT pairs expected");
  }
  return out;
}

void ApplyHardwareEnvironment(HardwareAdcOptions& options) {
  if (const char* v = Env("FTD_HX711_LINES")) options.hx711_lines = ParseHx711Lines(v);
  if (const char* v = Env("FTD_DRDY_LINE")) options.drdy_line = ParseUnsigned(v, "FTD_DRDY_LINE");
  if (const char* v = Env("FTD_SPI_HZ")) options.spi_speed_hz = ParseUnsigned(v, "FTD_SPI_HZ");
  if (const char* v = Env("FTD_EXCITATION_UV")) {
    options.excitation_uv = ParseUnsigned(v, "FTD_EXCITATION_UV");
  }
  if (const char* v = Env("FTD_RT_PRIORITY")) {
    options.realtime_priority = static_cast<int>(ParseUnsigned(v, "FTD_RT_PRIORITY"));
  }
  if (const char* v = Env("FTD_ADS131M")) {
    const std::string m = v;
    if (m != "06" && m != "08")
      throw std::invalid_argument("FTD_ADS131M: '" + m + "' is not 06 or 08");
    options.ads131m06 = m == "06";
  }
}

std::unique_ptr<hal::Adc> MakeHardwareAdc(const HardwareAdcOptions& given) {
  HardwareAdcOptions options = given;
  try {
    ApplyHardwareEnvironment(options);
  } catch (const std::exception& e) {
    throw FtdError(e.what());
  }
  std::string error;
  if (options.kind == "hx711") {
    if (options.gpiochip.empty()) throw FtdError("--adc hx711 needs --gpiochip /dev/gpiochipN");
    auto board = std::make_unique<Hx711Board>(options);
    if (!board->Open(&error)) throw FtdError(error);
    return board;
  }
  if (options.kind == "spi") {
    if (options.spidev.empty() || options.gpiochip.empty()) {
      throw FtdError(
          "--adc spi needs --spidev /dev/spidevB.C and --gpiochip /dev/gpiochipN (/DRDY)");
    }
    auto board = std::make_unique<SpiBoard>(options);
    if (!board->Open(&error)) throw FtdError(error);
    return board;
  }
  throw FtdError("--adc " + options.kind + ": unknown hardware ADC (hx711, spi)");
}

namespace {

/// A hardware converter (HX711 over GPIO, ADS131M over SPI); needs a calibration file.
class HardwareBackend final : public AdcBackend {
 public:
  HardwareBackend(std::unique_ptr<hal::Adc> adc, std::uint8_t channels)
      : adc_(std::move(adc)), channels_(channels) {}
  hal::Adc& adc() override { return *adc_; }
  [[nodiscard]] std::uint8_t channel_count() const override { return channels_; }

 private:
  std::unique_ptr<hal::Adc> adc_;
  std::uint8_t channels_;
};

}  // namespace

std::unique_ptr<AdcBackend> MakeHardwareBackend(const FtdOptions& opt) {
  constexpr std::uint8_t kChannels = 6;
  const HardwareAdcOptions hw{opt.adc, opt.gpiochip, opt.spidev, kChannels};
  return std::make_unique<HardwareBackend>(MakeHardwareAdc(hw), kChannels);
}

}  // namespace ftstack::daemon
