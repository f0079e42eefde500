// Zephyr-style round trip: wrench applied in sim → bridges → simulated ADC counts → firmware core →
// wrench, within a tolerance derived from the channel noise, quantisation and fixed-point bound.
#include <gtest/gtest.h>

#include <cmath>

#include "firmware/sampler.hpp"
#include "hal/sim/sim_adc.hpp"
#include "sim/ideal_calibration.hpp"
#include "sim/sensor_description.hpp"
#include "sim/simulated_sensor.hpp"

namespace ftstack {
namespace {

struct RoundTrip {
  Wrench mean_recovered;  // N, N·m
  Wrench reference;       // noise-free double-precision chain, N, N·m
  Wrench tolerance;       // derived
  Wrench linearisation;   // reference − applied (model nonlinearity), N, N·m
};

RoundTrip RunChain(const sim::SensorDescription& desc, const Wrench& applied, int samples,
                   std::uint64_t seed) {
  sim::ConstantWrench source(applied, 20.0);
  hal::sim::SimAdcParams params = desc.adc;
  params.seed = seed;
  params.realtime = false;
  sim::SimulatedAdc simulated(desc, source, params);
  fw::WrenchCore core;
  fw::Sampler sampler(simulated.adc(), core);
  EXPECT_EQ(sampler.Start(simulated.Config(1000)), hal::Status::kOk);
  const cal::CalFile cal = sim::IdealCalibration(*desc.model, sampler.info());
  fw::LoadReport rep{};
  core.SetCalibration(cal::ToFixed(cal, sampler.info(), &rep));

  RoundTrip rt;
  rt.mean_recovered.setZero();
  fw::PublishedSample p{};
  for (int i = 0; i < samples; ++i) {
    EXPECT_EQ(sampler.Step(p), hal::Status::kOk);
    EXPECT_EQ(p.status & ~fw::kStatusSimulated, 0) << "unexpected status bits";
    for (int r = 0; r < 6; ++r)
      rt.mean_recovered(r) +=
          p.wrench[static_cast<std::size_t>(r)] * fw::AxisLsb(static_cast<std::size_t>(r));
  }
  rt.mean_recovered /= samples;

  // Independent double-precision chain without noise: M · (b(w) − b(0)).
  const int n = desc.model->channel_count();
  Eigen::MatrixXd m(6, n);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < n; ++c)
      m(r, c) = cal.cal.matrix[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  }
  const Eigen::VectorXd b = desc.model->BridgeOutputs(applied, 20.0);
  const Eigen::VectorXd b0 = desc.model->BridgeOutputs(Wrench::Zero(), 20.0);
  rt.reference = m * (b - b0);
  rt.linearisation = rt.reference - applied;

  // Per-channel variance: white noise plus uniform quantisation of one count.
  const double cpm = fw::CountsPerMvv(sampler.info());
  const double var_mvv = params.noise_rms_mvv * params.noise_rms_mvv + 1.0 / (12.0 * cpm * cpm);
  for (int r = 0; r < 6; ++r) {
    const double sigma = std::sqrt(m.row(r).squaredNorm() * var_mvv / samples);
    rt.tolerance(r) = 4.5 * sigma + rep.worst_case_error_si[static_cast<std::size_t>(r)];
  }
  return rt;
}

class RoundTripTest : public ::testing::TestWithParam<int> {};

TEST_P(RoundTripTest, RecoversTheAppliedWrenchWithinDerivedTolerance) {
  const sim::SensorDescription desc = sim::DefaultSensorDescription();
  const Wrench rated = desc.model->rated();
  Wrench applied = Wrench::Zero();
  const int k = GetParam();
  if (k < 6) {
    applied(k) = 0.6 * rated(k);  // one axis at 60 % of rated
  } else if (k < 12) {
    applied(k - 6) = -0.9 * rated(k - 6);  // negative, near rated
  } else {
    applied << 0.3, -0.2, 0.5, 0.25, -0.3, 0.2;  // combined load, fractions of rated
    applied = applied.cwiseProduct(rated);
  }
  const RoundTrip rt = RunChain(desc, applied, 400, 100 + static_cast<std::uint64_t>(k));
  for (int r = 0; r < 6; ++r) {
    EXPECT_NEAR(rt.mean_recovered(r), rt.reference(r), rt.tolerance(r))
        << "axis " << r << " applied " << applied.transpose();
    // The sensor model itself must be linear enough for a linear calibration (0.5 % of rated).
    EXPECT_LE(std::fabs(rt.linearisation(r)), 0.005 * rated(r)) << "axis " << r;
  }
}

INSTANTIATE_TEST_SUITE_P(Loads, RoundTripTest, ::testing::Range(0, 13));

TEST(RoundTrip, ToleranceIsTightEnoughToCatchAOnePercentGainError) {
  // The derived tolerance must be meaningful: a one-percent gain error on one bridge has to
  // exceed it at 60 % of rated Fz, otherwise the test above could not fail.
  const sim::SensorDescription desc = sim::DefaultSensorDescription();
  Wrench applied = Wrench::Zero();
  applied(2) = 0.6 * desc.model->rated()(2);
  const RoundTrip rt = RunChain(desc, applied, 400, 5);
  const Eigen::MatrixXd s = desc.model->Sensitivity();
  const Eigen::MatrixXd m = s.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::VectorXd db = Eigen::VectorXd::Zero(s.rows());
  db(0) = 0.01 * (s.row(0) * applied)(0);
  const Eigen::VectorXd dw = m * db;
  double worst_ratio = 0;
  for (int r = 0; r < 6; ++r)
    worst_ratio = std::max(worst_ratio, std::fabs(dw(r)) / rt.tolerance(r));
  EXPECT_GT(worst_ratio, 1.0);
}

}  // namespace
}  // namespace ftstack
