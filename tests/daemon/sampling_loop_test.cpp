// ftd's sampling loop against a converter that fails at once: a bounded back-off instead of a busy
// loop, the fault published (status bits 3 and 8) while it lasts, recovery when it ends (issue 17,
// item 10).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <ctime>
#include <memory>
#include <thread>

#include "daemon/daemon.hpp"
#include "firmware/register_map.hpp"
#include "firmware/status_bits.hpp"

namespace ftstack::daemon {
namespace {

/// How the fake converter behaves.
enum class Mode : int { kReadErrorAtOnce = 0, kTimeoutAtOnce, kWorking };

/// A converter whose failures return at once (no waiting), counting every attempt.
class FailingAdc final : public hal::Adc {
 public:
  std::atomic<Mode> mode{Mode::kReadErrorAtOnce};
  std::atomic<long> attempts{0};

 private:
  hal::Status DoConfigure(const hal::AdcConfig& config) override {
    info_ = hal::AdcInfo{config.channel_count, -(1 << 23), (1 << 23) - 1, 3906250,
                         config.rate_hz,       false};
    return hal::Status::kOk;
  }
  hal::Status DoWaitDataReady(std::uint32_t) override {
    attempts.fetch_add(1);
    switch (mode.load()) {
      case Mode::kReadErrorAtOnce:
        return hal::Status::kOk;
      case Mode::kTimeoutAtOnce:
        return hal::Status::kTimeout;  // a driver that gives up without waiting
      case Mode::kWorking:
        break;
    }
    timespec ts{0, 1000000};  // one period at 1 kHz
    nanosleep(&ts, nullptr);
    return hal::Status::kOk;
  }
  hal::Status DoRead(hal::AdcSample& out) override {
    out = hal::AdcSample{};
    out.channel_count = info_.channel_count;
    return mode.load() == Mode::kReadErrorAtOnce ? hal::Status::kReadError : hal::Status::kOk;
  }
  hal::AdcInfo DoInfo() const override { return info_; }
  hal::AdcInfo info_{};
};

FailingAdc* g_adc = nullptr;

class FailingBackend final : public AdcBackend {
 public:
  hal::Adc& adc() override { return *g_adc; }
  [[nodiscard]] std::uint8_t channel_count() const override { return 6; }
  [[nodiscard]] std::optional<cal::CalFile> BuiltinCalibration(const hal::AdcInfo&) const override {
    cal::CalFile f;
    f.cal.channel_count = 6;
    for (std::size_t i = 0; i < 6; ++i) f.cal.matrix[i][i] = 100.0;  // N or N·m per mV/V
    return f;
  }
};

std::unique_ptr<AdcBackend> MakeFailing(const FtdOptions&) {
  return std::make_unique<FailingBackend>();
}

/// Most attempts a loop backing off from `period_us`, doubling up to kMaxBackoffUs, can make in
/// `window_s`: sleeps never end early, so the pauses before the last attempt fit in the window.
long MaxAttempts(double window_s, std::uint32_t period_us) {
  long n = 1;
  double slept_s = 0;
  std::uint32_t b = period_us;
  while (slept_s + b * 1e-6 <= window_s) {
    slept_s += b * 1e-6;
    ++n;
    b = std::min(2 * b, kMaxBackoffUs);
  }
  return n;
}

std::uint16_t Status(Ftd& ftd) {
  std::uint16_t s = 0;
  EXPECT_EQ(ftd.register_map().ReadInput(fw::kInStatus, 1, &s), fw::ModbusException::kNone);
  return s;
}

void ExpectBackOff(Mode mode) {
  FailingAdc adc;
  adc.mode = mode;
  g_adc = &adc;
  FtdOptions opt;
  opt.rate_hz = 1000;
  Ftd ftd(opt, &MakeFailing);
  const auto t0 = std::chrono::steady_clock::now();
  ftd.Start();
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  const std::uint16_t status = Status(ftd);
  const long attempts_while_failing = adc.attempts.load();
  const double window_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // The fault is published and stays: ADC fault and stale, wrench not refreshed.
  EXPECT_NE(status & fw::kStatusAdcFault, 0);
  EXPECT_NE(status & fw::kStatusStale, 0);
  // Before: a busy loop (millions of attempts in 0.6 s). Now: the back-off's schedule.
  EXPECT_GE(attempts_while_failing, 2);
  EXPECT_LE(attempts_while_failing, MaxAttempts(window_s, 1000)) << "in " << window_s << " s";
  FtdStats st = ftd.stats();
  EXPECT_GE(st.adc_errors, static_cast<std::uint64_t>(attempts_while_failing) - 1);
  EXPECT_GE(st.backoffs, st.adc_errors - 1);  // every failure returned at once
  EXPECT_EQ(st.samples, 0u);
  // The converter recovers: sampling resumes (within one pause of ≤ 100 ms) and bit 3 clears.
  adc.mode = Mode::kWorking;
  for (int i = 0; i < 500 && ftd.stats().samples < 20; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_GE(ftd.stats().samples, 20u);
  EXPECT_EQ(Status(ftd) & fw::kStatusAdcFault, 0);
  ftd.Stop();
  g_adc = nullptr;
}

TEST(SamplingLoop, ReadErrorAtOnceBacksOffInsteadOfSpinning) {
  ExpectBackOff(Mode::kReadErrorAtOnce);
}

TEST(SamplingLoop, TimeoutAtOnceBacksOffInsteadOfSpinning) { ExpectBackOff(Mode::kTimeoutAtOnce); }

}  // namespace
}  // namespace ftstack::daemon
