// ftd's Sparkplug B metric set: what DBIRTH lists, DDATA always carries and reports by exception.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "daemon/sparkplug.hpp"
#include "firmware/device.hpp"

namespace ftstack::daemon {

/// The averaged wrench of one publication window (sums of the sampling thread's LSB values).
struct WrenchWindow {
  std::array<std::int64_t, 6> sum_lsb{};
  std::uint32_t samples = 0;
  std::uint32_t last_sequence = 0;  ///< sequence of the window's last sample
  std::uint64_t end_us = 0;         ///< device clock of the window's last sample
  std::uint16_t status_or = 0;      ///< status bits seen during the window
  std::uint8_t invalid_axes = 0;    ///< bit r: axis r was not a value in some sample
};

/// The state reported by exception, read by the publishing thread (never the sampling thread).
struct DeviceState {
  fw::DeviceSample latest{};
  std::array<float, 6> transform{};  ///< tool transform, Dx Dy Dz m, Rx Ry Rz deg (holding 10–21)
  std::uint16_t filter_length = 1;
  std::uint16_t decimation = 1;
  bool gravity_comp = false;
  std::uint64_t mqtt_dropped = 0;
  std::uint32_t mqtt_reconnects = 0;
  std::uint32_t commands = 0;  ///< commands handled (the acknowledgement counter)
  std::string last_command;    ///< "" until the first
  std::string last_result;
  bool write_protected = false;
};

/// Wrench metrics of a window: Wrench/Fx_n … Wrench/Mz_nm (Double, the window's mean; null for
/// an axis that was invalid), Wrench/Samples, Wrench/Sequence, Wrench/Time_us (UTC µs of the
/// window's last sample, `utc_offset_us` = UTC − device clock).
[[nodiscard]] std::vector<sparkplug::Metric> WrenchMetrics(const WrenchWindow& w,
                                                           std::int64_t utc_offset_us);

/// Every metric reported by exception (status bits, events, peaks, configuration, publisher,
/// command acknowledgement). One list: a new group of metrics (e.g. health findings) is added
/// here and appears in DBIRTH and, when it changes, in DDATA.
[[nodiscard]] std::vector<sparkplug::Metric> ExceptionMetrics(const DeviceState& s);

/// The command metrics DBIRTH declares (Device Control/Tare, Device Control/Clear Peaks).
[[nodiscard]] std::vector<sparkplug::Metric> CommandMetrics();

/// The metrics of `now` that differ from the same-named metric in `sent` (or are new there).
[[nodiscard]] std::vector<sparkplug::Metric> Changed(const std::vector<sparkplug::Metric>& now,
                                                     const std::vector<sparkplug::Metric>& sent);

}  // namespace ftstack::daemon
