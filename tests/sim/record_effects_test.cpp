// Each injected effect's residual (real − sim, noise off) against the effect's closed form.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "record_test_util.hpp"

namespace ftstack::sim {
namespace {

using namespace testing_util;

// Without noise the only difference between the quantised real output and an exact value is the
// ADC rounding: at most half a step (plus the 10-digit CSV precision, far below that).
const double kTol = 0.5 * Lsb() + 1e-12;

TEST(RecordEffects, NoneEqualsModelWithinQuantisation) {
  const RecordResult r = MakeRecording(TestRequest("rig", {"none"}, 60.0));
  ASSERT_EQ(r.real.rows(), 12001u);
  for (int ch = 0; ch < 6; ++ch) {
    for (const double v : Residual(r, ch)) ASSERT_LE(std::abs(v), kTol);
  }
  // The sim column is the model evaluated on the recorded wrench.
  const Eigen::MatrixXd s = TestSensitivity();
  for (std::size_t i = 0; i < r.sim.rows(); i += 97) {
    const Eigen::VectorXd b = s * WrenchAt(r.sim, i) + TestZero();
    for (int ch = 0; ch < 6; ++ch)
      ASSERT_NEAR(r.sim.Column("b" + std::to_string(ch))[i], b(ch), 1e-9);
  }
  EXPECT_TRUE(r.truth["effects"].empty());
  EXPECT_EQ(r.truth["strongest"], "none");
}

TEST(RecordEffects, ZeroOffsetPerChannel) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"zero_offset:offset=[3e-4,-2e-4],channels=[1,4]"}, 30.0));
  const double want[6] = {0, 3e-4, 0, 0, -2e-4, 0};
  for (int ch = 0; ch < 6; ++ch) {
    for (const double v : Residual(r, ch)) ASSERT_NEAR(v, want[ch], kTol);
  }
  EXPECT_EQ(r.truth["effects"][0]["footprint"]["channels"], nlohmann::json::array({1, 4}));
}

TEST(RecordEffects, ZeroOffsetDefaultsMatchTruth) {
  const RecordResult r = MakeRecording(TestRequest("rig", {"zero_offset"}, 20.0));
  const auto& off = r.truth["effects"][0]["params"]["offset"];
  for (int ch = 0; ch < 6; ++ch) {
    const double o = off[static_cast<std::size_t>(ch)];
    EXPECT_GE(std::abs(o), 3e-4);  // a few noise sigma of the built-in read-out (1e-4 mV/V)
    EXPECT_LE(std::abs(o), 6e-4);
    for (const double v : Residual(r, ch)) ASSERT_NEAR(v, o, kTol);
  }
}

TEST(RecordEffects, ZeroDriftIsSlowWanderOfRequestedRms) {
  const double amp = 4e-4;
  const double corner = 0.02;
  const RecordResult r = MakeRecording(
      TestRequest("rig", {"zero_drift:amplitude=4e-4,corner_hz=0.02,channels=[0,3]"}, 200.0));
  const auto& t = r.real.Column("t");
  for (int ch = 0; ch < 6; ++ch) {
    const auto d = Residual(r, ch);
    double ss = 0.0;
    for (const double v : d) ss += v * v;
    const double rms = std::sqrt(ss / static_cast<double>(d.size()));
    if (ch != 0 && ch != 3) {
      EXPECT_LE(rms, kTol);
      continue;
    }
    EXPECT_NEAR(rms, amp, kTol);  // scaled to the RMS exactly; rounding moves it by < half a step
    EXPECT_NEAR(d[0], 0.0, kTol);
    // Only frequencies up to corner_hz: Hann-windowed DFT (every 50th sample, 4 Hz) — the power
    // beyond 3 × corner_hz is leakage, below the window's -31 dB first side lobe.
    std::vector<double> x;
    for (std::size_t i = 0; i < d.size(); i += 50) x.push_back(d[i]);
    const double span = t[(x.size() - 1) * 50];
    double lo = 0.0;
    double hi = 0.0;
    const std::size_t m = x.size();
    for (std::size_t k = 1; k < m / 2; ++k) {
      std::complex<double> acc = 0.0;
      for (std::size_t i = 0; i < m; ++i) {
        const double hann = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                                 static_cast<double>(m - 1));
        acc += hann * x[i] *
               std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(k * i) /
                                   static_cast<double>(m));
      }
      const double f = static_cast<double>(k) / span;
      (f > 3.0 * corner ? hi : lo) += std::norm(acc);
    }
    EXPECT_LT(hi / (lo + hi), 1e-3) << "channel " << ch;
  }
  // Two channels wander independently.
  const auto a = Residual(r, 0);
  const auto b = Residual(r, 3);
  double ab = 0, aa = 0, bb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += a[i] * b[i];
    aa += a[i] * a[i];
    bb += b[i] * b[i];
  }
  EXPECT_LT(std::abs(ab / std::sqrt(aa * bb)), 0.999);
}

TEST(RecordEffects, ThermalZeroDriftFollowsTemperature) {
  const RecordResult r = MakeRecording(TestRequest(
      "thermal", {"thermal_zero_drift:coef_per_K=[5e-5,-7e-5],channels=[2,5],t0_c=20"}, 120.0));
  const auto res_r = Residuals(r);
  const auto& temp = r.real.Column("temp_C");
  EXPECT_GT(*std::max_element(temp.begin(), temp.end()) - temp.front(), 2.0);
  // temp_C is written in steps of 1 m°C: allow coef · 0.5 mK on top of the rounding.
  for (std::size_t i = 0; i < temp.size(); ++i) {
    ASSERT_NEAR(res_r[2][i], 5e-5 * (temp[i] - 20.0), kTol + 5e-5 * 5e-4);
    ASSERT_NEAR(res_r[5][i], -7e-5 * (temp[i] - 20.0), kTol + 7e-5 * 5e-4);
    ASSERT_NEAR(res_r[0][i], 0.0, kTol);
  }
}

TEST(RecordEffects, ThermalSpanDriftScalesTheLoadPart) {
  const double c = -2e-4;
  const RecordResult r =
      MakeRecording(TestRequest("thermal", {"thermal_span_drift:coef_per_K=-2e-4"}, 120.0));
  const auto res_r = Residuals(r);
  const auto& temp = r.real.Column("temp_C");
  const double t0 = r.truth["effects"][0]["params"]["t0_c"];
  EXPECT_NEAR(t0, temp.front(), 5e-4);
  const Eigen::MatrixXd s = TestSensitivity();
  double peak = 0.0;
  for (std::size_t i = 0; i < temp.size(); ++i) {
    const Eigen::VectorXd load = s * WrenchAt(r.sim, i);
    for (int ch = 0; ch < 6; ++ch) {
      const double want = c * (temp[i] - t0) * load(ch);
      ASSERT_NEAR(res_r[ch][i], want, kTol + std::abs(c * load(ch)) * 1e-3);
      peak = std::max(peak, std::abs(want));
    }
  }
  EXPECT_GT(peak, 1e-4);
}

TEST(RecordEffects, ExcitationDriftIsOneCommonFactor) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"excitation_drift:amplitude=2e-3"}, 120.0));
  const auto res_r = Residuals(r);
  std::vector<double> e;
  for (std::size_t i = 0; i < r.real.rows(); ++i) {
    int big = 0;
    double bmax = 0.0;
    for (int ch = 0; ch < 6; ++ch) {
      const double b = std::abs(r.sim.Column("b" + std::to_string(ch))[i]);
      if (b > bmax) {
        bmax = b;
        big = ch;
      }
    }
    if (bmax < 0.2) continue;
    const double f = res_r[big][i] / r.sim.Column("b" + std::to_string(big))[i];
    e.push_back(f);
    for (int ch = 0; ch < 6; ++ch) {
      const double b = r.sim.Column("b" + std::to_string(ch))[i];
      ASSERT_NEAR(res_r[ch][i], f * b, kTol * (1.0 + std::abs(b) / bmax));
    }
  }
  ASSERT_GT(e.size(), 1000u);
  double m = 0.0;
  for (const double v : e) m = std::max(m, std::abs(v));
  EXPECT_GT(m, 5e-4);
  EXPECT_LT(m, 10 * 2e-3);
}

// First-order lag of a ramp: g(s) = s − τ(1 − e^{−s/τ}) for s > 0, 0 before.
double LagRamp(double s, double tau) { return s <= 0 ? 0.0 : s - tau * (1.0 - std::exp(-s / tau)); }

TEST(RecordEffects, CreepFollowsFirstOrderStepResponseAndRecovers) {
  const double tau = 12.0;
  const double frac = 4e-3;
  const Wrench w = Along(2, 300.0) + Along(3, 5.0);
  const std::string p =
      WriteProfile("creep_step", {0, 1.0, 1.5, 60.0, 60.5, 120.0},
                   {Wrench::Zero(), Wrench::Zero(), w, w, Wrench::Zero(), Wrench::Zero()}, 100.0);
  const RecordResult r = MakeRecording(TestRequest(p, {"creep:tau_s=12,fraction=4e-3"}));
  const auto res_r = Residuals(r);
  const auto& t = r.real.Column("t");
  const Eigen::VectorXd load = TestSensitivity() * w;
  for (std::size_t i = 0; i < t.size(); ++i) {
    // Superposed ramp responses: up over [1, 1.5] s, down over [60, 60.5] s.
    const double x = (LagRamp(t[i] - 1.0, tau) - LagRamp(t[i] - 1.5, tau) -
                      LagRamp(t[i] - 60.0, tau) + LagRamp(t[i] - 60.5, tau)) /
                     0.5;
    for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], frac * load(ch) * x, kTol) << t[i];
  }
  // After the step: 1 − C·e^{−(t − 1.5)/τ} of the final creep, C = τ/T_r·(1 − e^{−T_r/τ}).
  const double c = tau / 0.5 * (1.0 - std::exp(-0.5 / tau));
  const std::size_t i = 100 * 25;  // t = 25 s
  EXPECT_NEAR(res_r[2][i], frac * load(2) * (1.0 - c * std::exp(-(25.0 - 1.5) / tau)), kTol);
}

TEST(RecordEffects, HysteresisMatchesPlayOperatorBranchesAndIsRateIndependent) {
  const double rated = TestRated()(0);
  const double a = 2e-3;
  const double width = 0.5;
  const double peak = 0.8 * rated;
  auto run = [&](double stretch) {
    const std::string p =
        WriteProfile("hyst" + std::to_string(static_cast<int>(stretch)),
                     {0, 1, 1 + 8 * stretch, 1 + 24 * stretch, 1 + 32 * stretch, 2 + 32 * stretch},
                     {Wrench::Zero(), Wrench::Zero(), Along(0, peak), Along(0, -peak),
                      Wrench::Zero(), Wrench::Zero()},
                     100.0);
    return MakeRecording(TestRequest(p, {"hysteresis:amplitude=2e-3,width=0.5"}));
  };
  const RecordResult r = run(1.0);
  const auto res_r = Residuals(r);
  const Eigen::VectorXd s0 = TestSensitivity().col(0);
  // Closed forms of the mean of 8 normalised plays (thresholds r_j = width·rated·j/8), starting
  // relaxed at zero: rising from 0, term_j = −min(w, r_j)/r_j; falling from the peak W,
  // term_j = min(W − r_j − w, r_j)/r_j.
  auto rising = [&](double w) {
    double sum = 0;
    for (int j = 1; j <= 8; ++j)
      sum -= std::min(w, width * rated * j / 8) / (width * rated * j / 8);
    return a * rated * sum / 8;
  };
  auto falling = [&](double w) {
    double sum = 0;
    for (int j = 1; j <= 8; ++j) {
      const double rj = width * rated * j / 8;
      sum += std::min(peak - rj - w, rj) / rj;
    }
    return a * rated * sum / 8;
  };
  const auto& t = r.real.Column("t");
  const auto& fx = r.sim.Column("Fx");
  int checked = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    double dw = NAN;
    if (t[i] >= 1.0 && t[i] <= 9.0) dw = rising(fx[i]);
    if (t[i] >= 9.0 && t[i] <= 25.0) dw = falling(fx[i]);
    if (std::isnan(dw)) continue;
    for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], s0(ch) * dw, kTol) << t[i];
    ++checked;
  }
  EXPECT_GT(checked, 2000);
  // Same load reached from below and from above differs by the loop (here at Fx = 0.4 rated).
  EXPECT_GT(falling(0.4 * rated) - rising(0.4 * rated), 1.0 * a * rated);
  // Rate independence: three times slower gives the same residual at the same point of the cycle.
  const RecordResult slow = run(3.0);
  const auto res_slow = Residuals(slow);
  for (std::size_t i = 100; i < t.size(); i += 7) {
    const std::size_t j = 100 + (i - 100) * 3;
    if (j >= slow.real.rows() || t[i] > 33.0) break;
    ASSERT_NEAR(slow.sim.Column("Fx")[j], fx[i], 1e-6);
    ASSERT_NEAR(res_slow[0][j], res_r[0][i], 2 * kTol);
  }
}

TEST(RecordEffects, BridgeNonlinearityIsQuadraticOnChosenChannels) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"bridge_nonlinearity:channels=[2],coef=-2e-3"}, 60.0));
  const auto res_r = Residuals(r);
  const auto& b2 = r.sim.Column("b2");
  for (std::size_t i = 0; i < b2.size(); ++i) {
    ASSERT_NEAR(res_r[2][i], -2e-3 * b2[i] * b2[i], kTol);
    ASSERT_NEAR(res_r[1][i], 0.0, kTol);
  }
  // The default picks one channel (per seed) with the quarter-bridge coefficient −2e-3 per mV/V.
  const RecordResult d = MakeRecording(TestRequest("rig", {"bridge_nonlinearity"}, 10.0));
  EXPECT_EQ(d.truth["effects"][0]["params"]["channels"].size(), 1u);
  EXPECT_DOUBLE_EQ(d.truth["effects"][0]["params"]["coef"].get<double>(), -2e-3);
}

TEST(RecordEffects, GeometricNonlinearityIsCubicInLoad) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"geometric_nonlinearity:coef=-4e-3"}, 80.0));
  const auto res_r = Residuals(r);
  const Eigen::MatrixXd s = TestSensitivity();
  const Wrench rated = TestRated();
  for (std::size_t i = 0; i < r.real.rows(); ++i) {
    const Wrench w = WrenchAt(r.sim, i);
    Wrench dw;
    for (int k = 0; k < 6; ++k) dw(k) = -4e-3 * std::pow(w(k) / rated(k), 3) * rated(k);
    const Eigen::VectorXd want = s * dw;
    for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], want(ch), kTol);
  }
}

TEST(RecordEffects, LoadStiffeningNeedsAxialLoadAndBending) {
  const RecordResult r = MakeRecording(TestRequest("rig", {"load_stiffening:coef=-0.01"}, 0.0));
  const auto res_r = Residuals(r);
  const Eigen::MatrixXd s = TestSensitivity();
  const Wrench rated = TestRated();
  double combined_peak = 0.0;
  for (std::size_t i = 0; i < r.real.rows(); ++i) {
    const Wrench w = WrenchAt(r.sim, i);
    Wrench dw = Wrench::Zero();
    for (const int k : {0, 1, 3, 4}) dw(k) = -0.01 * w(2) / rated(2) * w(k);
    const Eigen::VectorXd want = s * dw;
    for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], want(ch), kTol);
    combined_peak = std::max(combined_peak, want.cwiseAbs().maxCoeff());
  }
  EXPECT_GT(combined_peak, 5e-4);  // the rig's preload × moment section shows it
}

TEST(RecordEffects, MisalignmentIsAFrameRotation) {
  for (const char* axis : {"x", "y", "z"}) {
    const RecordResult r = MakeRecording(
        TestRequest("rig", {std::string("misalignment:axis=") + axis + ",angle_deg=0.4"}, 60.0));
    const auto res_r = Residuals(r);
    const double th = 0.4 * std::numbers::pi / 180.0;
    const double c = std::cos(th);
    const double sn = std::sin(th);
    Eigen::Matrix3d rot;  // rotation of the sensor frame about the axis (right hand)
    if (axis[0] == 'x') rot << 1, 0, 0, 0, c, -sn, 0, sn, c;
    if (axis[0] == 'y') rot << c, 0, sn, 0, 1, 0, -sn, 0, c;
    if (axis[0] == 'z') rot << c, -sn, 0, sn, c, 0, 0, 0, 1;
    const Eigen::MatrixXd s = TestSensitivity();
    for (std::size_t i = 0; i < r.real.rows(); i += 3) {
      const Wrench w = WrenchAt(r.sim, i);
      Wrench seen;
      seen.head<3>() = rot.transpose() * w.head<3>();
      seen.tail<3>() = rot.transpose() * w.tail<3>();
      const Eigen::VectorXd want = s * (seen - w);
      for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], want(ch), kTol) << axis;
    }
    EXPECT_EQ(r.truth["effects"][0]["params"]["axis"], axis);
  }
}

TEST(RecordEffects, GainErrorScalesOneChannelsLoadPart) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"gain_error:channels=[4],gain=1.003"}, 60.0));
  const auto res_r = Residuals(r);
  const Eigen::MatrixXd s = TestSensitivity();
  for (std::size_t i = 0; i < r.real.rows(); ++i) {
    const double load = s.row(4).dot(WrenchAt(r.sim, i));
    ASSERT_NEAR(res_r[4][i], 3e-3 * load, kTol);
    ASSERT_NEAR(res_r[0][i], 0.0, kTol);
  }
}

TEST(RecordEffects, TimeSkewDelaysByInterpolation) {
  // Slow ramps with keyframes away from most samples; 1.5 samples of delay at 200 Hz.
  const std::vector<double> kt = {0, 1, 3, 5, 7, 9, 10};
  const std::vector<Wrench> kw = {Wrench::Zero(), Wrench::Zero(), Along(1, 150) + Along(4, -6),
                                  Along(1, -120), Along(5, 7),    Wrench::Zero(),
                                  Wrench::Zero()};
  const std::string p = WriteProfile("skew", kt, kw, 200.0);
  const double d = 0.0075;
  const RecordResult r = MakeRecording(TestRequest(p, {"time_skew:delay_s=0.0075"}));
  const auto& t = r.real.Column("t");
  int checked = 0;
  for (std::size_t i = 2; i < t.size(); ++i) {
    // Linear interpolation of the sim between samples is exact where no keyframe lies between.
    bool near_key = false;
    for (const double k : kt) near_key = near_key || (k > t[i] - d - 0.006 && k < t[i] + 1e-9);
    if (near_key) continue;
    const double x = (t[i] - d) * 200.0;
    const auto j = static_cast<std::size_t>(std::floor(x));
    const double f = x - static_cast<double>(j);
    for (int ch = 0; ch < 6; ++ch) {
      const auto& b = r.sim.Column("b" + std::to_string(ch));
      ASSERT_NEAR(r.real.Column("b" + std::to_string(ch))[i], (1 - f) * b[j] + f * b[j + 1],
                  kTol + 1e-12);
    }
    ++checked;
  }
  EXPECT_GT(checked, 1800);
}

TEST(RecordEffects, SaturationClipsAtTheLimit) {
  const RecordResult r = MakeRecording(TestRequest("rig", {"saturation:limit=0.35"}, 80.0));
  std::size_t clipped = 0;
  for (int ch = 0; ch < 6; ++ch) {
    const auto& b = r.sim.Column("b" + std::to_string(ch));
    for (std::size_t i = 0; i < b.size(); ++i) {
      ASSERT_NEAR(r.real.Column("b" + std::to_string(ch))[i], std::clamp(b[i], -0.35, 0.35), kTol);
      clipped += std::abs(b[i]) > 0.35;
    }
  }
  EXPECT_GT(clipped, 100u);
  // Default: 0.9 × the 99.5th percentile of |output| over the record, so the largest loads clip.
  const RecordResult d = MakeRecording(TestRequest("rig", {"saturation"}, 0.0));
  const double lim = d.truth["effects"][0]["params"]["limit"];
  std::size_t over = 0;
  for (std::size_t i = 0; i < d.sim.rows(); ++i) {
    double m = 0;
    for (int ch = 0; ch < 6; ++ch)
      m = std::max(m, std::abs(d.sim.Column("b" + std::to_string(ch))[i]));
    over += m > lim;
  }
  EXPECT_GT(over, d.sim.rows() / 200);
}

TEST(RecordEffects, OverloadShiftAfterTheOverload) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"overload_shift:onset_s=50,shift=8e-4,axis=Fz"}, 100.0));
  const auto res_r = Residuals(r);
  const auto& t = r.real.Column("t");
  const auto& fz = r.sim.Column("Fz");
  const std::size_t on = 50 * 200;
  ASSERT_DOUBLE_EQ(t[on], 50.0);
  EXPECT_NEAR(fz[on], 1.6 * 400.0, 1e-9);  // the profile really contains the overload
  const Eigen::VectorXd col = TestSensitivity().col(2);
  const Eigen::VectorXd shift = 8e-4 * col / col.cwiseAbs().maxCoeff();
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (int ch = 0; ch < 6; ++ch) ASSERT_NEAR(res_r[ch][i], i >= on ? shift(ch) : 0.0, kTol);
  }
  EXPECT_DOUBLE_EQ(r.truth["effects"][0]["params"]["onset_s"].get<double>(), 50.0);
}

TEST(RecordEffects, MainsInterferenceAmplitudeByDft) {
  // Exact without noise …
  const RecordResult r = MakeRecording(
      TestRequest("rig", {"mains_interference:freq_hz=60,amplitude=3e-4,phase_deg=30"}, 20.0));
  const auto res_r = Residuals(r);
  const auto& t = r.real.Column("t");
  for (std::size_t i = 0; i < t.size(); ++i) {
    ASSERT_NEAR(res_r[3][i],
                3e-4 * std::sin(2 * std::numbers::pi * 60 * t[i] + std::numbers::pi / 6), kTol);
  }
  // … and found by a DFT under noise: amplitude error ~ σ·√(2/n) per channel.
  RecordRequest q = TestRequest("rig", {"mains_interference:amplitude=2.5e-4"}, 50.0);
  q.noise_mvv = 1e-4;
  const RecordResult n = MakeRecording(q);
  const auto& tn = n.real.Column("t");
  const std::size_t m = tn.size() - 1;  // 50 s = 2500 whole cycles of 50 Hz
  for (int ch = 0; ch < 6; ++ch) {
    const auto d = Residual(n, ch);
    std::complex<double> acc = 0;
    for (std::size_t i = 0; i < m; ++i)
      acc += d[i] * std::polar(1.0, -2 * std::numbers::pi * 50 * tn[i]);
    const double amp = 2.0 * std::abs(acc) / static_cast<double>(m);
    EXPECT_NEAR(amp, 2.5e-4, 5 * 1e-4 * std::sqrt(2.0 / static_cast<double>(m)));
  }
}

// Unit-ramp response of ω²/(s² + 2ζωs + ω²).
double RampResponse(double s, double wn, double z) {
  if (s <= 0) return 0.0;
  const double wd = wn * std::sqrt(1 - z * z);
  return s - 2 * z / wn +
         std::exp(-z * wn * s) *
             (2 * z / wn * std::cos(wd * s) + (2 * z * z - 1) / wd * std::sin(wd * s));
}

TEST(RecordEffects, ResonanceRingsAsSecondOrderSystem) {
  // A one-sample (5 ms) step up at 1 s and down at 3 s.
  const Wrench w = Along(0, 120.0) + Along(5, 4.0);
  const std::string p =
      WriteProfile("ring", {0, 1.0, 1.005, 3.0, 3.005, 6.0},
                   {Wrench::Zero(), Wrench::Zero(), w, w, Wrench::Zero(), Wrench::Zero()}, 200.0);
  const double wn = 2 * std::numbers::pi * 18;
  const Eigen::VectorXd load = TestSensitivity() * w;
  // Whole output through the mode, and a 3 % modal share on channels 0 and 5 only.
  for (const double share : {1.0, 0.03}) {
    const std::string spec =
        "resonance:freq_hz=18,damping_ratio=0.05,participation=" + std::to_string(share) +
        (share < 1 ? ",channels=[0,5]" : "");
    const RecordResult r = MakeRecording(TestRequest(p, {spec}));
    const auto res_r = Residuals(r);
    const auto& t = r.real.Column("t");
    double ring = 0;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double x = (RampResponse(t[i] - 1.0, wn, 0.05) - RampResponse(t[i] - 1.005, wn, 0.05) -
                        RampResponse(t[i] - 3.0, wn, 0.05) + RampResponse(t[i] - 3.005, wn, 0.05)) /
                       0.005;
      const Eigen::VectorXd quasi = TestSensitivity() * WrenchAt(r.sim, i);
      for (int ch = 0; ch < 6; ++ch) {
        const double want =
            (share == 1.0 || ch == 0 || ch == 5) ? share * (load(ch) * x - quasi(ch)) : 0.0;
        ASSERT_NEAR(res_r[ch][i], want, kTol + 1e-10) << spec << " t=" << t[i];
      }
      if (t[i] > 1.5 && t[i] < 2.5) ring = std::max(ring, std::abs(res_r[0][i]));
    }
    EXPECT_GT(ring, 0.05 * share * load(0))
        << spec;  // still ringing 0.5 s after the step (ζ = 0.05)
  }
}

TEST(RecordEffects, EffectsCombineAdditivelyWhenIndependent) {
  const RecordResult r = MakeRecording(TestRequest(
      "rig", {"zero_offset:offset=2e-4", "mains_interference:amplitude=1e-4,channels=[1]"}, 10.0));
  const auto res_r = Residuals(r);
  const auto& t = r.real.Column("t");
  for (std::size_t i = 0; i < t.size(); ++i) {
    ASSERT_NEAR(res_r[1][i], 2e-4 + 1e-4 * std::sin(2 * std::numbers::pi * 50 * t[i]), kTol);
    ASSERT_NEAR(res_r[2][i], 2e-4, kTol);
  }
  EXPECT_EQ(r.truth["effects"].size(), 2u);
}

TEST(RecordEffects, ConverterGlitchesAreIsolatedWrongCodesOnTheChosenChannels) {
  RecordRequest q =
      TestRequest("thermal", {"converter_glitch:count=9,offset_mvv=0.03,channels=[2,5]"}, 60.0);
  const RecordResult r = MakeRecording(q);
  int found = 0;
  for (int ch = 0; ch < 6; ++ch) {
    const auto res = Residual(r, ch);
    for (std::size_t i = 0; i < res.size(); ++i) {
      if (std::abs(res[i]) < 0.015) continue;
      ++found;
      EXPECT_TRUE(ch == 2 || ch == 5) << ch;
      EXPECT_NEAR(std::abs(res[i]), 0.03, 0.001);  // the offset, give or take noise
      if (i > 0) {
        EXPECT_LT(std::abs(res[i - 1]), 0.015);
      }
      if (i + 1 < res.size()) {
        EXPECT_LT(std::abs(res[i + 1]), 0.015);
      }
    }
  }
  EXPECT_EQ(found, 9);
  EXPECT_THROW((void)MakeRecording(TestRequest("thermal", {"converter_glitch:count=2.5"}, 10.0)),
               std::exception);
}

TEST(RecordEffects, EveryVocabularyNameInjectsWithDefaults) {
  // The spec's vocabulary, written out independently of the implementation's table.
  const std::vector<std::string> vocab = {"none",
                                          "zero_offset",
                                          "zero_drift",
                                          "thermal_zero_drift",
                                          "thermal_span_drift",
                                          "excitation_drift",
                                          "creep",
                                          "hysteresis",
                                          "bridge_nonlinearity",
                                          "geometric_nonlinearity",
                                          "load_stiffening",
                                          "misalignment",
                                          "gain_error",
                                          "time_skew",
                                          "saturation",
                                          "overload_shift",
                                          "mains_interference",
                                          "resonance",
                                          "converter_glitch"};
  EXPECT_EQ(EffectNames(), vocab);
  for (const auto& name : vocab) {
    RecordRequest q = TestRequest("thermal", {name}, 120.0);
    const RecordResult r = MakeRecording(q);
    double peak = 0;
    for (int ch = 0; ch < 6; ++ch) {
      for (const double v : Residual(r, ch)) peak = std::max(peak, std::abs(v));
    }
    if (name == "none") {
      EXPECT_LE(peak, kTol);
      continue;
    }
    // Defaults are sized at a few noise sigma of the built-in read-out (1e-4 mV/V) or more.
    EXPECT_GT(peak, 2e-4) << name;
    EXPECT_EQ(r.truth["effects"][0]["name"], name);
    EXPECT_FALSE(r.truth["effects"][0]["footprint"]["windows"].empty()) << name;
  }
}

}  // namespace
}  // namespace ftstack::sim
