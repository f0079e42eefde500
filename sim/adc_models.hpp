// Bridge read-out converters (HX711, ADS131M0x): datasheet noise and ranges → simulated-ADC params.
#pragma once

#include <cstdint>
#include <string>

#include "hal/sim/sim_adc.hpp"

namespace ftstack::sim {

/// Which converter a sensor is read by.
enum class AdcChip : std::uint8_t {
  kGeneric,    ///< the caller's own resolution, reference ratio and noise (no datasheet model)
  kHx711,      ///< Avia HX711: 24 bit, gain 128/64 (channel A) or 32 (B), 10 or 80 SPS
  kAds131m0x,  ///< TI ADS131M02/03/04/06/08: simultaneous sampling, 24 bit, gain 1…128
};

/// The converter as configured in a sensor: chip, PGA gain, output data rate and the bridge
/// excitation (the converter's reference is the excitation for the HX711 — ratiometric — and the
/// internal 1.2 V reference for the ADS131M0x).
struct AdcSpec {
  AdcChip chip = AdcChip::kAds131m0x;
  std::uint16_t gain = 128;
  std::uint32_t rate_hz = 1000;
  double excitation_v = 3.3;       ///< bridge excitation, V (HX711: AVDD)
  double reference_v = 1.2;        ///< ADS131M0x reference (internal 1.2 V)
  bool global_chop = false;        ///< ADS131M0x global-chop mode: noise / √2
  hal::sim::SimAdcParams generic;  ///< kGeneric only: taken as given
};

/// A converter at one operating point, ready for hal::sim::SimAdc.
struct AdcOperatingPoint {
  hal::sim::SimAdcParams params;  ///< noise in mV/V, reference ratio, required gain and rate
  double noise_uv_rms = 0;        ///< input-referred noise, µV RMS (datasheet figure)
  double full_scale_mvv = 0;      ///< input span ±full_scale_mvv, mV/V
};

/// Input-referred noise of the HX711, µV RMS: 0.050 at 10 SPS and 0.090 at 80 SPS at gain 128
/// (datasheet, "Input noise"). The datasheet gives no figure at gain 64 or 32; this model keeps the
/// output-referred noise, i.e. scales the input-referred figure by 128/gain (an assumption).
/// Throws std::invalid_argument for a gain other than 128/64/32 or a rate other than 10/80 Hz.
[[nodiscard]] double Hx711NoiseUv(std::uint16_t gain, std::uint32_t rate_hz);

/// Input-referred noise of the ADS131M0x, µV RMS, from the datasheet's noise table (fCLKIN =
/// 8.192 MHz, internal reference, global chop off) for gains 1, 2, 4, 8 and 128 at the data rates
/// 250 … 64 000 SPS; between tabulated rates the noise is interpolated in log–log (a rate set by
/// another clock frequency). Throws std::invalid_argument for other gains or rates outside the
/// table.
[[nodiscard]] double Ads131m0xNoiseUv(std::uint16_t gain, double rate_hz);

/// The operating point of `spec`: quantisation (24 bit), input span, noise in mV/V of the
/// excitation and the required gain/rate. Throws std::invalid_argument naming the bad setting.
[[nodiscard]] AdcOperatingPoint MakeAdcOperatingPoint(const AdcSpec& spec);

/// "generic", "hx711" or "ads131m0x".
[[nodiscard]] std::string ToString(AdcChip chip);

}  // namespace ftstack::sim
