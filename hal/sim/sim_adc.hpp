// The simulated ADC backend: bridge signals in mV/V → counts exactly as a 24-bit ratiometric ADC.
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "hal/adc.hpp"

namespace ftstack::hal::sim {

/// The analog side seen by the simulated ADC: bridge outputs in mV/V at a given time.
/// Implemented by the physics simulator (sim/) or by a test.
class BridgeSignalSource {
 public:
  virtual ~BridgeSignalSource() = default;
  /// Number of bridges this source drives (1 … kMaxChannels).
  [[nodiscard]] virtual std::uint8_t channel_count() const = 0;
  /// Fills bridge_mvv[0 … channel_count) with the bridge outputs in mV/V at time t_s and
  /// *temperature_c with the body temperature (°C, NaN if none). Returns false once exhausted.
  [[nodiscard]] virtual bool Sample(double t_s, double* bridge_mvv, double* temperature_c) = 0;
};

/// Injected faults, for testing the firmware's fault detection.
enum class SimFault : std::uint8_t {
  kNone = 0,
  kNoDataReady,  ///< data-ready never comes (WaitDataReady times out)
  kStuck,        ///< counts freeze at their last value
  kReadError,    ///< every read fails
  kOpenBridge,   ///< channel `fault_channel` reads at the positive rail (open gauge)
};

/// Electrical parameters of the simulated converter.
struct SimAdcParams {
  int resolution_bits = 24;  ///< two's-complement output width, 8 … 31
  /// Reference over excitation voltage. The input span is ±reference_ratio / gain of the
  /// excitation: 0.5 gives the HX711's ±0.5·AVDD/gain (3.90625 mV/V at gain 128).
  double reference_ratio = 0.5;
  double noise_rms_mvv = 1.0e-4;  ///< input-referred white noise per channel, mV/V RMS
  std::uint64_t seed = 1;         ///< noise seed: equal seeds give equal sample streams
  bool realtime = false;          ///< pace WaitDataReady to the wall clock (false: virtual time)
  double speed = 1.0;             ///< with realtime: simulated seconds per wall-clock second (> 0)
  /// Operating point the noise figure belongs to (a converter model's gain and data rate, see
  /// sim/adc_models.hpp). 0 accepts any; otherwise Configure rejects another value with
  /// kInvalidArgument, so the noise of the counts always matches the configuration.
  std::uint16_t required_gain = 0;
  std::uint32_t required_rate_hz = 0;
  /// Stall: Read holds its caller stall_us on every stall_every-th sample (0: never), as if the
  /// sampling thread were preempted there — deterministic late samples for tests.
  std::uint32_t stall_every = 0;
  std::uint32_t stall_us = 0;
  /// With realtime: conversions per data-ready (1 … kMaxBlockSamples), like a converter's FIFO
  /// with a watermark. The caller wakes once per block and reads the block without waiting.
  std::uint16_t block_samples = 1;
  /// False: a converter without a temperature input (an HX711): its samples carry no temperature,
  /// whatever the source gives.
  bool temperature = true;
};

/// Largest block of SimAdcParams::block_samples.
inline constexpr std::uint16_t kMaxBlockSamples = 64;

/// Simulated ratiometric delta-sigma ADC. counts = round(mV/V · max_counts / full_scale_mvv +
/// noise), clipped to the rails. The n-th sample converts at n / rate_hz (simulated time); its
/// timestamp is that instant on the wall clock when paced (realtime), the simulated time if not.
class SimAdc final : public Adc {
 public:
  SimAdc(BridgeSignalSource& source, const SimAdcParams& params);

  /// Injects a fault from now on (kNone clears it). `channel` selects the channel for kOpenBridge.
  void SetFault(SimFault fault, std::uint8_t channel = 0) {
    fault_ = fault;
    fault_channel_ = channel;
  }
  /// Counts per mV/V of the current configuration.
  [[nodiscard]] double counts_per_mvv() const { return counts_per_mvv_; }
  /// Index of the next sample to be produced.
  [[nodiscard]] std::uint64_t sample_index() const { return index_; }

 private:
  Status DoConfigure(const AdcConfig& config) override;
  Status DoWaitDataReady(std::uint32_t timeout_us) override;
  Status DoRead(AdcSample& out) override;
  AdcInfo DoInfo() const override { return info_; }
  /// Wall-clock instant (CLOCK_MONOTONIC, ns) at which sample `index` converts when paced.
  [[nodiscard]] std::int64_t DueNs(std::uint64_t index) const;

  BridgeSignalSource& source_;
  SimAdcParams params_;
  AdcInfo info_{};
  bool configured_ = false;
  bool ready_ = false;
  double counts_per_mvv_ = 0.0;
  std::uint64_t index_ = 0;
  std::int64_t start_ns_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  SimFault fault_ = SimFault::kNone;
  std::uint8_t fault_channel_ = 0;
  AdcSample last_{};
};

}  // namespace ftstack::hal::sim
