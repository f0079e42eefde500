#include "firmware/gravity_comp.hpp"

#include <cmath>
#include <limits>

#include "firmware/fixed_point.hpp"

namespace ftstack::fw {
namespace {

/// 1e-15 N per mN and 1e-15 N·m per 10 µN·m: the divisors from the products to output LSB.
constexpr std::int64_t kFemtoPerForceLsb = 1'000'000'000'000;
constexpr std::int64_t kFemtoPerMomentLsb = 10'000'000'000;

bool ToLsb(double v, double lsb, std::int32_t* out) {
  const double x = std::round(v / lsb);
  if (!(std::fabs(x) <= static_cast<double>(std::numeric_limits<std::int32_t>::max()))) {
    return false;
  }
  *out = static_cast<std::int32_t>(x);
  return true;
}

}  // namespace

PayloadStatus MakeFixedPayload(double mass_kg, const std::array<double, 3>& com_m,
                               const std::array<double, 3>& force_bias_n,
                               const std::array<double, 3>& moment_bias_nm, FixedPayload* out) {
  bool finite = std::isfinite(mass_kg);
  for (std::size_t i = 0; i < 3; ++i) {
    finite = finite && std::isfinite(com_m[i]) && std::isfinite(force_bias_n[i]) &&
             std::isfinite(moment_bias_nm[i]);
  }
  if (!finite) return PayloadStatus::kNotFinite;
  if (!(mass_kg > 0) || mass_kg > kMaxPayloadMassKg) return PayloadStatus::kOutOfRange;
  FixedPayload p{};
  p.mass_ug = std::llround(mass_kg * 1e9);
  for (std::size_t i = 0; i < 3; ++i) {
    const double first_moment = mass_kg * com_m[i];
    if (std::fabs(first_moment) > kMaxPayloadFirstMomentKgM) return PayloadStatus::kOutOfRange;
    p.first_moment_ug_m[i] = std::llround(first_moment * 1e9);
    if (!ToLsb(force_bias_n[i], kForceLsbN, &p.bias_lsb[i]) ||
        !ToLsb(moment_bias_nm[i], kMomentLsbNm, &p.bias_lsb[3 + i])) {
      return PayloadStatus::kOutOfRange;
    }
  }
  p.present = true;
  *out = p;
  return PayloadStatus::kOk;
}

bool GravityToFixed(float g_mps2, std::int32_t* out_umps2) {
  if (!std::isfinite(g_mps2) || std::fabs(g_mps2) > static_cast<float>(kMaxGravityMps2)) {
    return false;
  }
  *out_umps2 = static_cast<std::int32_t>(std::llround(static_cast<double>(g_mps2) * 1e6));
  return true;
}

void CompensateGravity(const FixedPayload& p, const std::array<std::int32_t, 3>& g,
                       const WrenchLsb& in, WrenchLsb* out, bool* saturated) {
  const std::array<std::int64_t, 3>& c = p.first_moment_ug_m;
  const std::int64_t gx = g[0], gy = g[1], gz = g[2];
  // (m·c) × g, 1e-15 N·m; each product ≤ 2e18 and each difference ≤ 4e18 (see the header).
  const std::array<std::int64_t, 3> moment = {c[1] * gz - c[2] * gy, c[2] * gx - c[0] * gz,
                                              c[0] * gy - c[1] * gx};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::int64_t weight = RoundDiv(p.mass_ug * g[i], kFemtoPerForceLsb);
    const std::int64_t f = static_cast<std::int64_t>(in[i]) - weight - p.bias_lsb[i];
    const std::int64_t m = static_cast<std::int64_t>(in[3 + i]) -
                           RoundDiv(moment[i], kFemtoPerMomentLsb) - p.bias_lsb[3 + i];
    (*out)[i] = SatToI32(f, saturated);
    (*out)[3 + i] = SatToI32(m, saturated);
  }
}

}  // namespace ftstack::fw
