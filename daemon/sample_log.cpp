#include "daemon/sample_log.hpp"

#include <cerrno>
#include <cstdio>
#include <system_error>

#include "daemon/options.hpp"
#include "measurement/recording.hpp"

namespace ftstack::daemon {
namespace {

constexpr std::size_t kLogRingCapacity = std::size_t{1} << 15;

}  // namespace

SampleLog::SampleLog() = default;
SampleLog::~SampleLog() = default;

void SampleLog::Open(const std::string& path, std::vector<std::string> metadata,
                     double time_scale) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) {
    throw FtdError(path + ": cannot write: " + std::system_category().message(errno));
  }
  std::fclose(f);
  path_ = path;
  metadata_ = std::move(metadata);
  time_scale_ = time_scale;
  ring_.resize(kLogRingCapacity);
}

void SampleLog::Push(const fw::DeviceSample& sample) {
  if (ring_.empty()) return;
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= ring_.size()) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  ring_[head % ring_.size()] = sample;
  head_.store(head + 1, std::memory_order_release);
}

void SampleLog::Drain(const hal::AdcInfo& adc) {
  if (ring_.empty()) return;
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  if (tail == head) return;
  const double mvv_per_count =
      adc.max_counts > 0 ? static_cast<double>(adc.full_scale_nvv) * 1e-6 / adc.max_counts : 0.0;
  std::vector<double> row;
  for (; tail != head; ++tail) {
    const fw::PublishedSample& s = ring_[tail % ring_.size()].sample;
    if (!writer_) {
      std::vector<std::string> names{"t"};
      for (std::size_t c = 0; c < s.channel_count; ++c) names.push_back("b" + std::to_string(c));
      for (std::size_t c = 0; c < s.channel_count; ++c) names.push_back("raw" + std::to_string(c));
      for (const std::string& n : WrenchColumns()) names.push_back(n);
      if (s.has_temperature) names.push_back("temp_C");
      names.push_back("status");
      writer_ = std::make_unique<RecordingWriter>(path_, metadata_, names);
    }
    if (logged_rows_ > 0 && s.timestamp_us < last_timestamp_us_) {
      time_base_us_ += std::uint64_t{1} << 32;  // the 32-bit µs timestamp wrapped
    }
    last_timestamp_us_ = s.timestamp_us;
    row.clear();
    row.push_back(static_cast<double>(time_base_us_ + s.timestamp_us) * 1e-6 * time_scale_);
    for (std::size_t c = 0; c < s.channel_count; ++c) {
      row.push_back(s.raw_counts[c] * mvv_per_count);
    }
    for (std::size_t c = 0; c < s.channel_count; ++c) row.push_back(s.raw_counts[c]);
    for (std::size_t i = 0; i < fw::kAxes; ++i) row.push_back(s.wrench[i] * fw::AxisLsb(i));
    if (s.has_temperature) row.push_back(s.temperature_mdegc * 1e-3);
    row.push_back(s.status);
    writer_->WriteRow(row);
    ++logged_rows_;
  }
  tail_.store(tail, std::memory_order_release);
}

void SampleLog::Flush() {
  if (writer_) writer_->Flush();
}

}  // namespace ftstack::daemon
