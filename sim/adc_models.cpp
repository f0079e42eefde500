#include "sim/adc_models.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

namespace ftstack::sim {
namespace {

// ADS131M04 datasheet (SBAS / Q1 variant), Table 7-1 "Noise (µVRMS) at TA = 25 °C", internal
// 1.2 V reference, fCLKIN = 8.192 MHz: rows OSR 16384 … 64, i.e. 0.25 … 64 kSPS.
constexpr std::array<double, 9> kAdsRateHz = {250,  500,   1000,  2000, 4000,
                                              8000, 16000, 32000, 64000};
struct AdsColumn {
  std::uint16_t gain;
  std::array<double, 9> noise_uv;
};
constexpr std::array<AdsColumn, 5> kAdsNoise = {{
    {1, {1.90, 2.39, 3.38, 4.25, 5.35, 7.56, 10.68, 21.31, 75.34}},
    {2, {1.69, 2.13, 2.99, 3.91, 4.68, 6.62, 9.56, 15.26, 41.63}},
    {4, {1.56, 2.13, 2.88, 3.79, 4.52, 6.37, 9.09, 13.52, 26.84}},
    {8, {0.95, 1.29, 1.74, 2.27, 2.70, 3.82, 5.42, 7.89, 14.59}},
    {128, {0.42, 0.57, 0.77, 1.00, 1.20, 1.69, 2.40, 3.42, 5.58}},
}};

void RequirePositive(double v, const char* what) {
  if (!std::isfinite(v) || v <= 0) {
    throw std::invalid_argument(std::string("ADC: ") + what + " must be finite and > 0");
  }
}

}  // namespace

double Hx711NoiseUv(std::uint16_t gain, std::uint32_t rate_hz) {
  if (gain != 128 && gain != 64 && gain != 32) {
    throw std::invalid_argument(
        "HX711: gain must be 128 or 64 (channel A) or 32 (channel B), not " + std::to_string(gain));
  }
  if (rate_hz != 10 && rate_hz != 80) {
    throw std::invalid_argument("HX711: the RATE pin selects 10 or 80 SPS, not " +
                                std::to_string(rate_hz));
  }
  const double at128 = rate_hz == 10 ? 0.050 : 0.090;
  return at128 * 128.0 / gain;
}

double Ads131m0xNoiseUv(std::uint16_t gain, double rate_hz) {
  const AdsColumn* col = nullptr;
  for (const auto& c : kAdsNoise) {
    if (c.gain == gain) col = &c;
  }
  if (col == nullptr) {
    throw std::invalid_argument(
        "ADS131M0x: this model has datasheet noise for gains 1, 2, 4, 8 "
        "and 128 only, not " +
        std::to_string(gain));
  }
  if (!std::isfinite(rate_hz) || rate_hz < kAdsRateHz.front() || rate_hz > kAdsRateHz.back()) {
    throw std::invalid_argument("ADS131M0x: data rate must lie in 250 … 64000 SPS");
  }
  for (std::size_t i = 0; i + 1 < kAdsRateHz.size(); ++i) {
    if (rate_hz <= kAdsRateHz[i + 1]) {
      const double f =
          std::log(rate_hz / kAdsRateHz[i]) / std::log(kAdsRateHz[i + 1] / kAdsRateHz[i]);
      return std::exp(std::log(col->noise_uv[i]) +
                      f * (std::log(col->noise_uv[i + 1]) - std::log(col->noise_uv[i])));
    }
  }
  return col->noise_uv.back();
}

AdcOperatingPoint MakeAdcOperatingPoint(const AdcSpec& spec) {
  AdcOperatingPoint op;
  if (spec.chip == AdcChip::kGeneric) {
    op.params = spec.generic;
    op.full_scale_mvv = 1000.0 * op.params.reference_ratio / spec.gain;
    op.noise_uv_rms = op.params.noise_rms_mvv * spec.excitation_v * 1e3;
    return op;
  }
  RequirePositive(spec.excitation_v, "excitation_v");
  op.params.resolution_bits = 24;
  op.params.required_gain = spec.gain;
  op.params.required_rate_hz = spec.rate_hz;
  if (spec.chip == AdcChip::kHx711) {
    op.noise_uv_rms = Hx711NoiseUv(spec.gain, spec.rate_hz);
    op.params.reference_ratio = 0.5;  // input span ±0.5·AVDD/gain, bridge excited from AVDD
  } else {
    RequirePositive(spec.reference_v, "reference_v");
    op.noise_uv_rms = Ads131m0xNoiseUv(spec.gain, spec.rate_hz);
    if (spec.global_chop) op.noise_uv_rms /= std::sqrt(2.0);
    op.params.reference_ratio = spec.reference_v / spec.excitation_v;  // span ±Vref/gain
  }
  op.params.noise_rms_mvv = op.noise_uv_rms * 1e-3 / spec.excitation_v;
  op.full_scale_mvv = 1000.0 * op.params.reference_ratio / spec.gain;
  return op;
}

std::string ToString(AdcChip chip) {
  switch (chip) {
    case AdcChip::kGeneric:
      return "generic";
    case AdcChip::kHx711:
      return "hx711";
    case AdcChip::kAds131m0x:
      return "ads131m0x";
  }
  return "unknown";
}

}  // namespace ftstack::sim
