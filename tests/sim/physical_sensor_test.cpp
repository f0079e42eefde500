// The physical sensor model end to end: closed-form sensitivity, conditioning, temperature,
// the built-in sensor's design figures, and sensor description files with positioned errors.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "sim/default_sensor.hpp"
#include "sim/physical_sensor.hpp"
#include "sim/sensor_description.hpp"

namespace ftstack::sim {
namespace {

FlexureSensorSpec Spec(int beams) {
  FlexureSensorSpec s;
  s.body.beam_count = beams;
  s.body.hub_radius_m = 0.010;
  s.body.rim_radius_m = 0.035;
  s.body.beam_width_m = 0.0045;
  s.body.beam_height_m = 0.006;
  s.body.e_pa = 71.7e9;
  s.body.poisson = 0.33;
  s.body.rim_compliance = {5e-6, 0, 0, 0, 0, 0};
  s.gauge.resistance_ohm = 350;
  s.gauge.gauge_factor = 2.05;
  s.gauge.transverse_sensitivity = 0.004;
  s.rated = DefaultRated();
  BridgeCircuit c;
  c.excitation_v = 3.3;
  AddBendingBridges(&s, 0.022, c);
  return s;
}

class PhysicalBeams : public ::testing::TestWithParam<int> {};

// Fz on n guided beams: moment (Fz/n)(L/2 − s), strain M·c/(E·I) at the gauges, four active arms
// at ±ε with transverse strain −ν·ε: output = 1000·GF·(1 − ν·Kt)/(1 − ν₀·Kt)·ε mV/V.
TEST_P(PhysicalBeams, FzSensitivityFollowsTheClosedFormChain) {
  const int n = GetParam();
  const FlexureSensorSpec spec = Spec(n);
  const PhysicalSensorModel m(spec);
  const double l = 0.025;
  const double s = 0.022;
  const double h = spec.body.beam_height_m;
  const double iy = spec.body.beam_width_m * h * h * h / 12;
  const double eps_per_n = (1.0 / n) * (l / 2 - s) * (h / 2) / (spec.body.e_pa * iy);
  const GaugeType& g = spec.gauge;
  const double expect = 1000 * g.gauge_factor * (1 - spec.body.poisson * g.transverse_sensitivity) /
                        (1 - g.calibration_poisson * g.transverse_sensitivity) * eps_per_n;
  const Eigen::MatrixXd sens = m.Sensitivity();
  for (int b = 0; b < m.channel_count(); b += 2) {
    EXPECT_NEAR(sens(b, 2), expect, 1e-6 * std::abs(expect)) << "bridge " << b;
    EXPECT_NEAR(sens(b + 1, 2), 0.0, 1e-9 * std::abs(expect)) << "in-plane bridge " << b + 1;
  }
}

// With n-fold symmetry the rated-normalised sensitivity has orthogonal columns (each axis excites
// the beams with the pattern 1, cos θ_i, sin θ_i), so its singular values are the column norms and
// the condition number is their ratio.
TEST_P(PhysicalBeams, ConditionNumberIsTheRatioOfOrthogonalColumnNorms) {
  const PhysicalSensorModel m(Spec(GetParam()));
  const DesignReport r = m.Report();
  const Eigen::MatrixXd& a = r.rated_output_mvv;
  const Eigen::MatrixXd gram = a.transpose() * a;
  const Eigen::VectorXd norms = gram.diagonal().cwiseSqrt();
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      if (i != j) {
        EXPECT_LT(std::abs(gram(i, j)), 1e-6 * norms(i) * norms(j)) << i << "," << j;
      }
    }
  }
  EXPECT_NEAR(r.condition_number, norms.maxCoeff() / norms.minCoeff(), 1e-6 * r.condition_number);
  EXPECT_LT(r.condition_number, 2.0);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

INSTANTIATE_TEST_SUITE_P(ThreeBeamAndMalteseCross, PhysicalBeams, ::testing::Values(3, 4));

TEST(PhysicalSensor, WarnsAboutOverstrainAndBadConditioning) {
  FlexureSensorSpec s = Spec(3);
  s.allowable_strain = 1e-4;
  s.body.rim_compliance = {0, 0, 0,
                           0, 0, 0};  // rigid rim: Fx, Fy go into axial load, poorly sensed
  s.max_condition_number = 5;
  const DesignReport r = PhysicalSensorModel(s).Report();
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_NE(r.warnings[0].find("exceeds the allowable"), std::string::npos);
  EXPECT_NE(r.warnings[1].find("badly conditioned"), std::string::npos);
  EXPECT_GT(r.condition_number, 5);
}

TEST(PhysicalSensor, TemperatureZeroCancelsInFullBridgesAndSpanFollowsModulusAndGaugeFactor) {
  FlexureSensorSpec s = Spec(3);
  s.gauge.thermal_output_per_k = 2e-6;
  s.gauge.gauge_factor_tc_per_k = 1e-4;
  s.gauge.self_heating_k_per_w = 30;
  s.modulus_tc_per_k = -3e-4;
  const PhysicalSensorModel m(s);
  EXPECT_LT(m.BridgeOutputs(Wrench::Zero(), 45.0).cwiseAbs().maxCoeff(), 1e-15);
  Wrench w = Wrench::Zero();
  w(2) = 200;
  const double b20 = m.BridgeOutputs(w, 20.0)(0);
  const double b45 = m.BridgeOutputs(w, 45.0)(0);
  // Gauges run 30 K/W × (1.65 V)²/350 Ω warmer than the body: their GF drifts with that too.
  const double sh = 1.65 * 1.65 / 350 * 30;
  const double gf_ratio = (1 + 1e-4 * (25 + sh)) / (1 + 1e-4 * sh);
  // The common thermal output c of all four arms divides the exact full-bridge output:
  // R(1 + c ± a) arms give a/(1 + c).
  const double c20 = 2.05 * (1 + 1e-4 * sh) * 2e-6 * sh;
  const double c45 = 2.05 * (1 + 1e-4 * (25 + sh)) * 2e-6 * (25 + sh);
  EXPECT_NEAR(b45 / b20, gf_ratio / (1 - 3e-4 * 25) * (1 + c20) / (1 + c45), 1e-9);
}

TEST(PhysicalSensor, QuarterBridgeSelfHeatingGivesTheClosedFormOffset) {
  FlexureSensorSpec s = Spec(3);
  s.gauge.thermal_output_per_k = 3e-6;
  s.gauge.self_heating_k_per_w = 50;
  s.bridges.resize(1);
  s.bridges[0].circuit.kind = BridgeKind::kQuarter;
  s.bridges[0].circuit.wiring = BridgeWiring::kThreeWire;
  s.bridges[0].arm_gauge = {0, -1, -1, -1};
  const PhysicalSensorModel m(s);
  const double dt = 1.65 * 1.65 / 350 * 50;  // K above the body
  const double x = 2.05 * 3e-6 * dt;         // ΔR/R of the gauge at zero load, 20 °C body
  EXPECT_NEAR(m.BridgeOutputs(Wrench::Zero(), 20.0)(0), 1000 * x / (4 + 2 * x), 1e-12);
}

TEST(PhysicalSensor, RejectsInconsistentBridges) {
  FlexureSensorSpec s = Spec(3);
  s.bridges[1].arm_gauge[2] = s.bridges[0].arm_gauge[0];  // one gauge in two arms
  EXPECT_THROW(PhysicalSensorModel{s}, std::invalid_argument);
  s = Spec(3);
  s.bridges[0].arm_gauge[3] = 999;
  EXPECT_THROW(PhysicalSensorModel{s}, std::invalid_argument);
  s = Spec(3);
  s.bridges.clear();
  EXPECT_THROW(PhysicalSensorModel{s}, std::invalid_argument);
}

// The built-in sensor meets its brief: rated ranges, 0.5–2 mV/V, inside the ADC span under the
// combined rated envelope, well conditioned, ~1e-4 of rated noise per axis.
TEST(DefaultSensor, MeetsItsDesignBrief) {
  const SensorDescription d = DefaultSensorDescription();
  const auto* m = dynamic_cast<const PhysicalSensorModel*>(d.model.get());
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->channel_count(), 6);
  EXPECT_EQ((m->rated() - DefaultRated()).norm(), 0.0);
  const DesignReport r = m->Report();
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
  EXPECT_LT(r.condition_number, 2.0);
  for (int j = 0; j < 6; ++j) {
    const double largest = r.rated_output_mvv.col(j).cwiseAbs().maxCoeff();
    EXPECT_GE(largest, 0.5) << "axis " << j;
    EXPECT_LE(largest, 2.0) << "axis " << j;
  }
  const AdcOperatingPoint op = MakeAdcOperatingPoint(d.adc_spec);
  EXPECT_LT(r.max_output_mvv, 0.95 * op.full_scale_mvv);
  EXPECT_DOUBLE_EQ(d.adc.noise_rms_mvv, kDefaultNoiseMvv);
  const Eigen::MatrixXd pinv = r.rated_output_mvv.completeOrthogonalDecomposition().pseudoInverse();
  for (int j = 0; j < 6; ++j) {
    const double frac = pinv.row(j).norm() * d.adc.noise_rms_mvv;  // of rated, RMS
    EXPECT_GT(frac, 0.5e-4) << "axis " << j;
    EXPECT_LT(frac, 2.0e-4) << "axis " << j;
  }
  // MakeDefaultSensor is the same physical model.
  const auto again = MakeDefaultSensor();
  Wrench w;
  w << 50, -30, 120, 2, -1, 0.5;
  EXPECT_EQ((again->BridgeOutputs(w, 25.0) - m->BridgeOutputs(w, 25.0)).norm(), 0.0);
}

TEST(DefaultSensor, ShippedFileIsTheCompiledInDescription) {
  std::ifstream in(std::string(FTSTACK_SOURCE_DIR) + "/sim/sensors/default.json");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(text, DefaultSensorJson());
  const SensorDescription d =
      LoadSensorDescription(std::string(FTSTACK_SOURCE_DIR) + "/sim/sensors/default.json");
  EXPECT_EQ(d.adc_spec.chip, AdcChip::kAds131m0x);
  EXPECT_EQ(d.adc.required_gain, 128u);
  EXPECT_EQ(d.adc.required_rate_hz, 0u);
  const hal::sim::SimAdcParams at2k = AdcParamsAt(d, 2000);
  EXPECT_EQ(at2k.required_rate_hz, 2000u);
  EXPECT_NEAR(at2k.noise_rms_mvv, 1.00e-3 / 3.3, 1e-15);  // datasheet: 1.00 µV at 2 kSPS, gain 128
  EXPECT_THROW((void)AdcParamsAt(d, 100), std::invalid_argument);
}

std::string ErrorOf(const std::string& text) {
  try {
    (void)ParseSensorDescription(text, "s.json");
  } catch (const SensorDescriptionError& e) {
    return e.what();
  }
  return "";
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(SensorDescriptionFile, ErrorsNameFileLineAndColumn) {
  const std::string base = DefaultSensorJson();
  // The line and column of "beam_width_m"'s value in the shipped text.
  auto where = [&](const std::string& key) {
    const std::size_t at = base.find(key);
    const std::size_t value = base.find_first_not_of(" :", at + key.size() + 1);
    int line = 1;
    std::size_t line_start = 0;
    for (std::size_t i = 0; i < value; ++i) {
      if (base[i] == '\n') {
        ++line;
        line_start = i + 1;
      }
    }
    return "s.json:" + std::to_string(line) + ":" + std::to_string(value - line_start + 1) + ": ";
  };
  std::string e = ErrorOf(Replace(base, "\"beam_width_m\": 0.0045", "\"beam_width_m\": -0.0045"));
  EXPECT_EQ(e.rfind(where("\"beam_width_m\""), 0), 0u) << e;
  EXPECT_NE(e.find("must be > 0"), std::string::npos) << e;
  e = ErrorOf(Replace(base, "\"beam_width_m\": 0.0045", "\"beam_width_m\": \"wide\""));
  EXPECT_EQ(e.rfind(where("\"beam_width_m\""), 0), 0u) << e;
  e = ErrorOf(Replace(base, "\"gauge_factor\": 2.05", "\"gauge_factr\": 2.05"));
  EXPECT_NE(e.find("unknown key 'gauge_factr'"), std::string::npos) << e;
  e = ErrorOf(Replace(base, "\"face\": \"top\"", "\"face\": \"upper\""));
  EXPECT_EQ(e.rfind(where("\"face\""), 0), 0u) << e;
  e = ErrorOf(Replace(base, "\"rate_hz\": 1000", "\"rate_hz\": 100"));
  EXPECT_NE(e.find("250"), std::string::npos) << e;
  e = ErrorOf(Replace(base, "\"beams\": 3", "\"beams\": 5"));
  EXPECT_NE(e.find("integer in 3 … 4"), std::string::npos) << e;
  e = ErrorOf(Replace(base, "\"rim_radius_m\": 0.035", "\"rim_radius_m\": 1e999"));
  EXPECT_EQ(e.rfind("s.json:", 0), 0u) << e;
  // Syntax: a missing comma on line 3.
  e = ErrorOf("{\n  \"schema\": \"ftstack-sensor/1\",\n  \"name\": \"x\"\n  \"model\": {}\n}\n");
  EXPECT_EQ(e.rfind("s.json:4:", 0), 0u) << e;
  EXPECT_EQ(ErrorOf(base), "");
}

TEST(SensorDescriptionFile, LinearModelsStillLoad) {
  const std::string text =
      R"({"schema": "ftstack-sensor/1", "name": "lin", "model": {"type": "linear",
    "sensitivity_mvv": [[0.001, 0, 0, 0, 0, 0], [0, 0.001, 0, 0, 0, 0]]},
    "adc": {"noise_mvv": 2e-4, "bits": 20}})";
  const SensorDescription d = ParseSensorDescription(text, "lin.json");
  EXPECT_EQ(d.model->channel_count(), 2);
  EXPECT_DOUBLE_EQ(d.adc.noise_rms_mvv, 2e-4);
  EXPECT_EQ(d.adc.resolution_bits, 20);
  EXPECT_EQ(d.adc.required_rate_hz, 0u);
}

}  // namespace
}  // namespace ftstack::sim
