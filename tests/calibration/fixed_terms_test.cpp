// Property tests: the fixed-point core with second-order and temperature terms against the
// double-precision evaluation of the same calibration, within the loader's proven bound.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "calibration/file/cal_file.hpp"
#include "calibration/fit/model.hpp"
#include "firmware/core.hpp"
#include "firmware/fixed_calibration.hpp"

namespace ftstack {
namespace {

constexpr std::array<double, 6> kRated = {200, 200, 400, 10, 10, 8};

struct Case {
  fw::FloatCalibration cal;
  hal::AdcInfo adc;
};

/// A random calibration shaped like a real one: about rated output at 0.6 mV/V per bridge,
/// second-order terms worth ~1 % of rated at that level, drift of ~0.03 %/°C.
Case RandomCase(std::mt19937_64& rng, bool products, bool temperature, int channels = 0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> nch(1, 8);
  Case c;
  const int n = channels > 0 ? channels : nch(rng);
  c.adc = cal::DefaultAdc(static_cast<std::uint8_t>(n));
  c.cal.channel_count = static_cast<std::uint8_t>(n);
  for (std::size_t r = 0; r < 6; ++r) {
    for (int ch = 0; ch < n; ++ch) {
      c.cal.matrix[r][static_cast<std::size_t>(ch)] = u(rng) * kRated[r] / 0.6;
    }
    c.cal.bias[r] = u(rng) * 0.01 * kRated[r];
  }
  for (int ch = 0; ch < n; ++ch) c.cal.offset_mvv[static_cast<std::size_t>(ch)] = 0.5 * u(rng);
  if (products) {
    std::size_t k = 0;
    for (int a = 0; a < n; ++a) {
      for (int b = a; b < n; ++b) {
        c.cal.products[k] = {static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b)};
        for (std::size_t r = 0; r < 6; ++r)
          c.cal.product_matrix[r][k] = u(rng) * 0.01 * kRated[r] / 0.36;
        ++k;
      }
    }
    c.cal.product_count = static_cast<std::uint8_t>(k);
  }
  if (temperature) {
    c.cal.temperature_compensated = true;
    c.cal.temp_ref_c = 20.0 + 5.0 * u(rng) + 0.0004;  // deliberately not on the m°C grid
    c.cal.temp_min_c = -10.0;
    c.cal.temp_max_c = 60.0;
    for (int ch = 0; ch < n; ++ch) {
      c.cal.bias_slope_mvv_per_c[static_cast<std::size_t>(ch)] = 3e-4 * u(rng);
      c.cal.gain_slope_per_c[static_cast<std::size_t>(ch)] = 3e-4 * u(rng);
    }
  }
  return c;
}

/// Random counts between the rails; one in eight samples pinned at a rail per channel.
std::array<std::int32_t, hal::kMaxChannels> RandomCounts(std::mt19937_64& rng,
                                                         const hal::AdcInfo& adc) {
  std::uniform_int_distribution<std::int32_t> u(adc.min_counts, adc.max_counts);
  std::uniform_int_distribution<int> pick(0, 7);
  std::array<std::int32_t, hal::kMaxChannels> x{};
  for (auto& v : x) {
    const int p = pick(rng);
    v = p == 0 ? adc.max_counts : p == 1 ? adc.min_counts : u(rng);
  }
  return x;
}

std::array<double, 6> Reference(const Case& c, const std::array<std::int32_t, hal::kMaxChannels>& x,
                                std::int32_t mdegc) {
  const double cpm = fw::CountsPerMvv(c.adc);
  std::array<double, hal::kMaxChannels> mvv{};
  for (std::size_t i = 0; i < hal::kMaxChannels; ++i) mvv[i] = x[i] / cpm;
  std::array<double, 6> y = cal::EvaluateCalibration(c.cal, mvv.data(), mdegc / 1000.0);
  for (std::size_t r = 0; r < 6; ++r) y[r] /= fw::AxisLsb(r);
  return y;
}

/// Applies `core` to `samples` random inputs and checks each axis against `ref` − `offset`
/// within the loader's bound.
template <typename TempGen>
void ExpectWithinBound(const Case& c, const fw::WrenchCore& core, const fw::LoadReport& rep,
                       std::mt19937_64& rng, int samples, TempGen temp,
                       const std::array<double, 6>& offset, double* worst_seen) {
  for (int s = 0; s < samples; ++s) {
    const auto x = RandomCounts(rng, c.adc);
    const std::int32_t t = temp(s);
    fw::WrenchLsb y{};
    bool sat = false;
    bool range = false;
    core.Apply(x, t, true, y, &sat, &range);
    ASSERT_FALSE(sat);
    if (c.cal.temperature_compensated) {
      EXPECT_EQ(range, t < std::lround(c.cal.temp_min_c * 1000) ||
                           t > std::lround(c.cal.temp_max_c * 1000));
    }
    const auto ref = Reference(c, x, t);
    for (std::size_t r = 0; r < 6; ++r) {
      const double err = std::fabs(y[r] - (ref[r] - offset[r]));
      if (worst_seen != nullptr) *worst_seen = std::max(*worst_seen, err);
      ASSERT_LE(err, rep.worst_case_error_lsb[r]) << "sample " << s << " axis " << r;
    }
  }
}

void CheckCases(bool products, bool temperature, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int32_t> temp(-30000, 90000);  // beyond the range too
  double worst_seen = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Case c = RandomCase(rng, products, temperature);
    fw::FixedCalibration fixed{};
    fw::LoadReport rep{};
    ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, &rep), fw::LoadStatus::kOk);
    fw::WrenchCore core;
    core.SetCalibration(fixed);
    for (std::size_t r = 0; r < 6; ++r) {
      // Realistic calibrations keep the core's contract: within 1 LSB of exact.
      ASSERT_LE(rep.worst_case_error_lsb[r], 1.0) << "trial " << trial << " axis " << r;
    }
    ExpectWithinBound(
        c, core, rep, rng, 200, [&](int) { return temp(rng); }, {}, &worst_seen);
  }
  std::printf("largest |fixed - double| seen: %.3f LSB\n", worst_seen);
}

TEST(FixedTerms, LinearWithinOneLsb) { CheckCases(false, false, 1); }
TEST(FixedTerms, SecondOrderWithinProvenBound) { CheckCases(true, false, 2); }
TEST(FixedTerms, TemperatureWithinProvenBound) { CheckCases(false, true, 3); }
TEST(FixedTerms, SecondOrderAndTemperatureWithinProvenBound) { CheckCases(true, true, 4); }

TEST(FixedTerms, TareMakesEveryFeatureRelativeToTheTarePoint) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::int32_t> temp(-5000, 50000);
  for (int trial = 0; trial < 100; ++trial) {
    const Case c = RandomCase(rng, true, true);
    fw::FixedCalibration fixed{};
    fw::LoadReport rep{};
    ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, &rep), fw::LoadStatus::kOk);
    fw::WrenchCore core;
    core.SetLimits(fw::CoreLimits{0, 0});
    core.SetCalibration(fixed);
    // Keep the tare sample away from the rails (a saturated sample is not usable for a tare).
    auto tare_x = RandomCounts(rng, c.adc);
    for (auto& v : tare_x) v /= 2;
    hal::AdcSample s{};
    s.channel_count = c.cal.channel_count;
    s.counts = tare_x;
    s.has_temperature = true;
    s.temperature_mdegc = temp(rng);
    ASSERT_TRUE(core.RequestTare(1));
    fw::CoreOutput out{};
    core.Process(s, false, out);
    ASSERT_TRUE(core.tare_active());
    const auto ref_tare = Reference(c, tare_x, s.temperature_mdegc);
    ExpectWithinBound(
        c, core, rep, rng, 50, [&](int) { return temp(rng); }, ref_tare, nullptr);
  }
}

TEST(FixedTerms, LoaderRefusesWhatCouldOverflowAndAcceptsUpToTheEdge) {
  std::mt19937_64 rng(6);
  for (int trial = 0; trial < 40; ++trial) {
    const Case base = RandomCase(rng, true, true);
    // Scale every coefficient by m; find the largest accepted m by bisection.
    auto scaled = [&](double m) {
      Case c = base;
      for (std::size_t r = 0; r < 6; ++r) {
        for (auto& v : c.cal.matrix[r]) v *= m;
        for (auto& v : c.cal.product_matrix[r]) v *= m;
        c.cal.bias[r] *= m;
      }
      return c;
    };
    double lo = 1.0;
    double hi = 1e12;
    fw::FixedCalibration fixed{};
    ASSERT_EQ(fw::LoadCalibration(scaled(lo).cal, base.adc, &fixed, nullptr), fw::LoadStatus::kOk);
    ASSERT_EQ(fw::LoadCalibration(scaled(hi).cal, base.adc, &fixed, nullptr),
              fw::LoadStatus::kOutputOverflow);
    for (int i = 0; i < 60; ++i) {
      const double mid = std::sqrt(lo * hi);
      if (fw::LoadCalibration(scaled(mid).cal, base.adc, &fixed, nullptr) == fw::LoadStatus::kOk) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    // At the edge, the extreme inputs still give the exact result within the bound: no wrap.
    const Case edge = scaled(lo);
    fw::LoadReport rep{};
    ASSERT_EQ(fw::LoadCalibration(edge.cal, edge.adc, &fixed, &rep), fw::LoadStatus::kOk);
    fw::WrenchCore core;
    core.SetCalibration(fixed);
    ExpectWithinBound(
        edge, core, rep, rng, 300, [](int s) { return s % 2 == 0 ? 60000 : -10000; }, {}, nullptr);
  }
}

/// A one-channel calibration with one square term x̃² on Fz, for an ADC with full int32 rails,
/// whose integer zero sits `xmax` counts below the positive rail: the core's raw product at that
/// rail is xmax².
Case SquareTermCase(std::int64_t xmax) {
  Case c;
  c.adc.channel_count = 1;
  c.adc.min_counts = std::numeric_limits<std::int32_t>::min();
  c.adc.max_counts = std::numeric_limits<std::int32_t>::max();
  c.adc.full_scale_nvv = 2147483647;  // 1e6 counts per mV/V
  c.cal.channel_count = 1;
  const std::int64_t zero = std::int64_t{c.adc.max_counts} - xmax;
  c.cal.offset_mvv[0] = static_cast<double>(zero) / fw::CountsPerMvv(c.adc);
  c.cal.product_count = 1;
  c.cal.products[0] = {0, 0};
  c.cal.product_matrix[2][0] = 1e-5;  // N per (mV/V)²: ≈ 92 N at the rail
  c.cal.bias[2] = 0.25;
  return c;
}

TEST(FixedTerms, RawProductOfASecondOrderFeatureIsBoundedExactlyAtTheEdge) {
  // The core computes x̃_a·x̃_b in int64 and rounds it by 2^(shift−1) before the shift; shift is
  // 37 for products between 2^62 and 2^63. Edge, in exact integers (independent of the loader):
  // X² + 2^36 ≤ 2^63 − 1 < (X + 1)² + 2^36.
  constexpr std::int64_t kEdge = 3037000488;
  using U128 = unsigned __int128;
  const U128 limit = (U128{1} << 63) - 1;
  ASSERT_LE(U128(kEdge) * U128(kEdge) + (U128{1} << 36), limit);
  ASSERT_GT(U128(kEdge + 1) * U128(kEdge + 1) + (U128{1} << 36), limit);

  const Case inside = SquareTermCase(kEdge);
  fw::FixedCalibration fixed{};
  fw::LoadReport rep{};
  ASSERT_EQ(fw::LoadCalibration(inside.cal, inside.adc, &fixed, &rep), fw::LoadStatus::kOk);
  ASSERT_EQ(std::int64_t{inside.adc.max_counts} - fixed.zero[0], kEdge);
  ASSERT_EQ(fixed.extra_count, 1);
  ASSERT_EQ(fixed.extra[0].shift, 37);
  fw::WrenchCore core;
  core.SetCalibration(fixed);
  // Exact against long double: y = q·(mV/V − offset)² + bias, at the rails, the zero and between.
  const long double cpm = static_cast<long double>(inside.adc.max_counts) / 2147.483647L;
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<std::int32_t> u(inside.adc.min_counts, inside.adc.max_counts);
  std::vector<std::int32_t> inputs = {inside.adc.max_counts, inside.adc.max_counts - 1,
                                      inside.adc.min_counts, fixed.zero[0], fixed.zero[0] + 1};
  for (int i = 0; i < 200; ++i) inputs.push_back(u(rng));
  for (const std::int32_t counts : inputs) {
    std::array<std::int32_t, hal::kMaxChannels> x{};
    x[0] = counts;
    fw::WrenchLsb y{};
    bool sat = false;
    core.Apply(x, y, &sat);
    ASSERT_FALSE(sat) << counts;
    const long double d = counts / cpm - static_cast<long double>(inside.cal.offset_mvv[0]);
    const long double ref_lsb = (1e-5L * d * d + 0.25L) / static_cast<long double>(fw::AxisLsb(2));
    EXPECT_LE(std::fabs(static_cast<double>(y[2] - ref_lsb)), rep.worst_case_error_lsb[2])
        << "counts " << counts;
    EXPECT_LE(rep.worst_case_error_lsb[2], 2.0);
  }
  // One count wider: the raw product at the rail could wrap. Refused, `fixed` untouched.
  const Case outside = SquareTermCase(kEdge + 1);
  fw::FixedCalibration untouched{};
  EXPECT_EQ(fw::LoadCalibration(outside.cal, outside.adc, &untouched, nullptr),
            fw::LoadStatus::kFeatureOverflow);
  EXPECT_FALSE(untouched.valid);
  // Far outside (a full 32-bit span: x̃² ≈ 2^64) likewise.
  EXPECT_EQ(fw::LoadCalibration(SquareTermCase(4294967295LL).cal, outside.adc, &untouched, nullptr),
            fw::LoadStatus::kFeatureOverflow);
}

TEST(FixedTerms, BadTermsAreRefused) {
  std::mt19937_64 rng(7);
  Case c = RandomCase(rng, true, true);
  fw::FixedCalibration fixed{};
  Case bad = c;
  bad.cal.products[0].b = bad.cal.channel_count;  // no such channel
  EXPECT_EQ(fw::LoadCalibration(bad.cal, bad.adc, &fixed, nullptr), fw::LoadStatus::kBadTerms);
  bad = c;
  bad.cal.product_matrix[3][0] = std::nan("");
  EXPECT_EQ(fw::LoadCalibration(bad.cal, bad.adc, &fixed, nullptr), fw::LoadStatus::kNotFinite);
  bad = c;
  bad.cal.gain_slope_per_c[0] = INFINITY;
  EXPECT_EQ(fw::LoadCalibration(bad.cal, bad.adc, &fixed, nullptr), fw::LoadStatus::kNotFinite);
  bad = c;
  bad.cal.temp_ref_c = 70.0;  // outside its own range
  EXPECT_EQ(fw::LoadCalibration(bad.cal, bad.adc, &fixed, nullptr), fw::LoadStatus::kBadTerms);
  EXPECT_FALSE(fixed.valid);  // untouched by every refusal
}

TEST(FixedTerms, MissingTemperatureUsesTheReferenceAndRaisesTheStatusBit) {
  std::mt19937_64 rng(8);
  const Case c = RandomCase(rng, false, true);
  fw::FixedCalibration fixed{};
  ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, nullptr), fw::LoadStatus::kOk);
  fw::WrenchCore core;
  core.SetLimits(fw::CoreLimits{0, 0});
  core.SetCalibration(fixed);
  hal::AdcSample s{};
  s.channel_count = c.cal.channel_count;
  s.has_temperature = false;
  fw::CoreOutput out{};
  core.Process(s, false, out);
  EXPECT_NE(out.status & fw::kStatusTempRange, 0);
  s.has_temperature = true;
  s.temperature_mdegc = 25000;
  core.Process(s, false, out);
  EXPECT_EQ(out.status & fw::kStatusTempRange, 0);
}

}  // namespace
}  // namespace ftstack

namespace ftstack {
namespace {

/// The cached per-ΔT coefficients at the edges of the compensated range and beyond (clamped),
/// the temperature jumping between them so every sample recomputes the cache, untared and with a
/// tare taken at the opposite edge: within the proven bound of the long-double reference.
TEST(FixedTerms, TemperatureRangeEdgesWithinProvenBound) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 60; ++trial) {
    const Case c = RandomCase(rng, trial % 2 == 0, true);
    fw::FixedCalibration fixed{};
    fw::LoadReport rep{};
    ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, &rep), fw::LoadStatus::kOk);
    const std::int32_t lo = fixed.temp_min_mdegc;
    const std::int32_t hi = fixed.temp_max_mdegc;
    const std::array<std::int32_t, 7> temps = {lo,     hi,    lo + 1, hi - 1, fixed.temp_ref_mdegc,
                                               lo - 1, hi + 1};
    fw::WrenchCore core;
    core.SetLimits(fw::CoreLimits{0, 0});
    core.SetCalibration(fixed);
    ExpectWithinBound(
        c, core, rep, rng, 70, [&](int s) { return temps[static_cast<std::size_t>(s) % 7]; }, {},
        nullptr);
    // Tare at one edge, evaluate at the other (and everywhere in between).
    hal::AdcSample s{};
    s.channel_count = c.cal.channel_count;
    s.counts = RandomCounts(rng, c.adc);
    for (auto& v : s.counts) v /= 2;  // a tare sample away from the rails
    s.has_temperature = true;
    s.temperature_mdegc = trial % 3 == 0 ? lo : hi;
    ASSERT_TRUE(core.RequestTare(1));
    fw::CoreOutput out{};
    core.Process(s, false, out);
    ASSERT_TRUE(core.tare_active());
    const auto ref_tare = Reference(c, s.counts, s.temperature_mdegc);
    ExpectWithinBound(
        c, core, rep, rng, 70, [&](int k) { return temps[static_cast<std::size_t>(k) % 7]; },
        ref_tare, nullptr);
  }
}

/// The narrow form (32-bit coefficients, SIMD sums) and the 64-bit form of the same calibration
/// both stay within the loader's bound and differ by at most one LSB; a calibration whose narrow
/// rounding would cost more than 1/16 LSB (outputs near the int32 range) is left in the 64-bit
/// form and stays within 1 LSB of the reference.
TEST(FixedTerms, NarrowFormOnlyWhereProvenAndWithinTheBound) {
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<std::int32_t> temp(-15000, 65000);
  for (int trial = 0; trial < 80; ++trial) {
    const Case c = RandomCase(rng, trial % 2 == 0, trial % 4 < 2);
    fw::FixedCalibration fixed{};
    fw::LoadReport rep{};
    ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, &rep), fw::LoadStatus::kOk);
    ASSERT_TRUE(fixed.narrow) << "trial " << trial;  // realistic calibrations run narrow
    fw::FixedCalibration wide = fixed;
    wide.narrow = false;
    fw::WrenchCore narrow_core;
    fw::WrenchCore wide_core;
    narrow_core.SetCalibration(fixed);
    wide_core.SetCalibration(wide);
    for (int s = 0; s < 100; ++s) {
      const auto x = RandomCounts(rng, c.adc);
      const std::int32_t t = temp(rng);
      fw::WrenchLsb yn{};
      fw::WrenchLsb yw{};
      bool sat = false;
      bool range = false;
      narrow_core.Apply(x, t, true, yn, &sat, &range);
      wide_core.Apply(x, t, true, yw, &sat, &range);
      const auto ref = Reference(c, x, t);
      for (std::size_t r = 0; r < 6; ++r) {
        ASSERT_LE(std::fabs(yn[r] - ref[r]), rep.worst_case_error_lsb[r]);
        ASSERT_LE(std::fabs(yw[r] - ref[r]), rep.worst_case_error_lsb[r]);
        ASSERT_LE(std::abs(yn[r] - yw[r]), 1);
      }
    }
  }
  // A linear calibration scaled up until the outputs reach ~2^28 LSB: the narrow rounding would
  // exceed 1/16 LSB, the 64-bit form keeps its ~0.5 LSB bound.
  Case big = RandomCase(rng, false, false);
  for (std::size_t r = 0; r < 6; ++r) {
    for (auto& v : big.cal.matrix[r]) v *= 20.0;
  }
  fw::FixedCalibration fixed{};
  fw::LoadReport rep{};
  ASSERT_EQ(fw::LoadCalibration(big.cal, big.adc, &fixed, &rep), fw::LoadStatus::kOk);
  EXPECT_FALSE(fixed.narrow);
  fw::WrenchCore core;
  core.SetCalibration(fixed);
  for (std::size_t r = 0; r < 6; ++r) EXPECT_LE(rep.worst_case_error_lsb[r], 1.0);
  ExpectWithinBound(
      big, core, rep, rng, 300, [&](int) { return temp(rng); }, {}, nullptr);
}

/// The narrow form's per-channel-count kernels (SSE2 / NEON / scalar, one instance per N): for
/// every N = 1 … 8 and every combination of terms, counts beyond the rails (up to the int32
/// limits) are clamped and flagged, channels beyond N (filled with extreme values) are ignored,
/// and the result stays within the loader's bound of the reference at the clamped counts, and
/// within 1 LSB of the 64-bit form.
TEST(FixedTerms, NarrowKernelsForEveryChannelCountClampBeyondTheRails) {
  std::mt19937_64 rng(21);
  std::uniform_int_distribution<std::int32_t> temp(-15000, 65000);
  std::uniform_int_distribution<int> pick(0, 5);
  for (int n = 1; n <= 8; ++n) {
    for (int terms = 0; terms < 4; ++terms) {
      const Case c = RandomCase(rng, (terms & 1) != 0, (terms & 2) != 0, n);
      fw::FixedCalibration fixed{};
      fw::LoadReport rep{};
      ASSERT_EQ(fw::LoadCalibration(c.cal, c.adc, &fixed, &rep), fw::LoadStatus::kOk);
      ASSERT_TRUE(fixed.narrow) << "N " << n << " terms " << terms;
      fw::FixedCalibration wide = fixed;
      wide.narrow = false;
      fw::WrenchCore narrow_core;
      fw::WrenchCore wide_core;
      narrow_core.SetCalibration(fixed);
      wide_core.SetCalibration(wide);
      for (int s = 0; s < 200; ++s) {
        auto x = RandomCounts(rng, c.adc);
        auto inside = x;
        bool beyond = false;
        for (std::size_t ch = 0; ch < hal::kMaxChannels; ++ch) {
          const int p = pick(rng);
          std::int32_t v = x[ch];
          if (p == 0) v = std::numeric_limits<std::int32_t>::max();
          if (p == 1) v = std::numeric_limits<std::int32_t>::min();
          if (p == 2) v = c.adc.max_counts + 1;
          if (p == 3) v = c.adc.min_counts - 1;
          if (ch >= static_cast<std::size_t>(n)) {
            x[ch] = v;  // not a channel of this calibration: never read
            continue;
          }
          if (s % 2 == 0) continue;  // every other sample stays between the rails
          x[ch] = v;
          inside[ch] = std::clamp(v, c.adc.min_counts, c.adc.max_counts);
          beyond = beyond || v != inside[ch];
        }
        const std::int32_t t = temp(rng);
        fw::WrenchLsb yn{};
        fw::WrenchLsb yw{};
        bool sat_n = false;
        bool sat_w = false;
        bool range = false;
        narrow_core.Apply(x, t, true, yn, &sat_n, &range);
        wide_core.Apply(x, t, true, yw, &sat_w, &range);
        EXPECT_EQ(sat_n, beyond) << "N " << n << " sample " << s;
        EXPECT_EQ(sat_w, beyond);
        const auto ref = Reference(c, inside, t);
        for (std::size_t r = 0; r < 6; ++r) {
          ASSERT_LE(std::fabs(yn[r] - ref[r]), rep.worst_case_error_lsb[r])
              << "N " << n << " terms " << terms << " axis " << r;
          ASSERT_LE(std::abs(yn[r] - yw[r]), 1);
        }
      }
    }
  }
}

}  // namespace
}  // namespace ftstack
