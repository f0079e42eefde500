// Validation groups and the robust fit, on rig data generated here (not by ftsim): a known mass
// in a few orientations gives one group per orientation; a pose recorded with a wrong reference
// is reported and down-weighted.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "calibration/fit/fit.hpp"

namespace {

using ftstack::cal::FitCalibration;
using ftstack::cal::FitOptions;
using ftstack::cal::FitResult;
using ftstack::cal::GroupBlocksByLoadDirection;
using ftstack::cal::ModelKind;
using ftstack::cal::RigData;

/// A linear 6-bridge sensor under a mass hung in `orientations` gravity directions, at `levers`
/// lever arms each (one block per orientation × lever), 50 rows per block, 1e-4 mV/V noise.
RigData Generate(int orientations, int levers, unsigned seed, int bad_block, double bad_scale) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Eigen::Matrix<double, 6, 6> s = Eigen::Matrix<double, 6, 6>::Identity() * 0.02;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) s(i, j) += 0.004 * gauss(rng);
  s.rightCols<3>() *= 20.0;  // mV/V per N·m
  RigData d;
  d.path = "generated";
  const int blocks = orientations * levers;
  const int per = 50;
  d.bridges.resize(blocks * per, 6);
  d.wrench.resize(blocks * per, 6);
  for (int o = 0; o < orientations; ++o) {
    const Eigen::Vector3d g =
        Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * 9.81;
    for (int l = 0; l < levers; ++l) {
      const Eigen::Vector3d c(0.05 * gauss(rng), 0.05 * gauss(rng), 0.05 + 0.05 * l);
      const int b = o * levers + l;
      Eigen::Matrix<double, 6, 1> w;
      w.head<3>() = 2.0 * g;
      w.tail<3>() = c.cross(2.0 * g);
      for (int i = 0; i < per; ++i) {
        const int r = b * per + i;
        Eigen::Matrix<double, 6, 1> bridge = s * w;
        for (int c6 = 0; c6 < 6; ++c6) bridge(c6) += 1e-4 * gauss(rng);
        d.bridges.row(r) = bridge.transpose();
        d.wrench.row(r) = (b == bad_block ? bad_scale : 1.0) * w.transpose();
        d.block.push_back(b);
        d.t_s.push_back(r * 0.01);
      }
    }
  }
  d.block_count = blocks;
  d.block_method = "generated";
  const std::array<double, 6> scale = {20, 20, 20, 2, 2, 2};
  const std::vector<int> of_block =
      GroupBlocksByLoadDirection(d.wrench, d.block, blocks, scale, 5.0, &d.group_count);
  for (const int b : d.block) d.group.push_back(of_block[static_cast<std::size_t>(b)]);
  d.group_method = "load direction within 5°";
  return d;
}

TEST(FitGroups, OneGroupPerOrientationWhateverTheLever) {
  const RigData d = Generate(7, 4, 1, -1, 1.0);
  EXPECT_EQ(d.group_count, 7);
  for (std::size_t i = 0; i < d.block.size(); ++i) EXPECT_EQ(d.group[i], d.block[i] / 4);
}

TEST(FitGroups, FoldsHoldOutWholeOrientationsAndReportEachGroup) {
  const RigData d = Generate(7, 4, 2, -1, 1.0);
  FitOptions o;
  o.models = {ModelKind::kLinear};
  const FitResult r = FitCalibration(d, o);
  EXPECT_EQ(r.folds, 7);
  EXPECT_NE(r.validation.find("7 groups"), std::string::npos) << r.validation;
  ASSERT_EQ(r.groups.size(), 7u);
  for (std::size_t i = 1; i < r.groups.size(); ++i)
    EXPECT_GE(r.groups[i - 1].rms_pct, r.groups[i].rms_pct);  // worst first
  EXPECT_TRUE(r.suspect_blocks.empty());
  o.by_group = false;
  EXPECT_NE(FitCalibration(d, o).validation.find("28 load blocks"), std::string::npos);
}

TEST(FitGroups, ABadlyRecordedPoseIsReportedAndDownWeighted) {
  const int bad = 9;
  const RigData d = Generate(8, 4, 3, bad, 1.15);  // its reference 15 % too large
  FitOptions o;
  o.models = {ModelKind::kLinear};
  o.lambdas = {0.0};
  const FitResult r = FitCalibration(d, o);
  ASSERT_FALSE(r.suspect_blocks.empty());
  EXPECT_EQ(r.suspect_blocks.front(), bad);
  EXPECT_TRUE(r.robust);
  EXPECT_LT(r.robust_score, r.plain_score);
  // The calibration reads the clean blocks better than plain least squares over every block
  // (solved here independently).
  Eigen::MatrixXd x(d.bridges.rows(), 7);
  x << d.bridges, Eigen::VectorXd::Ones(d.bridges.rows());
  const Eigen::MatrixXd beta = x.colPivHouseholderQr().solve(d.wrench);
  double ls = 0.0;
  double ours = 0.0;
  for (Eigen::Index i = 0; i < d.bridges.rows(); ++i) {
    if (d.block[static_cast<std::size_t>(i)] == bad) continue;
    const Eigen::RowVectorXd e_ls = x.row(i) * beta - d.wrench.row(i);
    Eigen::RowVectorXd e(6);
    for (int a = 0; a < 6; ++a) {
      double v = r.cal.bias[static_cast<std::size_t>(a)];
      for (int c = 0; c < 6; ++c) {
        v += r.cal.matrix[static_cast<std::size_t>(a)][static_cast<std::size_t>(c)] *
             (d.bridges(i, c) - r.cal.offset_mvv[static_cast<std::size_t>(c)]);
      }
      e(a) = v - d.wrench(i, a);
    }
    ls += e_ls.head<3>().squaredNorm();
    ours += e.head<3>().squaredNorm();
  }
  EXPECT_LT(ours, 0.5 * ls);
}

/// Keeps only the first block of group 0 (a quarter of its rows) and adds `extra_noise` mV/V to
/// that group's bridges: an orientation recorded with few, noisy rows.
RigData ThinNoisyFirstGroup(const RigData& full, double extra_noise) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> gauss(0.0, extra_noise);
  std::vector<Eigen::Index> keep;
  const int first_block = full.block.front();
  for (std::size_t i = 0; i < full.block.size(); ++i) {
    if (full.group[i] != 0 || full.block[i] == first_block)
      keep.push_back(static_cast<Eigen::Index>(i));
  }
  RigData d = full;
  d.bridges.resize(static_cast<Eigen::Index>(keep.size()), full.bridges.cols());
  d.wrench.resize(static_cast<Eigen::Index>(keep.size()), 6);
  d.block.clear();
  d.group.clear();
  d.t_s.clear();
  std::vector<int> renumber(static_cast<std::size_t>(full.block_count), -1);
  d.block_count = 0;
  for (std::size_t k = 0; k < keep.size(); ++k) {
    const auto i = static_cast<std::size_t>(keep[k]);
    const auto r = static_cast<Eigen::Index>(k);
    d.bridges.row(r) = full.bridges.row(keep[k]);
    if (full.group[i] == 0)
      for (Eigen::Index c = 0; c < d.bridges.cols(); ++c) d.bridges(r, c) += gauss(rng);
    d.wrench.row(r) = full.wrench.row(keep[k]);
    int& b = renumber[static_cast<std::size_t>(full.block[i])];
    if (b < 0) b = d.block_count++;
    d.block.push_back(b);
    d.group.push_back(full.group[i]);
    d.t_s.push_back(full.t_s[i]);
  }
  return d;
}

// The score is the mean over validation groups of each group's held-out mean squared error (÷
// rated², mean over axes), every orientation counting once: checked against leave-one-group-out
// least squares solved here, on a rig whose noisiest orientation has a quarter of the rows.
TEST(FitGroups, EveryValidationGroupCountsOnceInTheScore) {
  const RigData d = ThinNoisyFirstGroup(Generate(6, 4, 5, -1, 1.0), 2e-3);
  FitOptions o;
  o.models = {ModelKind::kLinear};
  o.lambdas = {0.0};
  o.rated = {20, 20, 20, 2, 2, 2};
  const FitResult r = FitCalibration(d, o);
  ASSERT_EQ(r.folds, 6);
  ASSERT_EQ(r.candidates.size(), 1u);
  std::vector<double> per_group;
  for (int g = 0; g < d.group_count; ++g) {
    std::vector<Eigen::Index> tr;
    std::vector<Eigen::Index> te;
    for (std::size_t i = 0; i < d.group.size(); ++i)
      (d.group[i] == g ? te : tr).push_back(static_cast<Eigen::Index>(i));
    Eigen::MatrixXd x(static_cast<Eigen::Index>(tr.size()), 7);
    Eigen::MatrixXd y(static_cast<Eigen::Index>(tr.size()), 6);
    for (std::size_t k = 0; k < tr.size(); ++k) {
      x.row(static_cast<Eigen::Index>(k)) << d.bridges.row(tr[k]), 1.0;
      y.row(static_cast<Eigen::Index>(k)) = d.wrench.row(tr[k]);
    }
    const Eigen::MatrixXd beta = x.colPivHouseholderQr().solve(y);
    double mse = 0.0;
    for (const Eigen::Index i : te) {
      Eigen::RowVectorXd xi(7);
      xi << d.bridges.row(i), 1.0;
      const Eigen::RowVectorXd e = xi * beta - d.wrench.row(i);
      for (int a = 0; a < 6; ++a)
        mse += std::pow(e(a) / o.rated[static_cast<std::size_t>(a)], 2) / 6.0;
    }
    per_group.push_back(mse / static_cast<double>(te.size()));
  }
  double mean = 0.0;
  for (const double m : per_group) mean += m / static_cast<double>(per_group.size());
  EXPECT_GT(per_group[0], 10 * per_group[1]);  // the thin group is the noisy one
  EXPECT_NEAR(r.candidates[0].score, mean, 1e-6 * mean);
  double shares = 0.0;
  for (const double s : r.candidates[0].fold_score) shares += s;
  EXPECT_NEAR(shares, r.candidates[0].score, 1e-12 * mean);
}

/// A linear 6-bridge sensor under a mass in 6 orientations × 2 levers, held at each of
/// `temps_c`, whose bridge zeros drift by `zero_drift` × (T − 20 °C) (mV/V per °C, channel c
/// scaled by (c + 1) / 6 with alternating sign), 1e-4 mV/V noise.
RigData AtTemperatures(const std::vector<double>& temps_c, double zero_drift, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const RigData one = Generate(6, 2, seed, -1, 1.0);
  RigData d;
  d.path = "generated";
  const auto n = one.bridges.rows();
  const auto t = static_cast<Eigen::Index>(temps_c.size());
  d.bridges.resize(n * t, 6);
  d.wrench.resize(n * t, 6);
  d.temp_c.resize(n * t);
  for (Eigen::Index k = 0; k < t; ++k) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index r = k * n + i;
      // The held temperature wanders by 0.2 °C; the bridges drift with it, as the sensor reads it.
      d.temp_c(r) = temps_c[static_cast<std::size_t>(k)] + 0.2 * gauss(rng);
      const double dt = d.temp_c(r) - 20.0;
      for (int c = 0; c < 6; ++c) {
        const double alpha = zero_drift * (c + 1) / 6.0 * (c % 2 == 0 ? 1.0 : -1.0);
        d.bridges(r, c) = one.bridges(i, c) + alpha * dt + 1e-4 * gauss(rng);
      }
      d.wrench.row(r) = one.wrench.row(i);
      d.block.push_back(static_cast<int>(k) * one.block_count +
                        one.block[static_cast<std::size_t>(i)]);
      d.group.push_back(one.group[static_cast<std::size_t>(i)]);
      d.t_s.push_back(static_cast<double>(r) * 0.01);
    }
  }
  d.block_count = one.block_count * static_cast<int>(t);
  d.group_count = one.group_count;
  d.block_method = "generated";
  d.group_method = one.group_method;
  return d;
}

// Temperature terms are candidates validated by holding out whole temperatures: a zero drift of
// 20 noise σ per °C is compensated with the slopes it was made with; without drift the same rig
// keeps the linear model.
TEST(FitTemperature, WholeTemperaturesAreHeldOutAndTermsTakenOnlyWhenTheyMatter) {
  const std::vector<double> temps = {5.0, 15.0, 25.0, 35.0};
  FitOptions o;
  o.rated = {20, 20, 20, 2, 2, 2};
  o.models = {ModelKind::kLinear, ModelKind::kLinearTemp};  // the question here: temperature or not
  const FitResult drift = FitCalibration(AtTemperatures(temps, 2e-3, 11), o);
  EXPECT_EQ(drift.validation, "4 temperatures (levels more than 1 °C apart)");
  EXPECT_EQ(drift.folds, 4);
  EXPECT_EQ(drift.kind, ModelKind::kLinearTemp);
  ASSERT_TRUE(drift.cal.temperature_compensated);
  for (int c = 0; c < 6; ++c) {
    const double alpha = 2e-3 * (c + 1) / 6.0 * (c % 2 == 0 ? 1.0 : -1.0);
    EXPECT_NEAR(drift.cal.bias_slope_mvv_per_c[static_cast<std::size_t>(c)], alpha, 2e-5) << c;
  }
  const FitResult flat = FitCalibration(AtTemperatures(temps, 0.0, 11), o);
  EXPECT_EQ(flat.validation, "4 temperatures (levels more than 1 °C apart)");
  EXPECT_EQ(flat.kind, ModelKind::kLinear) << flat.over_simplest.complex;
  EXPECT_FALSE(flat.cal.temperature_compensated);
  // Two temperatures cannot be held out in turn as a set of three or more: the load directions are.
  const FitResult two = FitCalibration(AtTemperatures({10.0, 30.0}, 2e-3, 11), o);
  EXPECT_EQ(two.validation.find("temperatures"), std::string::npos) << two.validation;
}

/// A candidate with the given per-fold shares of its score.
ftstack::cal::CandidateScore Candidate(ModelKind kind, int features, double lambda,
                                       std::vector<double> shares) {
  ftstack::cal::CandidateScore c;
  c.kind = kind;
  c.features = features;
  c.lambda = lambda;
  for (const double x : shares) c.score += x;
  c.fold_score = std::move(shares);
  return c;
}

// Margins and standard errors worked by hand: d_k = simpler − complex share, margin = Σ d_k,
// SE = √K · sample standard deviation of the d_k.
TEST(FitChoice, AMarginWithinOneStandardErrorKeepsTheSimplerModel) {
  using ftstack::cal::ChoiceMargin;
  const auto linear = Candidate(ModelKind::kLinear, 9, 0.0, {1.0, 1.0, 1.0, 1.0});
  // 2.5 % lower score (a 1 %-of-best rule would take it), d = .5 −.5 .3 −.2: SE = √(4·.6275/3).
  const auto noisy = Candidate(ModelKind::kQuadraticDiag, 17, 0.0, {0.5, 1.5, 0.7, 1.2});
  ChoiceMargin over;
  ChoiceMargin challenger;
  std::vector<ftstack::cal::CandidateScore> c = {noisy, linear};
  EXPECT_EQ(ftstack::cal::ChooseOneStandardError(c, &over, &challenger), 1u);
  EXPECT_TRUE(over.complex.empty());
  EXPECT_EQ(challenger.complex, "quadratic-diag lambda=0");
  EXPECT_NEAR(challenger.margin, 0.1, 1e-12);
  EXPECT_NEAR(challenger.se, std::sqrt(4 * 0.6275 / 3), 1e-12);
  // Consistently lower in every fold, d = .2 .1 .15 .25: SE = √(4·.0125/3) < margin .7.
  const auto steady = Candidate(ModelKind::kQuadraticDiag, 17, 0.0, {0.8, 0.9, 0.85, 0.75});
  c = {linear, steady};
  EXPECT_EQ(ftstack::cal::ChooseOneStandardError(c, &over, &challenger), 1u);
  EXPECT_NEAR(over.margin, 0.7, 1e-12);
  EXPECT_NEAR(over.se, std::sqrt(4 * 0.0125 / 3), 1e-12);
  EXPECT_EQ(over.simpler, "linear lambda=0");
  EXPECT_TRUE(challenger.complex.empty());
}

TEST(FitChoice, TheSmallestRidgeLambdaNotBeatenByMoreThanOneStandardErrorIsTaken) {
  using ftstack::cal::ChoiceMargin;
  const auto plain = Candidate(ModelKind::kLinear, 9, 0.0, {1.0, 1.0, 1.0, 1.0});
  const auto mild = Candidate(ModelKind::kLinear, 9, 0.03, {0.82, 0.88, 0.86, 0.76});
  // Lowest score, but only .02 below λ = 0.03 with SE √(4·.0009/3) ≈ .035.
  const auto strong = Candidate(ModelKind::kLinear, 9, 0.1, {0.8, 0.9, 0.85, 0.75});
  ChoiceMargin over;
  ChoiceMargin challenger;
  const std::vector<ftstack::cal::CandidateScore> c = {strong, plain, mild};
  EXPECT_EQ(ftstack::cal::ChooseOneStandardError(c, &over, &challenger), 2u);
  EXPECT_EQ(over.simpler, "linear lambda=0");
  EXPECT_EQ(over.complex, "linear lambda=0.03");
  EXPECT_EQ(challenger.complex, "linear lambda=0.1");
  EXPECT_NEAR(challenger.margin, 0.02, 1e-12);
  EXPECT_NEAR(challenger.se, std::sqrt(4 * 0.0009 / 3), 1e-12);
  EXPECT_FALSE(challenger.Significant());
}

}  // namespace
