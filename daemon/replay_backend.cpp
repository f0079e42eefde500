#include "daemon/replay_backend.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "calibration/file/recorded_unit.hpp"
#include "firmware/fixed_calibration.hpp"
#include "measurement/recording.hpp"

namespace ftstack::daemon {
namespace {

using Counts = std::array<std::int32_t, hal::kMaxChannels>;

/// Recorded counts delivered one row per conversion; kEndOfData after the last row.
class ReplayAdc final : public hal::Adc {
 public:
  ReplayAdc(std::vector<Counts> rows, std::vector<std::int32_t> temperature_mdegc,
            const hal::AdcInfo& info, bool paced)
      : rows_(std::move(rows)),
        temperature_mdegc_(std::move(temperature_mdegc)),
        info_(info),
        paced_(paced) {
    info_.simulated = true;  // not a live sensor: status bit 7, as the simulator
    info_.clock_timestamps = paced;
  }

 private:
  using Clock = std::chrono::steady_clock;

  hal::Status DoConfigure(const hal::AdcConfig& config) override {
    if (config.channel_count != info_.channel_count) return hal::Status::kInvalidArgument;
    info_.rate_hz = config.rate_hz;
    next_ = 0;
    start_ = Clock::now();
    configured_ = true;
    return hal::Status::kOk;
  }
  hal::Status DoWaitDataReady(std::uint32_t timeout_us) override {
    if (!configured_) return hal::Status::kNotConfigured;
    if (next_ >= rows_.size()) return hal::Status::kEndOfData;
    if (!paced_) return hal::Status::kOk;
    const auto due = start_ + std::chrono::microseconds(DueUs(next_));
    const auto deadline = Clock::now() + std::chrono::microseconds(timeout_us);
    if (due > deadline) {
      std::this_thread::sleep_until(deadline);
      return hal::Status::kTimeout;
    }
    std::this_thread::sleep_until(due);
    return hal::Status::kOk;
  }
  hal::Status DoRead(hal::AdcSample& out) override {
    if (!configured_) return hal::Status::kNotConfigured;
    if (next_ >= rows_.size()) return hal::Status::kEndOfData;
    out.channel_count = info_.channel_count;
    out.counts = rows_[next_];
    out.flags = {};
    out.timestamp_us = DueUs(next_);
    out.has_temperature = !temperature_mdegc_.empty();
    out.temperature_mdegc = out.has_temperature ? temperature_mdegc_[next_] : 0;
    ++next_;
    return hal::Status::kOk;
  }
  [[nodiscard]] hal::AdcInfo DoInfo() const override {
    return configured_ ? info_ : hal::AdcInfo{};
  }
  [[nodiscard]] std::uint64_t DueUs(std::size_t row) const {
    return static_cast<std::uint64_t>(row) * 1000000u / info_.rate_hz;
  }

  std::vector<Counts> rows_;
  std::vector<std::int32_t> temperature_mdegc_;
  hal::AdcInfo info_;
  bool paced_;
  bool configured_ = false;
  std::size_t next_ = 0;
  Clock::time_point start_;
};

class ReplayBackend final : public AdcBackend {
 public:
  explicit ReplayBackend(std::unique_ptr<ReplayAdc> adc, std::uint8_t channels)
      : adc_(std::move(adc)), channels_(channels) {}
  hal::Adc& adc() override { return *adc_; }
  [[nodiscard]] std::uint8_t channel_count() const override { return channels_; }

 private:
  std::unique_ptr<ReplayAdc> adc_;
  std::uint8_t channels_;
};

}  // namespace

std::unique_ptr<AdcBackend> MakeReplayBackend(const FtdOptions& opt) {
  if (opt.replay.empty() || opt.cal.empty()) {
    throw FtdError(
        "--adc replay needs --replay REC.csv and --cal CAL.json (the calibration "
        "whose converter the recording's counts are played as)");
  }
  try {
    const cal::CalFile cal = cal::LoadCalFile(opt.cal);
    ReadOptions ro;
    ro.require_bridges = true;
    Recording rec = ReadRecording(opt.replay, ro);
    const std::size_t n = cal.cal.channel_count;
    if (rec.BridgeCount() < n || n > hal::kMaxChannels) {
      throw FtdError(opt.replay + ": has " + std::to_string(rec.BridgeCount()) +
                     " bridge columns, the calibration " + opt.cal + " needs " + std::to_string(n));
    }
    const std::string used = cal::PrepareApplyInput(&rec, opt.replay_units, cal, opt.cal);
    std::fprintf(stderr, "ftd: replay %s: %s\n", opt.replay.c_str(), used.c_str());
    const double counts_per_input = fw::CountsPerMvv(cal.adc);
    std::vector<Counts> rows(rec.rows());
    for (std::size_t c = 0; c < n; ++c) {
      const std::vector<double>& col = rec.Column("b" + std::to_string(c));
      for (std::size_t i = 0; i < col.size(); ++i) {
        rows[i][c] = cal::InputCounts(col[i], counts_per_input, cal.adc);
      }
    }
    std::vector<std::int32_t> temperature_mdegc;
    if (rec.Has("temp_C")) {
      for (const double t : rec.Column("temp_C")) {
        temperature_mdegc.push_back(
            static_cast<std::int32_t>(std::lround(std::clamp(t, -1e6, 1e6) * 1000.0)));
      }
    }
    hal::AdcInfo info = cal.adc;
    info.channel_count = static_cast<std::uint8_t>(n);
    return std::make_unique<ReplayBackend>(
        std::make_unique<ReplayAdc>(std::move(rows), std::move(temperature_mdegc), info, opt.paced),
        static_cast<std::uint8_t>(n));
  } catch (const FtdError&) {
    throw;
  } catch (const std::exception& e) {
    throw FtdError(e.what());
  }
}

}  // namespace ftstack::daemon
