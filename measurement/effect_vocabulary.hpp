// The effect vocabulary shared by injector, diagnosis and scorecard (docs/spec/diagnosis.md).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace ftstack {

/// The effects of the vocabulary, in its order (docs/spec/diagnosis.md; names are exact).
enum class EffectKind {
  kNone,
  kZeroOffset,
  kZeroDrift,
  kThermalZeroDrift,
  kThermalSpanDrift,
  kExcitationDrift,
  kCreep,
  kHysteresis,
  kBridgeNonlinearity,
  kGeometricNonlinearity,
  kLoadStiffening,
  kMisalignment,
  kGainError,
  kTimeSkew,
  kSaturation,
  kOverloadShift,
  kMainsInterference,
  kResonance,
  kConverterGlitch,
};

/// How a parameter's value is written in `--effect NAME:key=value`.
enum class ParamType {
  kNumber,    ///< one finite number
  kList,      ///< one number, or a list `[a,b,c]` / `a/b/c` (one per channel)
  kChannels,  ///< 0-based bridge indices (`[0,3]`, `0/3`) or `all`
  kRotAxis,   ///< x, y or z
  kLoadAxis,  ///< Fx, Fy, Fz, Mx, My or Mz
};

/// Who uses a parameter (bit set): the injector accepts it (`ftsim record --effect`), the
/// diagnosis report must carry it (`effects[].params`, docs/spec/diagnosis.md).
enum ParamRole : unsigned {
  kInjected = 1U,
  kReported = 2U,
  kBoth = 3U,
  /// A figure the report may carry beside the required ones (a variant's or a derived value):
  /// listed for its unit and meaning, which the report writers take from here.
  kDescribed = 4U,
};

/// One parameter of an effect.
struct EffectParam {
  std::string_view key;      ///< canonical key (carries its unit where it has one)
  ParamType type;            ///< how the injector reads it
  std::string_view unit;     ///< "" for dimensionless
  std::string_view meaning;  ///< one phrase
  unsigned roles;            ///< ParamRole bits
  std::string_view alias;    ///< an older injector key still accepted ("" if none)
};

/// One effect: its name (exact), kind and parameters.
struct EffectDef {
  std::string_view name;
  EffectKind kind;
  std::span<const EffectParam> params;
};

namespace vocabulary_detail {
using P = EffectParam;
using T = ParamType;
inline constexpr P kChannels = {
    "channels", T::kChannels, "", "bridges affected (0-based or all)", kInjected, ""};
inline constexpr std::array<P, 0> kNone{};
inline constexpr std::array kZeroOffset = {
    P{"offset", T::kList, "mV/V", "constant bridge offset, per channel", kBoth, ""}, kChannels};
inline constexpr std::array kZeroDrift = {
    P{"amplitude_mvv", T::kNumber, "mV/V", "RMS of the slow wander over the record", kInjected,
      "amplitude"},
    P{"corner_hz", T::kNumber, "Hz", "highest frequency of the wander", kInjected, ""},
    P{"span_mvv", T::kNumber, "mV/V", "range of the fitted wander, per channel", kDescribed, ""},
    P{"level_from_s", T::kList, "s", "start of every fitted level (stepped variant)", kReported,
      ""},
    P{"levels_mvv", T::kList, "mV/V", "every fitted level, per channel (stepped variant)",
      kReported, ""},
    P{"levels", T::kNumber, "", "how many levels the stepped variant fitted", kDescribed, ""},
    P{"knots", T::kNumber, "", "knots of the fitted wander's spline", kDescribed, ""},
    kChannels};
inline constexpr std::array kThermalZeroDrift = {
    P{"coef_per_K", T::kList, "mV/V/K", "offset per kelvin, per channel", kBoth, ""},
    P{"t0_c", T::kNumber, "°C", "temperature of zero offset", kInjected, ""},
    P{"lag_s", T::kNumber, "s", "lag of the bridge's temperature behind the recorded one",
      kDescribed, ""},
    kChannels};
inline constexpr std::array kThermalSpanDrift = {
    P{"coef_per_K", T::kNumber, "1/K", "relative sensitivity change per kelvin", kBoth, ""},
    P{"t0_c", T::kNumber, "°C", "temperature of nominal sensitivity", kInjected, ""},
    P{"ref_temp_C", T::kNumber, "°C", "fitted temperature of nominal sensitivity", kDescribed, ""},
    P{"coef_per_K_by_channel", T::kList, "1/K",
      "relative sensitivity change per kelvin, per channel", kDescribed, ""},
    kChannels};
inline constexpr std::array kExcitationDrift = {
    P{"amplitude", T::kNumber, "", "RMS of the common relative sensitivity wander", kInjected, ""},
    P{"corner_hz", T::kNumber, "Hz", "highest frequency of the wander", kInjected, ""},
    P{"factor_min", T::kNumber, "", "least fitted sensitivity factor over the record", kDescribed,
      ""},
    P{"factor_max", T::kNumber, "", "largest fitted sensitivity factor over the record", kDescribed,
      ""},
    P{"knots", T::kNumber, "", "knots of the fitted wander's spline", kDescribed, ""}};
inline constexpr std::array kCreep = {
    P{"tau_s", T::kNumber, "s", "first-order creep time constant", kBoth, ""},
    P{"fraction", T::kNumber, "", "share of a load change that creeps in (report: per channel)",
      kBoth, ""},
    P{"tau1_s", T::kNumber, "s", "shorter time constant (two-time-constant variant)", kReported,
      ""},
    P{"tau2_s", T::kNumber, "s", "longer time constant (two-time-constant variant)", kReported, ""},
    P{"fraction1", T::kNumber, "", "share creeping in with tau1_s, per channel", kReported, ""},
    P{"fraction2", T::kNumber, "", "share creeping in with tau2_s, per channel", kReported, ""},
    kChannels};
inline constexpr std::array kHysteresis = {
    P{"amplitude", T::kNumber, "", "loop size as a fraction of rated load", kInjected, ""},
    P{"width", T::kNumber, "", "widest play threshold as a fraction of rated load", kInjected, ""},
    P{"travel_fraction", T::kNumber, "", "loop width as a fraction of the load's travel",
      kDescribed, ""},
    P{"half_width_mvv", T::kList, "mV/V", "loop half width, per channel", kDescribed, ""},
    P{"loop_half_height_mvv", T::kList, "mV/V", "loop half height, per channel", kDescribed, ""},
    P{"relay_levels", T::kNumber, "", "load levels of the relay grid", kDescribed, ""},
    P{"loop_half_height", T::kList, "N or N·m",
      "loop half height in the load's units, per wrench axis (load-path variant)", kDescribed, ""}};
inline constexpr std::array kBridgeNonlinearity = {
    P{"channels", T::kChannels, "", "bridges with a quadratic term", kBoth, ""},
    P{"coef", T::kNumber, "1/(mV/V)", "quadratic coefficient: b += coef·b²", kInjected, ""},
    P{"quadratic_per_mvv", T::kList, "1/(mV/V)", "fitted quadratic coefficient, per channel",
      kDescribed, ""}};
inline constexpr std::array kGeometricNonlinearity = {
    P{"coef", T::kNumber, "", "cubic term at rated load", kInjected, ""},
    P{"cubic_per_mvv2", T::kList, "1/(mV/V)²", "fitted cubic coefficient, per channel", kDescribed,
      ""},
    P{"relative_at_peak", T::kList, "", "cubic term relative to the output at the peak load",
      kDescribed, ""}};
inline constexpr std::array kLoadStiffening = {
    P{"coef", T::kNumber, "", "relative bending/shear sensitivity change at rated Fz", kInjected,
      ""},
    P{"fz_peak_n", T::kNumber, "N", "largest |Fz| of the record", kDescribed, ""},
    P{"kappa_at_peak_Fz", T::kList, "", "relative sensitivity change at the peak Fz, per channel",
      kDescribed, ""},
    P{"terms", T::kNumber, "", "the load products fitted (a label)", kDescribed, ""}};
inline constexpr std::array kMisalignment = {
    P{"axis", T::kRotAxis, "", "rotation axis (x, y, z)", kBoth, ""},
    P{"angle_deg", T::kNumber, "deg", "rotation of the sensor frame", kBoth, ""}};
inline constexpr std::array kGainError = {
    P{"channels", T::kChannels, "", "bridges whose gain is off", kBoth, ""},
    P{"gain", T::kNumber, "", "real/sim sensitivity ratio", kBoth, ""}};
inline constexpr std::array kTimeSkew = {
    P{"delay_s", T::kNumber, "s", "delay of the recording (>0: real lags)", kBoth, ""}};
inline constexpr std::array kSaturation = {
    P{"limit", T::kNumber, "mV/V", "clipping level", kBoth, ""},
    P{"limit_high", T::kNumber, "mV/V", "upper clipping level", kDescribed, ""},
    P{"limit_low", T::kNumber, "mV/V", "lower clipping level", kDescribed, ""}, kChannels};
inline constexpr std::array kOverloadShift = {
    P{"onset_s", T::kNumber, "s", "time of the overload and the shift", kBoth, ""},
    P{"shift", T::kNumber, "mV/V", "zero shift on the most sensitive channel", kInjected, ""},
    P{"axis", T::kLoadAxis, "", "overloaded wrench axis (Fx…Mz)", kInjected, ""},
    P{"factor", T::kNumber, "", "overload as a multiple of rated load", kInjected, ""},
    P{"recovery_tau_s", T::kNumber, "s",
      "time constant of the part of the shift that recovers (partly recovering variant)", kReported,
      ""},
    P{"recovering_shift", T::kNumber, "mV/V",
      "part of the shift that recovers, per channel (partly recovering variant)", kReported, ""}};
inline constexpr std::array kMainsInterference = {
    P{"freq_hz", T::kNumber, "Hz", "pick-up frequency", kBoth, ""},
    P{"amplitude_mvv", T::kNumber, "mV/V", "peak amplitude (report: per channel)", kBoth,
      "amplitude"},
    P{"phase_deg", T::kNumber, "deg", "phase at t = 0", kInjected, ""},
    P{"h2_amplitude_mvv", T::kList, "mV/V", "harmonic 2's peak amplitude, per channel", kDescribed,
      ""},
    P{"h2_seen_at_hz", T::kNumber, "Hz", "where harmonic 2 was found", kDescribed, ""},
    P{"h3_amplitude_mvv", T::kList, "mV/V", "harmonic 3's peak amplitude, per channel", kDescribed,
      ""},
    P{"h3_seen_at_hz", T::kNumber, "Hz", "where harmonic 3 was found", kDescribed, ""},
    P{"h4_amplitude_mvv", T::kList, "mV/V", "harmonic 4's peak amplitude, per channel", kDescribed,
      ""},
    P{"h4_seen_at_hz", T::kNumber, "Hz", "where harmonic 4 was found", kDescribed, ""},
    P{"h5_amplitude_mvv", T::kList, "mV/V", "harmonic 5's peak amplitude, per channel", kDescribed,
      ""},
    P{"h5_seen_at_hz", T::kNumber, "Hz", "where harmonic 5 was found", kDescribed, ""},
    P{"seen_at_hz", T::kNumber, "Hz", "where a fundamental above Nyquist was found (its alias)",
      kDescribed, ""},
    P{"even_harmonic_energy_fraction", T::kNumber, "",
      "the series' energy in its even harmonics (large: a rectified or switched supply)",
      kDescribed, ""},
    P{"dominant_harmonic", T::kNumber, "",
      "the order that carries most of the series' energy (1: the fundamental)", kDescribed, ""},
    kChannels};
inline constexpr std::array kResonance = {
    P{"freq_hz", T::kNumber, "Hz", "undamped natural frequency", kBoth, ""},
    P{"damping_ratio", T::kNumber, "", "damping ratio ζ", kBoth, ""},
    P{"participation", T::kNumber, "", "the mode's share of the output (report: per channel)",
      kBoth, ""},
    P{"freq2_hz", T::kNumber, "Hz", "undamped natural frequency of mode 2 (two-mode variant)",
      kReported, ""},
    P{"damping_ratio2", T::kNumber, "", "damping ratio of mode 2 (two-mode variant)", kReported,
      ""},
    P{"participation2", T::kNumber, "",
      "mode 2's share of the output, per channel (two-mode variant)", kReported, ""},
    P{"damped_freq_hz", T::kNumber, "Hz", "damped frequency the record rings at", kDescribed, ""},
    P{"load_changes", T::kNumber, "", "load changes the ringing restarts at (per-change variant)",
      kDescribed, ""},
    kChannels};
inline constexpr std::array kConverterGlitch = {
    P{"count", T::kNumber, "", "isolated wrong codes (report: how many were found)", kBoth, ""},
    P{"offset_mvv", T::kNumber, "mV/V", "each wrong code's distance from the true value", kInjected,
      ""},
    P{"times_s", T::kList, "s", "time of every wrong code found", kReported, ""}, kChannels};
}  // namespace vocabulary_detail

/// The vocabulary, in EffectKind order.
inline constexpr std::array<EffectDef, 19> kEffectVocabulary = {{
    {"none", EffectKind::kNone, vocabulary_detail::kNone},
    {"zero_offset", EffectKind::kZeroOffset, vocabulary_detail::kZeroOffset},
    {"zero_drift", EffectKind::kZeroDrift, vocabulary_detail::kZeroDrift},
    {"thermal_zero_drift", EffectKind::kThermalZeroDrift, vocabulary_detail::kThermalZeroDrift},
    {"thermal_span_drift", EffectKind::kThermalSpanDrift, vocabulary_detail::kThermalSpanDrift},
    {"excitation_drift", EffectKind::kExcitationDrift, vocabulary_detail::kExcitationDrift},
    {"creep", EffectKind::kCreep, vocabulary_detail::kCreep},
    {"hysteresis", EffectKind::kHysteresis, vocabulary_detail::kHysteresis},
    {"bridge_nonlinearity", EffectKind::kBridgeNonlinearity,
     vocabulary_detail::kBridgeNonlinearity},
    {"geometric_nonlinearity", EffectKind::kGeometricNonlinearity,
     vocabulary_detail::kGeometricNonlinearity},
    {"load_stiffening", EffectKind::kLoadStiffening, vocabulary_detail::kLoadStiffening},
    {"misalignment", EffectKind::kMisalignment, vocabulary_detail::kMisalignment},
    {"gain_error", EffectKind::kGainError, vocabulary_detail::kGainError},
    {"time_skew", EffectKind::kTimeSkew, vocabulary_detail::kTimeSkew},
    {"saturation", EffectKind::kSaturation, vocabulary_detail::kSaturation},
    {"overload_shift", EffectKind::kOverloadShift, vocabulary_detail::kOverloadShift},
    {"mains_interference", EffectKind::kMainsInterference, vocabulary_detail::kMainsInterference},
    {"resonance", EffectKind::kResonance, vocabulary_detail::kResonance},
    {"converter_glitch", EffectKind::kConverterGlitch, vocabulary_detail::kConverterGlitch},
}};

/// The entry of `kind` (the table is in kind order; checked at compile time in the source).
[[nodiscard]] constexpr const EffectDef& EffectOf(EffectKind kind) {
  return kEffectVocabulary[static_cast<std::size_t>(kind)];
}

/// The effect named `name` (exact), nullptr if the vocabulary has none.
[[nodiscard]] const EffectDef* FindEffect(std::string_view name);

/// The parameter of `def` whose key — or, with `accept_alias`, whose alias — is `key`.
[[nodiscard]] const EffectParam* FindParam(const EffectDef& def, std::string_view key,
                                           bool accept_alias = true);

/// The canonical key `key` of `kind`, checked against the vocabulary: throws std::logic_error when
/// the effect has no parameter `key` with every role in `roles` (so a renamed key fails loudly).
[[nodiscard]] std::string_view ParamKey(EffectKind kind, std::string_view key, unsigned roles);

/// "k1, k2 (alias a2), …": the keys of `def` that have a role in `roles`; "none" if there are none.
[[nodiscard]] std::string ValidKeys(const EffectDef& def, unsigned roles = kInjected);

/// "none, zero_offset, …": every effect name in vocabulary order.
[[nodiscard]] std::string EffectNameList();

}  // namespace ftstack
