// ADS131M06/08 driver against a fake chip modelling its register map, frames, CRC and /DRDY.
#include "hal/spi_adc/ads131m.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <string>

#include "hal/spi/spidev.hpp"
#include "tests/hal/fake_ads131m.hpp"

namespace ftstack::test {
namespace {

using hal::AdcConfig;
using hal::AdcSample;
using hal::Status;
using hal::spi_adc::Ads131mAdc;
using hal::spi_adc::Ads131mModel;
using hal::spi_adc::Ads131mParams;
namespace reg = hal::spi_adc::ads131m;

constexpr std::uint32_t kRateHz = 1000;  // OSR 4096 at 8.192 MHz
constexpr std::uint32_t kPeriodUs = 1000;

/// Ideal code of the chip for `uv` at `gain` in double precision (±VREF/gain ↔ ±2^23).
double IdealCounts(double uv, int gain) { return uv * 1e-6 * gain / 1.2 * 8388608.0; }

struct Rig {
  explicit Rig(std::uint8_t chip_channels = 8)
      : chip(time, chip_channels),
        params{chip_channels == 6 ? Ads131mModel::kAds131m06 : Ads131mModel::kAds131m08} {}
  Status Configure(std::uint8_t channels = 6, std::uint16_t gain = 32,
                   std::uint32_t rate_hz = kRateHz) {
    adc = std::make_unique<Ads131mAdc>(params, chip, chip.drdy(), time);
    AdcConfig cfg;
    cfg.channel_count = channels;
    cfg.gain = gain;
    cfg.rate_hz = rate_hz;
    return adc->Configure(cfg);
  }
  Status Next(AdcSample& s) {
    const Status w = adc->WaitDataReady(2 * kPeriodUs);
    return w == Status::kOk ? adc->Read(s) : w;
  }
  FakeTime time;
  FakeAds131m chip;
  Ads131mParams params;
  std::unique_ptr<Ads131mAdc> adc;
};

const InputsUv kInputs = {1000.0, -2500.5, 0.0, 37.5, -0.02, 18000.0, -9000.0, 12.0};

TEST(Ads131mCrc, MatchesTheCcittFalseCheckValue) {
  // CRC-16/CCITT-FALSE (poly 1021h, init FFFFh) of "123456789" is 29B1h (the published check).
  const std::uint8_t msg[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
  EXPECT_EQ(reg::Crc16Ccitt(msg, sizeof msg), 0x29B1);
  EXPECT_EQ(reg::Crc16Ccitt(msg, 0), 0xFFFF);
}

TEST(Ads131mCommands, EncodingFollowsTheDataSheetBitPatterns) {
  EXPECT_EQ(reg::Rreg(0x00), 0b1010000000000000);
  EXPECT_EQ(reg::Rreg(0x3F, 2), 0b1011111110000001);
  EXPECT_EQ(reg::Wreg(0x03), 0b0110000110000000);
  EXPECT_EQ(reg::WregAck(0x03), 0b0100000110000000);
  EXPECT_EQ(reg::ResetAck(8), 0xFF28);
  EXPECT_EQ(reg::ResetAck(6), 0xFF26);
}

TEST(Ads131m, ConfiguresRegistersAndVerifiesThem) {
  Rig r;
  ASSERT_EQ(r.Configure(6, 32, kRateHz), Status::kOk) << r.adc->error();
  // MODE: RX_CRC_EN (bit 12), RESET cleared (bit 10), WLENGTH 24 bit (01b at 9:8), TIMEOUT (4).
  EXPECT_EQ(r.chip.reg(reg::kRegMode), 0x1110);
  // CLOCK: all 8 channels on (15:8), OSR 4096 = code 5 (4:2), high-resolution power (10b).
  EXPECT_EQ(r.chip.reg(reg::kRegClock), 0xFF00 | 5 << 2 | 2);
  // Gain 32 = code 5 in every nibble.
  EXPECT_EQ(r.chip.reg(reg::kRegGain1), 0x5555);
  EXPECT_EQ(r.chip.reg(reg::kRegGain2), 0x5555);
  const hal::AdcInfo info = r.adc->Info();
  EXPECT_EQ(info.rate_hz, 1000u);
  EXPECT_EQ(info.min_counts, -8388608);
  EXPECT_EQ(info.max_counts, 8388607);
  // ±1.2 V / 32 over a 5 V excitation: 7.5 mV/V.
  EXPECT_EQ(info.full_scale_nvv, 7500000);
  EXPECT_EQ(r.chip.input_crc_errors(), 0);
  EXPECT_EQ(r.adc->counters().retries, 0u);
}

TEST(Ads131m, ReadsEveryChannelAsThePgaAndConverterDoAndTracksTheRate) {
  Rig r;
  InputsUv in2 = kInputs;
  for (double& v : in2) v = -v * 1.5;
  ASSERT_EQ(r.Configure(8, 16), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs);  // after Configure: the chip converts during configuration too
  r.chip.PushInputs(in2);
  AdcSample s;
  for (const InputsUv& in : {kInputs, in2}) {
    ASSERT_EQ(r.Next(s), Status::kOk);
    ASSERT_EQ(s.channel_count, 8);
    for (int i = 0; i < 8; ++i) {
      // Quantisation: the code is the ideal value rounded, so within half a count.
      EXPECT_NEAR(s.counts[i], IdealCounts(in[i], 16), 0.5) << i;
      EXPECT_EQ(s.flags[i], 0) << i;
    }
  }
  EXPECT_EQ(r.chip.input_crc_errors(), 0);
  EXPECT_EQ(r.chip.period_ns(), 1000000);  // the chip really runs at the configured 1 kHz
}

TEST(Ads131m, PerChannelGainsAreProgrammedAndReportedOnTheSmallestGainsScale) {
  Rig r;
  r.params.channel_gain = {128, 0, 64, 1, 0, 0, 0, 0};  // 0: AdcConfig::gain (8)
  ASSERT_EQ(r.Configure(6, 8), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs);
  // Codes: 128 → 7, 8 → 3, 64 → 6, 1 → 0, channels 4…7 → 3.
  EXPECT_EQ(r.chip.reg(reg::kRegGain1), 0x0637);
  EXPECT_EQ(r.chip.reg(reg::kRegGain2), 0x3333);
  // Smallest gain in use is 1: ±1.2 V over 5 V = 240 mV/V.
  EXPECT_EQ(r.adc->Info().full_scale_nvv, 240000000);
  AdcSample s;
  ASSERT_EQ(r.Next(s), Status::kOk);
  const int gains[] = {128, 8, 64, 1, 8, 8};
  for (int i = 0; i < 6; ++i) {
    // The chip rounds at its own gain (±0.5 of its count), the driver divides by gain/1 and
    // rounds again (±0.5): within 0.5 + 0.5/ratio of the ideal value at gain 1.
    const double ratio = gains[i];
    EXPECT_NEAR(s.counts[i], IdealCounts(kInputs[i], 1), 0.5 + 0.5 / ratio) << i;
  }
  // At gain 128 channel 0 resolves what gain 1 cannot: its raw code is exact to 1/128.
  EXPECT_EQ(FakeAds131m::Code(kInputs[0], 128), std::lround(IdealCounts(kInputs[0], 128)));
}

TEST(Ads131m, OutputCrcErrorDropsTheSampleAndIsCounted) {
  Rig r;
  ASSERT_EQ(r.Configure(), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs, 3);
  AdcSample s;
  ASSERT_EQ(r.Next(s), Status::kOk);
  r.chip.CorruptNextOutputFrames(1);
  ASSERT_EQ(r.Next(s), Status::kReadError);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NE(s.flags[i] & hal::kChannelReadError, 0) << i;
    EXPECT_EQ(s.counts[i], 0) << i;  // no corrupted value passed on
  }
  EXPECT_EQ(r.adc->counters().crc_errors, 1u);
  ASSERT_EQ(r.Next(s), Status::kOk);
  EXPECT_NEAR(s.counts[1], IdealCounts(kInputs[1], 32), 0.5);
}

TEST(Ads131m, CorruptedRegisterWriteIsCaughtByReadBackAndRetried) {
  Rig r;
  r.chip.CorruptNextWregData(1);  // MODE, written before the input CRC check is on
  ASSERT_EQ(r.Configure(), Status::kOk) << r.adc->error();
  EXPECT_EQ(r.chip.reg(reg::kRegMode), 0x1110);
  EXPECT_EQ(r.adc->counters().retries, 1u);
}

TEST(Ads131m, CorruptedWriteWithInputCrcOnIsFlaggedByTheChipAndRetried) {
  Rig r;
  r.params.attempts = 3;
  ASSERT_EQ(r.Configure(), Status::kOk) << r.adc->error();  // RX_CRC_EN now set
  r.chip.CorruptNextWregData(2);  // MODE (first write of the re-configure) twice
  ASSERT_EQ(r.Configure(6, 64), Status::kOk) << r.adc->error();
  EXPECT_GE(r.chip.input_crc_errors(), 1);  // the chip noticed the second one (CRC on by then)
  EXPECT_EQ(r.adc->counters().retries, 2u);
  EXPECT_EQ(r.chip.reg(reg::kRegGain1), 0x6666);
}

TEST(Ads131m, PersistentWriteCorruptionFailsConfigureNamingTheRegister) {
  Rig r;
  r.params.attempts = 3;
  r.chip.CorruptNextWregData(3);
  EXPECT_EQ(r.Configure(), Status::kReadError);
  const std::string err = r.adc->error();
  EXPECT_NE(err.find("register 02h"), std::string::npos) << err;
  EXPECT_EQ(r.adc->WaitDataReady(1000), Status::kNotConfigured);
}

TEST(Ads131m, MissingDataReadyTimesOut) {
  Rig r;
  ASSERT_EQ(r.Configure(), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs, 4);
  AdcSample s;
  ASSERT_EQ(r.Next(s), Status::kOk);
  r.chip.SetDrdyStuckHigh(true);
  const std::int64_t t0 = r.time.now_ns;
  EXPECT_EQ(r.adc->WaitDataReady(2 * kPeriodUs), Status::kTimeout);
  EXPECT_GE(r.time.now_ns - t0, 2 * kPeriodUs * 1000);  // it waited the whole timeout
  EXPECT_EQ(r.adc->Read(s), Status::kTimeout);
  EXPECT_EQ(r.adc->counters().timeouts, 1u);
  r.chip.SetDrdyStuckHigh(false);
  EXPECT_EQ(r.Next(s), Status::kOk);
}

TEST(Ads131m, ScriptExhaustedMeansNoDataReady) {
  Rig r;
  ASSERT_EQ(r.Configure(), Status::kOk);
  EXPECT_EQ(r.adc->WaitDataReady(5 * kPeriodUs), Status::kTimeout);
}

TEST(Ads131m, LockedInterfaceIsUnlockedBeforeReset) {
  Rig r;
  r.chip.Lock();
  ASSERT_EQ(r.Configure(), Status::kOk) << r.adc->error();
  EXPECT_EQ(r.chip.reg(reg::kRegGain1), 0x5555);
}

TEST(Ads131m, UnexpectedChipResetIsDetectedAndTheRegistersReapplied) {
  Rig r;
  ASSERT_EQ(r.Configure(6, 4), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs, 2);
  AdcSample s;
  ASSERT_EQ(r.Next(s), Status::kOk);
  r.chip.PowerGlitch();           // back to gain 1, 4 kSPS, RESET flag set
  r.chip.PushInputs(kInputs, 8);  // it converts at its default 4 kSPS while being reconfigured
  ASSERT_EQ(r.Next(s), Status::kReadError);
  EXPECT_EQ(r.adc->counters().unexpected_resets, 1u);
  EXPECT_NE(s.flags[0] & hal::kChannelReadError, 0);
  ASSERT_EQ(r.Next(s), Status::kOk);
  EXPECT_EQ(r.chip.reg(reg::kRegGain1), 0x2222);
  EXPECT_NEAR(s.counts[5], IdealCounts(kInputs[5], 4), 0.5);
}

TEST(Ads131m, Ads131m06HasItsOwnFrameLengthAndIdentity) {
  Rig r(6);
  ASSERT_EQ(r.Configure(6, 2), Status::kOk) << r.adc->error();
  r.chip.PushInputs(kInputs);
  EXPECT_EQ(r.chip.reg(reg::kRegClock), 0x3F00 | 5 << 2 | 2);
  AdcSample s;
  ASSERT_EQ(r.Next(s), Status::kOk);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(s.counts[i], IdealCounts(kInputs[i], 2), 0.5) << i;
  // An ADS131M08 driver configuration on this chip is refused by the identity checks.
  Rig wrong(6);
  wrong.params.model = Ads131mModel::kAds131m08;
  EXPECT_EQ(wrong.Configure(), Status::kUnavailable);
  EXPECT_NE(std::string(wrong.adc->error()).find("FF28"), std::string::npos) << wrong.adc->error();
}

TEST(Ads131m, NothingOnTheBusIsUnavailable) {
  for (std::uint8_t level : {0x00, 0xFF}) {
    FakeTime time;
    AbsentSpiDevice bus(level);
    FakeAds131m unused(time, 8);
    Ads131mAdc adc(Ads131mParams{}, bus, unused.drdy(), time);
    AdcConfig cfg;
    EXPECT_EQ(adc.Configure(cfg), Status::kUnavailable);
    EXPECT_NE(std::string(adc.error()).find("RESET response"), std::string::npos) << adc.error();
  }
}

TEST(Ads131m, RejectsWhatTheChipCannotDo) {
  Rig r;
  EXPECT_EQ(r.Configure(6, 3), Status::kInvalidArgument);         // gain not a power of two
  EXPECT_EQ(r.Configure(6, 256), Status::kInvalidArgument);       // above 128
  EXPECT_EQ(r.Configure(6, 32, 1234), Status::kInvalidArgument);  // no such data rate
  EXPECT_EQ(r.Configure(6, 32, 252), Status::kOk);                // OSR 16256: 251.97 Hz
  EXPECT_EQ(r.adc->Info().rate_hz, 252u);
  Rig six(6);
  EXPECT_EQ(six.Configure(7), Status::kInvalidArgument);
  EXPECT_EQ(six.chip.frames(), 0);  // refused before any I/O
}

TEST(Spidev, MissingNodeIsUnavailableWithTheReason) {
  hal::spi::Spidev dev;
  const char* path = "/dev/spidev-ftstack-test-absent";
  ASSERT_NE(access(path, F_OK), 0);
  EXPECT_EQ(dev.Open(path, 1, 8000000), Status::kUnavailable);
  const std::string err = dev.error();
  EXPECT_NE(err.find(path), std::string::npos) << err;
  EXPECT_NE(err.find("No such file or directory"), std::string::npos) << err;
  std::uint8_t buf[4] = {};
  EXPECT_EQ(dev.Transfer(buf, buf, sizeof buf), Status::kUnavailable);
}

TEST(Spidev, ANodeThatIsNoSpidevIsUnavailable) {
  hal::spi::Spidev dev;
  EXPECT_EQ(dev.Open("/dev/null", 1, 8000000), Status::kUnavailable);
  const std::string err = dev.error();
  EXPECT_NE(err.find("not an spidev device"), std::string::npos) << err;
  EXPECT_FALSE(dev.is_open());
}

}  // namespace
}  // namespace ftstack::test
