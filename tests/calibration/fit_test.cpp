// Fitting: held-out error against the independent noise floor, model choice, block detection.
#include <gtest/gtest.h>

#include <cmath>

#include "calibration/fit/apply.hpp"
#include "calibration/fit/fit.hpp"
#include "calibration/fit/fit_report.hpp"
#include "sim/rig.hpp"
#include "tests/calibration/test_models.hpp"

namespace ftstack::cal {
namespace {

using sim::DesignRig;
using sim::RigDesignOptions;
using sim::RigKeys;
using sim::RigStep;
using sim::SimulateRig;

constexpr double kRateHz = 200.0;

std::array<double, 6> Rated(const sim::SensorDescription& d) {
  std::array<double, 6> r{};
  for (int a = 0; a < 6; ++a) r[static_cast<std::size_t>(a)] = d.model->rated()(a);
  return r;
}

FitResult FitSimulated(const sim::SensorDescription& d, const RigDesignOptions& ro,
                       std::uint64_t seed, const std::vector<ModelKind>& models = {},
                       RigData* data_out = nullptr) {
  const auto keys = RigKeys(DesignRig(d.model->rated(), ro), ro);
  const Recording rec = SimulateRig(d, keys, kRateHz, seed);
  BlockOptions bo;
  bo.scale = Rated(d);
  RigData data = RigDataFromRecording(rec, bo);
  FitOptions fo;
  fo.rated = Rated(d);
  fo.models = models;
  FitResult r = FitCalibration(data, fo);
  if (data_out != nullptr) *data_out = std::move(data);
  return r;
}

/// RMS per axis of the fixed-point core's output against the reference on a fresh recording.
std::array<double, 6> FixedPointRms(const CalFile& cal, const Recording& rec) {
  const Recording out = ApplyCalibration(cal, rec);
  std::array<double, 6> rms{};
  for (std::size_t a = 0; a < 6; ++a) {
    const auto& ref = rec.Column(WrenchColumns()[a]);
    const auto& got = out.Column(WrenchColumns()[a]);
    double ss = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) ss += (got[i] - ref[i]) * (got[i] - ref[i]);
    rms[a] = std::sqrt(ss / static_cast<double>(ref.size()));
  }
  return rms;
}

/// Cross-validated score of one candidate (−1 if absent).
double ScoreOf(const FitResult& r, ModelKind kind, double lambda) {
  for (const CandidateScore& c : r.candidates) {
    if (c.kind == kind && c.lambda == lambda) return c.score;
  }
  return -1;
}

/// The chosen model's score: mean over axes of (held-out RMS / rated)².
double ChosenScore(const FitResult& r) {
  double s = 0;
  for (std::size_t a = 0; a < 6; ++a) s += std::pow(r.heldout_rms_si[a] / r.rated[a], 2) / 6;
  return s;
}

/// Held-out RMS of every axis within 1.1× the noise floor (printed for the record).
void ExpectNearFloor(const std::array<double, 6>& rms, const Eigen::Matrix<double, 6, 1>& floor,
                     const char* what) {
  for (int a = 0; a < 6; ++a) {
    const double v = rms[static_cast<std::size_t>(a)];
    std::printf("%s axis %d: RMS %.4g, noise floor %.4g, ratio %.3f\n", what, a, v, floor(a),
                v / floor(a));
    EXPECT_LE(v, 1.1 * floor(a)) << what << " axis " << a;
  }
}

/// The exported fixed-point form on a fresh simulated rig (other loads, other noise seed).
void ExpectFixedPointNearFloor(const sim::SensorDescription& d, const FitResult& r,
                               const RigDesignOptions& ro, std::uint64_t seed,
                               const Eigen::Matrix<double, 6, 1>& floor) {
  const CalFile cal = CalFileFromFit(r, DefaultAdc(6), "t", "2026-01-01");
  const Recording fresh =
      SimulateRig(d, RigKeys(DesignRig(d.model->rated(), ro), ro), kRateHz, seed);
  ExpectNearFloor(FixedPointRms(cal, fresh), floor, "fixed-point, fresh data");
}

TEST(Fit, LinearSensorHeldOutErrorIsWithinTenPercentOfTheNoiseFloor) {
  const sim::SensorDescription d = sim::DefaultSensorDescription();
  const Eigen::Matrix<double, 6, 1> floor = testing::NoiseFloor(d);
  const FitResult r = FitSimulated(d, RigDesignOptions{}, 11);
  EXPECT_EQ(r.kind, ModelKind::kLinear);
  EXPECT_GT(r.block_count, 100);
  EXPECT_EQ(r.block_method, "holds");
  ExpectNearFloor(r.heldout_rms_si, floor, "linear held-out");
  for (int a = 0; a < 6; ++a) {
    const double rms = r.heldout_rms_si[static_cast<std::size_t>(a)];
    // Below the floor would mean the validation leaked the reference.
    EXPECT_GE(rms, 0.9 * floor(a)) << "axis " << a;
    // 95 % of a Gaussian error lies within 1.96 σ.
    EXPECT_NEAR(r.heldout_p95_si[static_cast<std::size_t>(a)] / rms, 1.96, 0.1);
  }
  RigDesignOptions ro;
  ro.random_combinations = 40;
  ro.seed = 99;
  ExpectFixedPointNearFloor(d, r, ro, 12345, floor);
}

TEST(Fit, QuadraticSensorIsFittedByTheSecondOrderModel) {
  sim::SensorDescription d = sim::DefaultSensorDescription();
  auto base = sim::MakeDefaultSensor();
  // 0.3 % nonlinearity per bridge at its 0.6 mV/V rated output: k = 0.003 / 0.6 per mV/V.
  Eigen::VectorXd k(6);
  k << 0.005, -0.004, 0.006, 0.003, -0.005, 0.004;
  d.model = std::make_shared<testing::DistortedSensor>(*base, k, Eigen::VectorXd::Zero(6),
                                                       Eigen::VectorXd::Zero(6));
  const Eigen::Matrix<double, 6, 1> floor = testing::NoiseFloor(d);
  const FitResult r = FitSimulated(d, RigDesignOptions{}, 21);
  // A nonlinearity of each bridge alone is its square: the squares-only model, fewer terms than
  // every product, generalises as well and wins.
  EXPECT_EQ(r.kind, ModelKind::kQuadraticDiag);
  EXPECT_EQ(r.cal.product_count, 6);
  // The nonlinearity is far above the noise.
  EXPECT_GT(ScoreOf(r, ModelKind::kLinear, 0.0), 4.0 * ChosenScore(r));
  ExpectNearFloor(r.heldout_rms_si, floor, "quadratic held-out");
  // And the second-order terms run in the fixed-point core.
  ASSERT_GT(r.cal.product_count, 0);
  RigDesignOptions ro;
  ro.seed = 5;
  ExpectFixedPointNearFloor(d, r, ro, 777, floor);
}

TEST(Fit, TemperatureDriftIsCompensatedPerChannel) {
  sim::SensorDescription d = sim::DefaultSensorDescription();
  auto base = sim::MakeDefaultSensor();
  // Typical datasheet drift of a foil-gauge sensor: zero ≈ 0.02 % of 1 mV/V per °C (2 noise σ
  // per °C here), span ≈ 0.02 % per °C.
  Eigen::VectorXd zero_drift(6);  // mV/V per °C
  zero_drift << 2e-4, -1.5e-4, 1e-4, 0.0, -2e-4, 5e-5;
  Eigen::VectorXd gain_drift(6);  // per °C
  gain_drift << 2e-4, -1.5e-4, 1e-4, 2.5e-4, -5e-5, 1.5e-4;
  d.model = std::make_shared<testing::DistortedSensor>(*base, Eigen::VectorXd::Zero(6), zero_drift,
                                                       gain_drift);
  const Eigen::Matrix<double, 6, 1> floor = testing::NoiseFloor(d);
  RigDesignOptions ro;
  ro.temperatures_c = {20.0, 5.0, 40.0};
  const FitResult r = FitSimulated(d, ro, 31);
  EXPECT_EQ(r.kind, ModelKind::kLinearTemp);
  ASSERT_TRUE(r.cal.temperature_compensated);
  // The fitted per-channel slopes are the physical ones: zero drift α_c and gain drift γ_c
  // (relative to the reference temperature, γ/(1 + γ·(T_ref − 20))), to a few per cent.
  const double dt_ref = r.cal.temp_ref_c - 20.0;
  for (int c = 0; c < 6; ++c) {
    EXPECT_NEAR(r.cal.bias_slope_mvv_per_c[static_cast<std::size_t>(c)], zero_drift(c), 5e-6) << c;
    EXPECT_NEAR(r.cal.gain_slope_per_c[static_cast<std::size_t>(c)],
                gain_drift(c) / (1.0 + gain_drift(c) * dt_ref), 1e-5)
        << c;
  }
  // Without compensation the drift dominates.
  EXPECT_GT(ScoreOf(r, ModelKind::kLinear, 0.0), 10.0 * ChosenScore(r));
  ExpectNearFloor(r.heldout_rms_si, floor, "temperature held-out");
  // Through the fixed-point core at temperatures inside the compensated range.
  RigDesignOptions fresh_ro;
  fresh_ro.temperatures_c = {12.0, 30.0};
  fresh_ro.seed = 9;
  ExpectFixedPointNearFloor(d, r, fresh_ro, 4242, floor);
}

TEST(Fit, ChosenModelIsNeverWorseThanPlainLeastSquaresOnTheSameFolds) {
  // Few, noisy blocks with a quadratic candidate: regularisation and model choice must not lose
  // against plain least squares evaluated the same way.
  sim::SensorDescription d = sim::DefaultSensorDescription();
  d.adc.noise_rms_mvv = 2e-3;
  RigDesignOptions ro;
  ro.levels = {1.0};
  ro.combined = false;
  ro.random_combinations = 6;
  ro.hold_s = 0.1;
  const FitResult r = FitSimulated(d, ro, 41);
  const double ls = ScoreOf(r, ModelKind::kLinear, 0.0);
  ASSERT_GT(ls, 0);
  EXPECT_LE(ChosenScore(r), ls * (1 + 1e-12));
}

TEST(Blocks, HoldsAreFoundAndTransitionsJoinTheNearestHold) {
  // Three holds (rows 0–9, 14–23, 28–37) joined by 4-row ramps.
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(38, 6);
  for (int i = 0; i < 38; ++i) {
    double v = 0;
    if (i < 10) {
      v = 0;
    } else if (i < 14) {
      v = 20.0 * (i - 9);
    } else if (i < 24) {
      v = 100;
    } else if (i < 28) {
      v = 100 - 20.0 * (i - 23);
    } else {
      v = 0;
    }
    w(i, 2) = v;
  }
  BlockOptions bo;
  bo.scale = {1, 1, 100, 1, 1, 1};
  int count = 0;
  std::string method;
  const std::vector<int> b = DetectBlocks(w, bo, &count, &method);
  EXPECT_EQ(method, "holds");
  ASSERT_EQ(count, 3);
  // The ramp 10…13 is split at its middle: rows 10, 11 → hold 0; 12, 13 → hold 1.
  EXPECT_EQ(b[11], 0);
  EXPECT_EQ(b[12], 1);
  EXPECT_EQ(b[20], 1);
  EXPECT_EQ(b[26], 2);
  EXPECT_EQ(b[37], 2);
}

TEST(Blocks, SlowRampsDoNotBecomeHolds) {
  // 20 holds of 500 rows joined by 400-row ramps of 40 % of the scale (1 % every 10 rows).
  const int hold = 500;
  const int ramp = 400;
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(20 * hold + 19 * ramp, 6);
  Eigen::Index row = 0;
  for (int h = 0; h < 20; ++h) {
    const double level = (h % 2) * 0.4;
    for (int i = 0; i < hold; ++i) w(row++, 1) = level;
    if (h == 19) break;
    for (int i = 1; i <= ramp; ++i) {
      w(row++, 1) = level + ((h % 2) ? -0.4 : 0.4) * i / static_cast<double>(ramp + 1);
    }
  }
  BlockOptions bo;
  bo.scale = {1, 1, 1, 1, 1, 1};
  int count = 0;
  std::string method;
  (void)DetectBlocks(w, bo, &count, &method);
  EXPECT_EQ(method, "holds");
  EXPECT_EQ(count, 20);
}

TEST(Blocks, ContinuousLoadingIsCutIntoContiguousChunks) {
  Eigen::MatrixXd w(1000, 6);
  for (int i = 0; i < 1000; ++i) w.row(i).setConstant(std::sin(i * 0.05) * 100);
  BlockOptions bo;
  int count = 0;
  std::string method;
  const std::vector<int> b = DetectBlocks(w, bo, &count, &method);
  EXPECT_EQ(method, "chunks");
  EXPECT_EQ(count, 20);
  for (int i = 1; i < 1000; ++i)
    EXPECT_GE(b[static_cast<std::size_t>(i)], b[static_cast<std::size_t>(i - 1)]);
}

TEST(Blocks, PoseColumnWins) {
  const sim::SensorDescription d = sim::DefaultSensorDescription();
  RigDesignOptions ro;
  ro.levels = {0.5, 1.0};
  ro.random_combinations = 4;
  const auto steps = DesignRig(d.model->rated(), ro);
  const Recording rec = SimulateRig(d, RigKeys(steps, ro), 100.0, 3, true);
  const RigData data = RigDataFromRecording(rec, BlockOptions{});
  EXPECT_EQ(data.block_method, "column pose");
  // Every step is one pose, except that the repeated zero loads are separate poses too.
  EXPECT_EQ(data.block_count, static_cast<int>(steps.size()));
}

TEST(Design, ProposedLoadSetIsWellConditioned) {
  const Wrench rated = sim::DefaultRated();
  const auto steps = DesignRig(rated, RigDesignOptions{});
  const double kappa = LoadSetCondition(sim::RigLoads(steps), rated);
  EXPECT_LT(kappa, 10.0);
  // Single-axis loads only along Fz would be singular.
  std::vector<RigStep> bad(steps.begin(), steps.begin() + 1);
  RigStep fz;
  fz.wrench(2) = 400;
  bad.push_back(fz);
  EXPECT_FALSE(std::isfinite(LoadSetCondition(sim::RigLoads(bad), rated)) &&
               LoadSetCondition(sim::RigLoads(bad), rated) < 1e6);
  // Combined axial preload × moment loads are in the sequence, and every sweep comes back down.
  bool preload_moment = false;
  for (const RigStep& s : steps) preload_moment |= s.wrench(2) != 0 && s.wrench(3) != 0;
  EXPECT_TRUE(preload_moment);
}

}  // namespace
}  // namespace ftstack::cal
