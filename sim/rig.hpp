// Load-set design for a calibration rig and its simulation (sim sensor → simulated ADC → rows).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "measurement/recording.hpp"
#include "sim/sensor_description.hpp"
#include "sim/wrench_source.hpp"

namespace ftstack::sim {

/// What the proposed rig sequence contains.
struct RigDesignOptions {
  /// Single-axis levels as fractions of rated, swept up then down on each sign.
  std::vector<double> levels = {0.25, 0.5, 0.75, 1.0};
  bool combined = true;  ///< axial preload × moments, lever loads (F × r), shear × torsion
  int random_combinations = 24;  ///< extra mixed loads within ±60 % of rated (fixed seed)
  double hold_s = 0.5;           ///< static hold per load, s
  double ramp_s = 0.2;           ///< transition between holds, s
  /// Body temperatures (°C) to repeat the sequence at; empty → one pass at 20 °C. Later passes
  /// use the combined and random loads plus the full-scale single-axis ones.
  std::vector<double> temperatures_c;
  std::uint64_t seed = 7;
};

/// One static load of the sequence.
struct RigStep {
  Wrench wrench = Wrench::Zero();  ///< N, N·m
  double temperature_c = 20.0;
  std::string label;  ///< e.g. "+Fz 50% up", "Fz 50% x Mx -50%"
};

/// Proposes a rig sequence for a sensor of rated range `rated` (N, N·m).
[[nodiscard]] std::vector<RigStep> DesignRig(const Wrench& rated, const RigDesignOptions& options);

/// The loads of the sequence, in order (for cal::LoadSetCondition).
[[nodiscard]] std::vector<Wrench> RigLoads(const std::vector<RigStep>& steps);

/// Keyframes of the sequence: each step held hold_s after a ramp_s transition.
[[nodiscard]] std::vector<ProfileWrench::Key> RigKeys(const std::vector<RigStep>& steps,
                                                      const RigDesignOptions& options);

/// One line per step (index, label, wrench, temperature), as `ftcal design` prints it.
[[nodiscard]] std::string RigStepTable(const std::vector<RigStep>& steps);

/// The keyframes as a profile recording: t, Fx…Mz, temp_C (what `ftsim record --profile` reads).
[[nodiscard]] Recording RigProfileRecording(const std::vector<ProfileWrench::Key>& keys);

/// Runs the keyframes through the sensor: SimulatedSensor → hal::sim::SimAdc (its noise,
/// resolution and seed) → counts → mV/V. Columns t, Fx…Mz (the applied reference), b0…, temp_C,
/// and `pose` (index of the step being held or approached) when `with_pose`.
[[nodiscard]] Recording SimulateRig(const SensorDescription& sensor,
                                    const std::vector<ProfileWrench::Key>& keys, double rate_hz,
                                    std::uint64_t seed, bool with_pose = false);

}  // namespace ftstack::sim
