// Simulated recordings with known physics: load profile → sensor model → effects → simulated ADC.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "measurement/recording.hpp"
#include "sim/effects.hpp"
#include "sim/sensor_description.hpp"

namespace ftstack::sim {

/// What to record. Everything is deterministic per `seed`.
struct RecordRequest {
  SensorDescription sensor = DefaultSensorDescription();
  std::string profile = "rig";  ///< see MakeProfile
  double rate_hz = 0.0;         ///< 0: the profile's default (rig/taps/thermal 200, hold 100)
  double duration_s = 0.0;      ///< 0: the profile's natural length
  std::uint64_t seed = 1;
  std::optional<double> noise_mvv;  ///< overrides the sensor's ADC noise (mV/V RMS)
  std::vector<EffectSpec> effects;  ///< injected into the real recording only
  bool temperature = true;          ///< write temp_C
};

/// The outputs of one request.
struct RecordResult {
  Recording real;        ///< effects + ADC noise and quantisation (what ftdiag gets as --real)
  Recording sim;         ///< the model's noise-free prediction without effects (--sim)
  nlohmann::json truth;  ///< schema "ftsim-truth/1": the injected effects, exact parameters, where
  std::vector<Effect> effects;  ///< resolved effects (defaults filled in)
  Eigen::MatrixXd clean_real;   ///< real before the ADC (N × rows, mV/V)
  LoadProfile profile;          ///< the load actually applied (after inserted overloads)
};

/// Makes the real and simulated recordings and the truth. Throws ProfileError, EffectSpecError,
/// SensorDescriptionError or std::invalid_argument with a one-line reason.
[[nodiscard]] RecordResult MakeRecording(const RecordRequest& request);

/// `specs` resolved against `model` for `profile` sampled at `rate_hz` (defaults filled in; the
/// overloads an overload_shift needs inserted into `profile`).
[[nodiscard]] std::vector<Effect> ResolveEffects(const SensorModel& model, LoadProfile& profile,
                                                 double rate_hz,
                                                 const std::vector<EffectSpec>& specs,
                                                 std::uint64_t seed);

/// What Compose needs for `profile` sampled at `rate_hz` from 0 to its duration, with `specs`
/// resolved against `model` (defaults filled in; the overloads an overload_shift needs inserted
/// into `profile`). The input points at `model` and `profile`: they must outlive it.
struct ComposeSetup {
  ComposeInput in;
  std::vector<Effect> effects;
};
[[nodiscard]] ComposeSetup SetUpCompose(const SensorModel& model, LoadProfile& profile,
                                        double rate_hz, const std::vector<EffectSpec>& specs,
                                        std::uint64_t seed);

/// The bridge outputs (N × rows, mV/V, noise-free) with the set-up's effects, as MakeRecording
/// composes its real recording (saturation limits defaulted from the model's prediction).
[[nodiscard]] Eigen::MatrixXd ComposeWithEffects(ComposeSetup* setup);

/// Saturation effects without a limit get 0.9 × the 99.5th percentile of |output| of their
/// channels in `sim`, the effect-free prediction (N × samples), so the largest loads clip.
void DefaultSaturationLimits(const Eigen::MatrixXd& sim, std::vector<Effect>* effects);

/// Parses several --effect arguments (see ParseEffectSpec).
[[nodiscard]] std::vector<EffectSpec> ParseEffects(const std::vector<std::string>& texts);

/// Writes the truth JSON (pretty-printed); throws std::runtime_error if it cannot.
void WriteTruth(const std::string& path, const nlohmann::json& truth);

}  // namespace ftstack::sim
