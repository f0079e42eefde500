// ftdiag core: numerical blocks against closed forms, and diagnoses of closed-form fixtures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>

#include <unistd.h>

#include "diagnosis/effects/families.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/signal.hpp"
#include "diagnosis/filters/lowpass.hpp"
#include "diagnosis/loader/data.hpp"
#include "diagnosis/report/html_report.hpp"
#include "diagnosis/report/json_report.hpp"
#include "tests/diagnosis/diag_fixture.hpp"
#include "tests/diagnosis/random_sensor.hpp"

namespace ftstack::diag {
namespace {

// The registry holds one plug-in per effect of the vocabulary (docs/spec/diagnosis.md), in its
// order, each named by its kind; the engine's trait look-ups find the effects the spec describes.
TEST(DiagRegistry, OnePluginPerVocabularyEffectInOrder) {
  const auto& effects = Effects();
  ASSERT_EQ(effects.size() + 1, kEffectVocabulary.size());
  for (std::size_t i = 0; i < effects.size(); ++i) {
    EXPECT_EQ(effects[i].kind, kEffectVocabulary[i + 1].kind);
    EXPECT_EQ(std::string(effects[i].name), kEffectVocabulary[i + 1].name);
    EXPECT_NE(effects[i].fit, nullptr) << effects[i].name;
    EXPECT_EQ(FindEffect(effects[i].name), &effects[i]);
  }
  ASSERT_NE(FindEffectWith(kDriftInTime), nullptr);
  EXPECT_STREQ(FindEffectWith(kDriftInTime)->name, "zero_drift");
  EXPECT_TRUE(FindEffect("hysteresis")->Has(kLoadHistory));
  EXPECT_TRUE(FindEffect("thermal_span_drift")->Has(kNeedsTemperature | kTimeBased));
  EXPECT_FALSE(FindEffect("creep")->Has(kTimeBased));
  EXPECT_EQ(FindEffect("undetermined"), nullptr);
}

constexpr double kNoise = 1e-4;

TEST(DiagSignal, RobustNoiseIgnoresDriftAndLines) {
  // White noise σ plus a drift of 20 σ and a 50 Hz line of 10 σ: the median Welch level sees σ.
  const std::size_t n = 60000;
  const double rate = 200.0;
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate;
    x[i] = kNoise * g(rng) + 20 * kNoise * std::sin(2 * M_PI * t / 200.0) +
           10 * kNoise * std::sin(2 * M_PI * 50.0 * t);
  }
  // Relative SE of the median over ~230 bins of ~110-segment averages is ~1 % on σ²; allow 3 % on
  // σ.
  EXPECT_NEAR(RobustNoise(x.data(), n, rate), kNoise, 0.03 * kNoise);
}

TEST(DiagSignal, FirstOrderLowPassMatchesRampResponse) {
  // x = t from rest: y = t − τ(1 − e^{−t/τ}); the discretisation is exact for piecewise-linear
  // input.
  const double tau = 0.7;
  std::vector<double> t(500);
  std::vector<double> x(500);
  std::vector<double> y(500);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = x[i] = 0.01 * static_cast<double>(i);
  FirstOrderLowPass(t.data(), x.data(), t.size(), tau, y.data());
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_NEAR(y[i], t[i] - tau * (1 - std::exp(-t[i] / tau)), 1e-12);
  }
}

TEST(DiagSignal, SecondOrderLowPassMatchesRampResponse) {
  // ÿ + 2ζωẏ + ω²y = ω²t from rest: y = t − 2ζ/ω + e^{−ζωt}(2ζ/ω·cos ω_d t + (2ζ² − 1)/ω_d·sin ω_d
  // t).
  const double f = 7.0;
  const double z = 0.05;
  const double w = 2 * M_PI * f;
  const double wd = w * std::sqrt(1 - z * z);
  std::vector<double> t(800);
  std::vector<double> y(800);
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = 0.004 * static_cast<double>(i);
  SecondOrderLowPass(t.data(), t.data(), t.size(), f, z, y.data());
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double e = std::exp(-z * w * t[i]);
    const double ref =
        t[i] - 2 * z / w +
        e * (2 * z / w * std::cos(wd * t[i]) + (2 * z * z - 1) / wd * std::sin(wd * t[i]));
    EXPECT_NEAR(y[i], ref, 1e-10);
  }
}

TEST(DiagSignal, NormalEquationsMatchQr) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd x(400, 4);
  Eigen::VectorXd y(400);
  NormalEq ne(4);
  for (int i = 0; i < 400; ++i) {
    for (int j = 0; j < 4; ++j) x(i, j) = g(rng) * (j + 1) * 1e-3;
    y(i) = g(rng);
    const Eigen::VectorXd row = x.row(i).transpose();
    ne.Add(row.data(), y(i));
  }
  const Eigen::VectorXd ref = x.colPivHouseholderQr().solve(y);
  const auto r = ne.Solve();
  for (int j = 0; j < 4; ++j) EXPECT_NEAR(r.beta(j), ref(j), 1e-9 * std::fabs(ref(j)) + 1e-9);
  EXPECT_NEAR(r.sse, (y - x * ref).squaredNorm(), 1e-9 * y.squaredNorm());
}

// A nested model's sums taken from the wider pass are those of its own pass, bit for bit (the
// creep variants with and without a gain term are fitted from one pass), for the unrolled row
// lengths and the wide one, weighted rows included; and its fit is the QR solution of its columns.
TEST(DiagSignal, LeadingSumsAreTheNarrowPassBitForBit) {
  std::mt19937 rng(9);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const int p : {2, 3, 4, 6}) {
    const int k = p - 1;
    Eigen::MatrixXd x(300, p);
    Eigen::VectorXd y(300);
    NormalEq wide(p);
    NormalEq narrow(k);
    for (int i = 0; i < 300; ++i) {
      for (int j = 0; j < p; ++j) x(i, j) = g(rng) * (j + 1);
      y(i) = g(rng);
      const double w = 0.5 + (i % 3);
      const Eigen::VectorXd row = x.row(i).transpose();
      wide.Add(row.data(), y(i), w);
      narrow.Add(row.data(), y(i), w);
    }
    const auto lead = wide.Leading(k).Solve();
    const auto own = narrow.Solve();
    ASSERT_EQ(lead.beta.size(), k);
    for (int j = 0; j < k; ++j) EXPECT_EQ(lead.beta(j), own.beta(j)) << "p " << p;
    EXPECT_EQ(lead.sse, own.sse) << "p " << p;
    EXPECT_EQ(lead.rows, own.rows);
    Eigen::VectorXd sw(300);
    for (int i = 0; i < 300; ++i) sw(i) = std::sqrt(0.5 + (i % 3));
    const Eigen::MatrixXd xw = sw.asDiagonal() * x.leftCols(k);
    const Eigen::VectorXd ref = xw.colPivHouseholderQr().solve(sw.asDiagonal() * y);
    for (int j = 0; j < k; ++j) EXPECT_NEAR(lead.beta(j), ref(j), 1e-9 * (1 + std::fabs(ref(j))));
  }
}

TEST(DiagSignal, HysteresisOperatorsAreRateIndependent) {
  // The same monotone-segment path sampled coarsely and 10× finer gives the same output at the
  // common points: the operators depend on the path, not on time.
  std::vector<double> coarse;
  std::vector<double> fine;
  const double keys[] = {0, 1, 0.3, 0.8, -1, -0.2};
  for (std::size_t k = 0; k + 1 < std::size(keys); ++k) {
    for (int j = 0; j < 10; ++j) {
      coarse.push_back(keys[k] + (keys[k + 1] - keys[k]) * j / 10.0);
      for (int m = 0; m < 10; ++m)
        fine.push_back(keys[k] + (keys[k + 1] - keys[k]) * (j * 10 + m) / 100.0);
    }
  }
  std::vector<double> zc(coarse.size());
  std::vector<double> zf(fine.size());
  DahlOperator(coarse.data(), coarse.size(), 0.3, zc.data());
  DahlOperator(fine.data(), fine.size(), 0.3, zf.data());
  for (std::size_t i = 0; i < coarse.size(); ++i) EXPECT_NEAR(zc[i], zf[i * 10], 1e-12);
  PlayOperator(coarse.data(), coarse.size(), 0.5, zc.data());
  PlayOperator(fine.data(), fine.size(), 0.5, zf.data());
  for (std::size_t i = 0; i < coarse.size(); ++i) EXPECT_NEAR(zc[i], zf[i * 10], 1e-12);
}

// ---------------------------------------------------------------------------------------------
// Diagnoses of closed-form fixtures (the effects are written from physics in diag_fixture.hpp,
// integrated independently of ftdiag's own models).

double ExcessRemoved(const Report& r) {
  const double before = r.hold_rms_before * r.hold_rms_before - kNoise * kNoise;
  const double after = r.hold_rms_after * r.hold_rms_after - kNoise * kNoise;
  return 1.0 - after / before;
}

struct Case {
  const char* name;
  double size_sigma;
  unsigned seed;
};

class DiagFixture : public ::testing::TestWithParam<Case> {};

TEST_P(DiagFixture, NamesLocatesAndModelsTheEffect) {
  const Case c = GetParam();
  const auto fx = testing::MakeFixture({{c.name, c.size_sigma}}, c.seed, 200.0, kNoise, 4.0);
  const Report r = Diagnose(fx.data);
  ASSERT_EQ(r.verdict, c.name);
  const auto& e = r.effects.front().fit;
  EXPECT_GE(ExcessRemoved(r), 0.7);
  // Noise estimate within 5 % of the true σ on every channel.
  for (int ch = 0; ch < r.noise_rms.size(); ++ch)
    EXPECT_NEAR(r.noise_rms(ch), kNoise, 0.05 * kNoise);
  // Every fitted parameter is typed with a unit from the vocabulary or the effect's declaration
  // (never guessed from its key; "" for a ratio).
  for (const auto& p : TypedParameters(r.cx, e)) {
    EXPECT_TRUE(p["unit"].is_string()) << c.name << " " << p.dump();
    EXPECT_TRUE(p["status"].is_string()) << c.name << " " << p.dump();
  }
  const std::string n = c.name;
  if (n == "creep") {
    EXPECT_NEAR(e.params["tau_s"].get<double>(), fx.truth, 0.15 * fx.truth);
  }
  if (n == "time_skew") {
    EXPECT_NEAR(e.params["delay_s"].get<double>(), fx.truth, 0.1 * fx.truth);
  }
  if (n == "mains_interference") {
    EXPECT_NEAR(e.params["freq_hz"].get<double>(), fx.truth, 0.01);
  }
  if (n == "resonance") {
    EXPECT_NEAR(e.params["freq_hz"].get<double>(), fx.truth, 0.02 * fx.truth);
  }
  if (n == "misalignment") {
    EXPECT_EQ(e.params["axis"], "z");
    EXPECT_NEAR(e.params["angle_deg"].get<double>(), fx.truth, 0.1 * fx.truth);
  }
  if (n == "gain_error") {
    EXPECT_EQ(e.channels, std::vector<int>{3});
    EXPECT_NEAR(e.params["gain"][0].get<double>(), fx.truth, 0.1 * (fx.truth - 1.0));
  }
  if (n == "overload_shift") {
    EXPECT_NEAR(e.params["onset_s"].get<double>(), fx.truth, r.cx.block_s);
  }
  if (n == "saturation") {
    EXPECT_NEAR(e.params["limit"].get<double>(), fx.truth, 0.01 * fx.truth);
  }
  if (n == "thermal_zero_drift") {
    EXPECT_NEAR(e.params["coef_per_K"][4].get<double>(), fx.truth, 0.1 * fx.truth);
  }
  if (n == "thermal_span_drift") {
    EXPECT_NEAR(e.params["coef_per_K"].get<double>(), fx.truth, 0.15 * fx.truth);
  }
  if (n == "bridge_nonlinearity") {
    EXPECT_EQ(e.params["channels"], (std::vector<int>{1, 4}));
  }
  if (n == "zero_offset") {
    EXPECT_NEAR(e.params["offset"][2].get<double>(), fx.truth,
                4 * kNoise / std::sqrt(r.cx.n_train));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Effects, DiagFixture,
    ::testing::Values(Case{"zero_offset", 3, 1}, Case{"zero_drift", 6, 2},
                      Case{"thermal_zero_drift", 5, 3}, Case{"thermal_span_drift", 6, 4},
                      Case{"excitation_drift", 6, 5}, Case{"creep", 4, 6}, Case{"hysteresis", 3, 7},
                      Case{"bridge_nonlinearity", 4, 8}, Case{"geometric_nonlinearity", 5, 9},
                      Case{"load_stiffening", 5, 10}, Case{"misalignment", 4, 11},
                      Case{"gain_error", 4, 12}, Case{"time_skew", 5, 13},
                      Case{"saturation", 5, 14}, Case{"overload_shift", 3, 15},
                      Case{"mains_interference", 2, 16}, Case{"resonance", 4, 17}),
    [](const ::testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

// A fit on a bound or outside the stated range is not resolved. The bounds in closed form: at
// 200 Hz creep τ runs from max(3 samples, 0.2 s) = 0.2 s to a third of the record, fractions to 5
// %.
TEST(DiagHonesty, FitOnABoundOrOutsideItsRangeIsNotResolved) {
  const auto fx = testing::MakeFixture({}, 3, 200.0, kNoise, 4.0);
  const Context cx = MakeContext(fx.data);
  const double third = (fx.data.t_s.back() - fx.data.t_s.front()) / 3.0;
  EffectFit f;
  f.name = "creep";
  f.params["fraction"] = {0.004, -0.01, 0.0};
  f.params["tau_s"] = 12.0;
  EXPECT_EQ(NotResolved(cx, f), "");
  f.params["tau_s"] = 0.2;
  EXPECT_NE(NotResolved(cx, f).find("tau_s = 0.2 at its lower bound"), std::string::npos)
      << NotResolved(cx, f);
  f.params["tau_s"] = third / 1.01;  // 1 % inside a bound (in log) is still on it
  EXPECT_NE(NotResolved(cx, f).find("at its upper bound"), std::string::npos);
  f.params["tau_s"] = 2.0 * third;
  EXPECT_NE(NotResolved(cx, f).find("above its range"), std::string::npos);
  f.params["tau_s"] = 12.0;
  f.params["fraction"] = {0.004, -0.08, 0.0};  // either sign: |fraction| ≤ 5 %
  EXPECT_NE(NotResolved(cx, f).find("fraction up to 0.08 beyond its range"), std::string::npos);
  // Resonance: lightly damped down to ζ = 1e-3, below 0.98 × Nyquist (98 Hz here).
  EffectFit r;
  r.name = "resonance";
  r.params["freq_hz"] = 12.0;
  r.params["damping_ratio"] = 0.002;
  EXPECT_EQ(NotResolved(cx, r), "");
  r.params["damping_ratio"] = 0.5;
  EXPECT_NE(NotResolved(cx, r).find("at its upper bound"), std::string::npos);
  r.params["damping_ratio"] = 0.05;
  r.params["freq_hz"] = 99.0;
  EXPECT_NE(NotResolved(cx, r).find("above its range"), std::string::npos);
}

// resonance's variant "ringing per load change" searches ζ only up to 0.05 (light damping), a
// narrower range than resonance's 0.5: a variant fit at ζ = 0.05 or above is on its own bound and
// not resolved, where the same value is resolved for the locked ringing. Nyquist is 100 Hz at 200
// Hz, so 0.98 × Nyquist = 98 Hz bounds the frequency of both.
TEST(DiagHonesty, RingingPerChangeIsCheckedAgainstItsOwnDeclaredRange) {
  const auto fx = testing::MakeFixture({}, 3, 200.0, kNoise, 4.0);
  const Context cx = MakeContext(fx.data);
  EffectFit r;
  r.name = "resonance";
  r.params["freq_hz"] = 12.0;
  r.params["damping_ratio"] = 0.05;
  EXPECT_EQ(NotResolved(cx, r), "");  // the locked ringing: inside 1e-3 … 0.5
  r.variant = fx::kRingingPerChange;
  EXPECT_NE(NotResolved(cx, r).find("damping_ratio = 0.05 at its upper bound"), std::string::npos)
      << NotResolved(cx, r);
  r.params["damping_ratio"] = 0.2;
  EXPECT_NE(NotResolved(cx, r).find("above its range"), std::string::npos) << NotResolved(cx, r);
  r.params["damping_ratio"] = 0.01;
  EXPECT_EQ(NotResolved(cx, r), "");
  r.params["freq_hz"] = 97.5;  // 0.5 % below 0.98 × Nyquist: on the bound
  EXPECT_NE(NotResolved(cx, r).find("at its upper bound"), std::string::npos);
  const auto p = TypedParameters(cx, r);
  for (const auto& q : p) {
    if (q["key"] == "damping_ratio") {
      EXPECT_EQ(q["range"][1].get<double>(), 0.05);
    }
  }
}

/// The typed status of `key` in a TypedParameters list, or "" without it.
std::string StatusIn(const nlohmann::json& typed, const std::string& key) {
  for (const auto& p : typed) {
    if (p["key"] == key) return p["status"].get<std::string>();
  }
  return "";
}

// The pieces rule in closed form: a claim is contradicted when the pieces' values of its largest
// element straddle zero (here b1's creep fraction −0.01, pieces −0.02…+0.004); b0's pieces
// straddle zero too but b0 does not carry the effect; the pieces of a scale searched in log (τ)
// contradict it when they differ by more than a factor 2 and by more than 3 σ between two pieces
// (σ per piece √4 × the curvature σ), not within a factor 2. The evidence words name the channel
// whose pieces they quote.
TEST(DiagHonesty, PiecesStraddlingZeroOrAFactorApartContradictAClaim) {
  const auto fx = testing::MakeFixture({}, 3, 200.0, kNoise, 4.0);
  const Context cx = MakeContext(fx.data);
  EffectFit f;
  f.name = "creep";
  f.params["tau_s"] = 12.0;
  f.params["fraction"] = {0.004, -0.01, 0.001};
  f.sigma["fraction"] = {1e-4, 1e-4, 1e-4};
  f.spread["fraction"] = {{"pieces", 4},
                          {"agree", false},
                          {"min", {-0.001, -0.02, 0.0005}},
                          {"max", {0.005, 0.004, 0.002}}};
  const std::string why = NotResolved(cx, f);
  EXPECT_NE(why.find("fraction = -0.01, per piece -0.02–0.004"), std::string::npos) << why;
  EXPECT_EQ(SpreadWords(f), "fraction on b1 per piece -0.02–0.004");
  f.spread["fraction"]["min"] = {-0.001, -0.03, 0.0005};
  f.spread["fraction"]["max"] = {0.005, -0.002, 0.002};
  EXPECT_EQ(NotResolved(cx, f), "");  // one sign: a linear amplitude is not judged by a factor
  EXPECT_EQ(SpreadWords(f), "fraction on b1 per piece -0.03–-0.002");
  // τ, a scale searched in log: pieces 6–30 s (a factor 5) over 3 σ apart (8.5e-2 s) contradict.
  f.spread.erase("fraction");
  f.sigma["tau_s"] = 0.01;
  f.spread["tau_s"] = {{"pieces", 4}, {"min", 6.0}, {"max", 30.0}};
  EXPECT_NE(NotResolved(cx, f).find("tau_s = 12, per piece 6–30, a factor 5"), std::string::npos)
      << NotResolved(cx, f);
  EXPECT_EQ(StatusIn(TypedParameters(cx, f), "tau_s"), "pieces_disagree");
  f.spread["tau_s"]["min"] = 16.0;
  EXPECT_EQ(NotResolved(cx, f), "");  // a factor 1.9
  EXPECT_EQ(StatusIn(TypedParameters(cx, f), "tau_s"), "resolved");
  f.spread["tau_s"]["min"] = 6.0;
  f.sigma["tau_s"] = 3.0;
  EXPECT_EQ(NotResolved(cx, f), "");  // a factor 5 within 3 σ between two pieces (25 s)
  // A parameter without a stated range (an onset time is the piece's own) never contradicts.
  EffectFit o;
  o.name = "overload_shift";
  o.params["onset_s"] = 2.0;
  o.spread["onset_s"] = {{"pieces", 3}, {"agree", false}, {"min", -1.0}, {"max", 3.0}};
  EXPECT_EQ(NotResolved(cx, o), "");
  EXPECT_EQ(SpreadWords(o), "onset_s per piece -1–3");
  // Nor does a signed coefficient whose pieces straddle zero, even where each piece's own σ is
  // small: a true cubic on a converter's grid reads −0.92…0.99 per piece.
  EffectFit g;
  g.name = "overload_shift";
  g.params["recovering_shift"] = {0.001, 0.3};
  g.sigma["recovering_shift"] = {1e-3, 1e-3};
  g.spread["recovering_shift"] = {{"pieces", 2},
                                  {"min", {-0.001, -0.2}},
                                  {"max", {0.002, 0.3}},
                                  {"min_sigma", {1e-3, 0.01}},
                                  {"max_sigma", {1e-3, 0.01}}};
  EXPECT_EQ(NotResolved(cx, g), "");
  EXPECT_EQ(StatusIn(TypedParameters(cx, g), "recovering_shift"), "resolved");
}

// The spread across pieces of the record covers the truth on data the creep model describes, and
// the pieces agree with the curvature σ; the JSON report carries it next to the σ.
TEST(DiagHonesty, CreepSpreadAcrossPiecesCoversTheTruth) {
  const auto fx = testing::MakeFixture({{"creep", 6}}, 6, 200.0, kNoise, 4.0);
  const Report r = Diagnose(fx.data);
  ASSERT_EQ(r.verdict, "creep");
  const auto& e = r.effects.front().fit;
  ASSERT_TRUE(e.spread.contains("tau_s")) << e.spread.dump();
  const auto& s = e.spread["tau_s"];
  EXPECT_GE(s["pieces"].get<int>(), 3) << s.dump();
  const double larger = s["larger"].get<double>();
  EXPECT_GE(larger, e.sigma["tau_s"].get<double>());
  EXPECT_LE(s["min"].get<double>(), s["max"].get<double>());
  EXPECT_NEAR(e.params["tau_s"].get<double>(), fx.truth, 3.0 * larger + 0.05 * fx.truth);
  EXPECT_LE(s["min"].get<double>(), fx.truth * 1.2) << s.dump();
  EXPECT_GE(s["max"].get<double>(), fx.truth * 0.8) << s.dump();
  EXPECT_TRUE(s["agree"].get<bool>()) << s.dump();
  EXPECT_EQ(ToJson(r)["effects"][0]["spread"]["tau_s"], s);
}

TEST(DiagFixtureNone, NoiseOnlyMakesNoClaim) {
  for (unsigned seed : {21u, 22u}) {
    const auto fx = testing::MakeFixture({}, seed, 200.0, kNoise, 4.0);
    const Report r = Diagnose(fx.data);
    EXPECT_EQ(r.verdict, "none") << "seed " << seed;
    EXPECT_TRUE(r.effects.empty());
    EXPECT_TRUE(r.mismatch_channels.empty());
    EXPECT_DOUBLE_EQ(r.hold_rms_after, r.hold_rms_before);
  }
}

TEST(DiagFixturePairs, OffsetAndCreepAreBothNamed) {
  const auto fx = testing::MakeFixture({{"zero_offset", 5}, {"creep", 5}}, 2, 200.0, kNoise, 4.0);
  const Report r = Diagnose(fx.data);
  std::string said;
  for (const auto& e : r.effects)
    said += e.fit.name + " " + TypedParameters(r.cx, e.fit).dump() + "\n";
  for (const auto& d : r.dropped) said += "not claimed: " + d + "\n";
  for (const auto& c : r.candidates) said += "candidate " + c.name + ": " + c.not_resolved + "\n";
  ASSERT_EQ(r.effects.size(), 2u) << said;
  std::vector<std::string> names{r.effects[0].fit.name, r.effects[1].fit.name};
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"creep", "zero_offset"}));
  EXPECT_GE(ExcessRemoved(r), 0.7);
}

// The fits run in parallel: the report must not depend on how many threads ran them (the reference
// is the sequential run; every candidate's score and every claimed prediction compared exactly).
TEST(DiagFixturePairs, ReportDoesNotDependOnThreadCount) {
  const auto fx = testing::MakeFixture({{"zero_offset", 5}, {"creep", 5}}, 2, 200.0, kNoise, 4.0);
  DiagnoseOptions one;
  one.threads = 1;
  const Report a = Diagnose(fx.data, one);
  for (int threads : {2, 5}) {
    DiagnoseOptions many;
    many.threads = threads;
    const Report b = Diagnose(fx.data, many);
    EXPECT_EQ(a.verdict, b.verdict) << threads;
    ASSERT_EQ(a.candidates.size(), b.candidates.size()) << threads;
    for (std::size_t k = 0; k < a.candidates.size(); ++k) {
      EXPECT_EQ(a.candidates[k].name, b.candidates[k].name) << threads;
      EXPECT_EQ(a.candidates[k].score, b.candidates[k].score) << threads;
    }
    ASSERT_EQ(a.effects.size(), b.effects.size()) << threads;
    for (std::size_t k = 0; k < a.effects.size(); ++k) {
      EXPECT_EQ(a.effects[k].fit.name, b.effects[k].fit.name) << threads;
      EXPECT_EQ(a.effects[k].fit.params.dump(), b.effects[k].fit.params.dump()) << threads;
      EXPECT_TRUE(a.effects[k].fit.pred == b.effects[k].fit.pred) << threads;
    }
  }
}

TEST(DiagReportHtml, NotClaimedPartnersAreSaidInWords) {
  // A pair partner left unclaimed (Report::dropped, JSON "not_claimed": "name: reason") is named
  // in the HTML apart from the claimed effects, with its reason, in words.
  const auto fx = testing::MakeFixture({{"zero_offset", 5}}, 3, 200.0, kNoise, 4.0);
  Report r = Diagnose(fx.data);
  ASSERT_FALSE(r.effects.empty());
  r.dropped.push_back("zero_drift: one offset per load hold explains it as well");
  const std::string html = HtmlReport(fx.data, r);
  EXPECT_NE(html.find("<h2>zero_drift (not claimed)</h2>"), std::string::npos);
  EXPECT_NE(html.find("<b>Not claimed.</b> zero_drift improved the held-out rows"),
            std::string::npos);
  EXPECT_NE(html.find("one offset per load hold explains it as well</p>"), std::string::npos);
  EXPECT_EQ(ToJson(r)["not_claimed"][0], r.dropped[0]);
}

TEST(DiagReportText, SummaryNamesTheVerdictAndEveryClaimOnce) {
  // The summary's first line: the verdict, then the other claims; when the verdict is not the
  // first claim (an unidentified one ranks above it, or none is identified) every claim is listed
  // after it with its identification, never the verdict twice.
  Report r;
  r.hold_rms_before = 2.0;
  r.hold_rms_after = 1.0;
  const auto first_line = [&r] {
    const std::string s = SummaryText(r);
    return s.substr(0, s.find('\n'));
  };
  ClaimedEffect drift;
  drift.fit.name = "zero_drift";
  ClaimedEffect shift;
  shift.fit.name = "overload_shift";
  r.verdict = "zero_drift";
  r.effects = {drift, shift};
  EXPECT_EQ(first_line(), "verdict: zero_drift + overload_shift  (held-out RMS 2 -> 1 mV/V)");
  r.effects[0].confounded_with = {"hysteresis"};
  r.verdict = "overload_shift";
  EXPECT_EQ(first_line(),
            "verdict: overload_shift; claimed: zero_drift (not identified) + overload_shift  "
            "(held-out RMS 2 -> 1 mV/V)");
  r.effects[1].confounded_with = {"zero_offset"};
  r.verdict = "undetermined";
  EXPECT_EQ(first_line(),
            "verdict: undetermined; claimed: zero_drift (not identified) + overload_shift (not "
            "identified)  (held-out RMS 2 -> 1 mV/V)");
  r.verdict = "none";
  r.effects.clear();
  EXPECT_EQ(first_line(), "verdict: none  (held-out RMS 2 -> 1 mV/V)");
}

TEST(DiagFixtureSubtle, WithoutTemperatureThermalDriftIsNotClaimed) {
  // The same thermal drift, but the real file carries no temp_C: the tool must fall back to time.
  auto fx = testing::MakeFixture({{"thermal_zero_drift", 6}}, 3, 200.0, kNoise, 4.0);
  fx.data.temp_c.clear();
  const Report r = Diagnose(fx.data);
  EXPECT_EQ(r.verdict, "zero_drift");
  EXPECT_GE(ExcessRemoved(r), 0.7);
}

// A ratiometric converter's reference follows the bridge excitation, so a drift of the excitation
// cancels in every reading: declared so, the common gain drift of the fixture is not called
// excitation_drift (not even a candidate). The control, undeclared, names it.
TEST(DiagFixtureRatiometric, DeclaredRatiometricReadingsHaveNoExcitationDrift) {
  auto fx = testing::MakeFixture({{"excitation_drift", 6}}, 5, 200.0, kNoise, 4.0);
  const Report plain = Diagnose(fx.data);
  EXPECT_EQ(plain.verdict, "excitation_drift");
  fx.data.real_ratiometric = true;
  const Report ratiometric = Diagnose(fx.data);
  EXPECT_NE(ratiometric.verdict, "excitation_drift");
  for (const auto& e : ratiometric.effects) EXPECT_NE(e.fit.name, "excitation_drift");
  for (const auto& c : ratiometric.candidates) EXPECT_NE(c.name, "excitation_drift");
}

// The flag comes from the real file's declaration: the codes of a ratiometric converter set it;
// a non-ratiometric one (with its excitation) and plain mV/V do not.
TEST(DiagFixtureRatiometric, LoaderReadsTheDeclaredConverter) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("diag_ratiometric_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, const std::string& meta, int code) {
    std::ofstream f(dir / name);
    f << meta << "t,Fx,Fy,Fz,Mx,My,Mz,b0\n";
    for (int i = 0; i < 100; ++i)
      f << 0.1 * i << ",0,0," << (i < 50 ? 0 : 10) << ",0,0,0," << code << "\n";
  };
  write("sim.csv", "", 0);
  const std::string counts =
      "# bridge_unit: counts\n# converter: bits=24, coding=signed, gain=128, ";
  write("ratio.csv", counts + "ratiometric=yes\n", 1000);
  write("fixed.csv", counts + "ratiometric=no, reference_v=2.5\n# excitation_v: 5\n", 1000);
  write("mvv.csv", "", 0);
  const auto load = [&](const std::string& real) {
    return LoadSimReal((dir / "sim.csv").string(), (dir / real).string()).real_ratiometric;
  };
  EXPECT_TRUE(load("ratio.csv"));
  EXPECT_FALSE(load("fixed.csv"));
  EXPECT_FALSE(load("mvv.csv"));
  std::filesystem::remove_all(dir);
}

// The two files are read at once, on two threads; the error reported is the one a reading in
// turn would give: the sim's when both are bad (with its line and column), else the real's.
TEST(DiagLoader, BothFilesBadReportsTheSimFirst) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("diag_load_errors_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const std::string& name, int bad_row) {
    std::ofstream f(dir / name);
    f << "t,Fx,Fy,Fz,Mx,My,Mz,b0\n";
    for (int i = 0; i < 2000; ++i) {
      f << 0.1 * i << ",0,0,1,0,0,0," << (i == bad_row ? "0.1x" : "0.1") << "\n";
    }
  };
  write("sim_bad.csv", 1500);  // line 1502
  write("real_bad.csv", 10);   // line 12
  write("good.csv", -1);
  const auto error_of = [&](const std::string& sim, const std::string& real) {
    try {
      (void)LoadSimReal((dir / sim).string(), (dir / real).string());
    } catch (const DiagInputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string both = error_of("sim_bad.csv", "real_bad.csv");
  EXPECT_NE(both.find((dir / "sim_bad.csv").string() + ":1502:"), std::string::npos) << both;
  const std::string real_only = error_of("good.csv", "real_bad.csv");
  EXPECT_NE(real_only.find((dir / "real_bad.csv").string() + ":12:"), std::string::npos)
      << real_only;
  const std::string missing = error_of("missing.csv", "real_bad.csv");
  EXPECT_NE(missing.find((dir / "missing.csv").string() + ": cannot open"), std::string::npos)
      << missing;
  EXPECT_EQ(error_of("good.csv", "good.csv"), "no error");
  std::filesystem::remove_all(dir);
}

TEST(DiagConditioning, WrongCodesOnLoadRampsAreFoundAndStepsAreNot) {
  // 6 bridges at 100 Hz, 60 s: loads ramp to a new random target in 0.5 s (up to ~0.03 mV/V per
  // row), hold 1.5 s, and every third change is an instant step. Wrong codes of ±0.1 mV/V (100 σ
  // of the noise, 3 times the detection threshold) sit at chosen rows, two of them mid-ramp, one
  // right after a step; nothing else may be reported.
  const int nc = 6;
  const Eigen::Index n = 6000;
  testing::RandomSensor sensor(21, nc);
  auto& rng = sensor.rng;
  auto& u = sensor.u;
  auto& g = sensor.g;
  const Eigen::MatrixXd& s = sensor.s;
  DiagData d;
  d.sim_name = "ramps";
  d.real_name = "ramps with wrong codes";
  d.sim_mvv.resize(n, nc);
  d.real_mvv.resize(n, nc);
  d.wrench.resize(n, 6);
  Eigen::VectorXd from = Eigen::VectorXd::Zero(6);
  Eigen::VectorXd to = Eigen::VectorXd::Zero(6);
  bool step = false;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (i % 200 == 0) {
      from = to;
      for (int a = 0; a < 6; ++a) to(a) = 40.0 * u(rng);
      step = (i / 200) % 3 == 2;
    }
    const double f = step ? 1.0 : std::min(1.0, static_cast<double>(i % 200) / 50.0);
    const Eigen::VectorXd w = from + f * (to - from);
    d.t_s.push_back(0.01 * static_cast<double>(i));
    d.wrench.row(i) = w.transpose().cast<float>();
    const Eigen::VectorXd b = s * w;
    for (int c = 0; c < nc; ++c) {
      d.sim_mvv(i, c) = b(c);
      d.real_mvv(i, c) = b(c) + 1e-3 * g(rng);
    }
  }
  // (row, channel): rows 1025 and 3630 are mid-ramp (the changes at 1000 and 3600 ramp), 2220
  // follows the step at 2200, 1180 and 4790 are in holds.
  const std::vector<std::pair<int, int>> wrong = {
      {1025, 1}, {1180, 4}, {2220, 0}, {3630, 5}, {4790, 2}};
  for (const auto& [row, c] : wrong) d.real_mvv(row, c) += row % 2 == 0 ? 0.1 : -0.1;
  const Report r = Diagnose(d);
  const auto& found = r.cx.conditioning.glitches;
  ASSERT_EQ(found.size(), wrong.size()) << ToJson(r)["findings"].dump();
  for (std::size_t k = 0; k < wrong.size(); ++k) {
    EXPECT_EQ(found[k].row, wrong[k].first);
    EXPECT_EQ(found[k].channel, wrong[k].second);
    EXPECT_NEAR(std::fabs(found[k].offset_mvv), 0.1, 0.005) << found[k].row;
  }
  EXPECT_EQ(r.verdict, "none");
}

/// A recording of n rows, dt_s apart, on nc channels: reference ref(i, c) and real load
/// real(i, c), the latter with white noise of 1e-4 mV/V (seeded).
template <class Ref, class Real>
DiagData NoisyRecording(int n, int nc, double dt_s, unsigned seed, Ref ref, Real real) {
  DiagData d;
  d.sim_name = "reference";
  d.real_name = "real load with noise";
  d.sim_mvv.resize(n, nc);
  d.real_mvv.resize(n, nc);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1e-4);
  for (int i = 0; i < n; ++i) {
    d.t_s.push_back(dt_s * i);
    for (int c = 0; c < nc; ++c) {
      d.sim_mvv(i, c) = ref(i, c);
      d.real_mvv(i, c) = real(i, c) + noise(rng);
    }
  }
  return d;
}

TEST(DiagConditioning, TransitionIsShownOnTheChannelWithTheLongestOwnWindow) {
  // One reference ramp on three channels (0 → 1 mV/V at 100 Hz: 0.05, 0.15, …, 0.95 on rows
  // 100–109, 1 from row 110), each with its own real load u(100 + k), all lagging (10–90 % rise
  // ≥ 10 rows against the reference's 8). By hand, the rows where |u − v| > 0.1:
  //   b0: u = (k + ½)/20, rows 102–117 (15 rows apart), rise rows 102–118;
  //   b1: u = v up to 0.75 (k ≤ 7), then 0.75 + 0.008 (k − 7): rows 109–125 (16 apart);
  //   b2: u = (k + ½)/22, rows 102–119 (17 apart), rise rows 102–120 (18 rows).
  // b2 lags over the most rows of its own; the union window (102–125, 23 apart) is what is
  // excluded, with one row of margin: 1.01–1.26 s.
  const auto ref = [](int i, int) {
    const int k = i - 100;
    return k < 0 ? 0.0 : (k < 10 ? (k + 0.5) / 10.0 : 1.0);
  };
  const auto real = [&](int i, int c) {
    const int k = i - 100;
    switch (c) {
      case 0:
        return k < 0 ? 0.0 : std::min(1.0, (k + 0.5) / 20.0);
      case 1:
        return k <= 7 ? ref(i, c) : std::min(1.0, 0.75 + 0.008 * (k - 7));
      default:
        return k < 0 ? 0.0 : std::min(1.0, (k + 0.5) / 22.0);
    }
  };
  const DiagData d = NoisyRecording(400, 3, 0.01, 5, ref, real);
  const Context cx = MakeContext(d);
  const auto& tr = cx.conditioning.transitions;
  ASSERT_EQ(tr.size(), 1u);
  EXPECT_EQ(tr[0].first_row, 100);
  EXPECT_EQ(tr[0].channel, 2);
  EXPECT_TRUE(tr[0].excluded);
  EXPECT_NEAR(tr[0].step_mvv, 1.0, 1e-12);
  EXPECT_NEAR(tr[0].application_s, 18 * 0.01 / 0.8, 1e-9);
  EXPECT_NEAR(tr[0].excluded_from_s, 1.01, 1e-9);
  EXPECT_NEAR(tr[0].excluded_to_s, 1.26, 1e-9);
}

TEST(DiagConditioning, ARampsFootAndTheBounceAreExcludedAndTheRingingIsNot) {
  // A hand-hung weight at 10 Hz: the reference steps 0 → 1 mV/V at row 300 (30 s); the real load
  // is a raised cosine over 29.4–30.9 s, then a bounce of 8 % of the step at 2.5 Hz decaying with
  // 0.3 s, under a swing of 0.4 % at 0.8 Hz decaying with 100 s; noise 1e-4 mV/V. By hand:
  // - the foot: the ramp is 1.1 % off at 29.5 s (row 295; 0 at 29.4 s), 100 σ of the noise;
  // - the bounce: its amplitude 0.08 e^(−Δ/0.3) is below the swing's 0.004 only for Δ > 0.9 s,
  //   i.e. after 31.8 s; the swing lasts the whole hold and is a finding, not a transition.
  const double pi = std::numbers::pi;
  const auto ref = [](int i, int) { return i >= 300 ? 1.0 : 0.0; };
  const auto real = [&](int i, int) {
    const double t = 0.1 * i;
    const double x = std::clamp((t - 29.4) / 1.5, 0.0, 1.0);
    double u = 0.5 * (1.0 - std::cos(pi * x));
    if (t > 30.9) {
      const double after = t - 30.9;
      u += 0.08 * std::exp(-after / 0.3) * std::sin(2 * pi * 2.5 * after) +
           0.004 * std::exp(-after / 100.0) * std::sin(2 * pi * 0.8 * after);
    }
    return u;
  };
  const DiagData d = NoisyRecording(1200, 1, 0.1, 7, ref, real);
  const Context cx = MakeContext(d);
  const auto& tr = cx.conditioning.transitions;
  ASSERT_EQ(tr.size(), 1u);
  EXPECT_TRUE(tr[0].excluded);
  EXPECT_LE(tr[0].excluded_from_s, 29.5 + 1e-9);
  EXPECT_GE(tr[0].excluded_to_s, 31.8);
  EXPECT_LE(tr[0].excluded_to_s, 33.9);
}

TEST(DiagConditioning, CreepFloorIsThreeTimesTheMedianSettlingOfTheLaggingChanges) {
  // At 10 Hz, five reference steps (0 -> 1 -> 2 -> 3 -> 4 -> 5 mV/V, every 60 s). The real load
  // follows three of them as linear ramps of 1, 2 and 4 s (they lag), and two at once (they do
  // not, and are not excluded). By hand, each lagging change's excluded window holds at least the
  // rows off the reference by more than 0.1 (from the change to 0.9 of the ramp) and ends by the
  // ramp's end plus half a second; the floor is 3 x the median window, the 2 s ramp's: between
  // 3 x 1.8 and 3 x 2.6 s. Counting the prompt steps (no window) would halve it; 3 x the median
  // 10-90 % rise (the ramps' own lengths: 2 s) would miss the settling after the ramp.
  const std::vector<double> ramp_s = {1.0, 0.0, 2.0, 0.0, 4.0};
  const auto ref = [](int i, int) { return static_cast<double>(std::min(i / 600, 5)); };
  const auto real = [&](int i, int) {
    const int k = i / 600;
    if (k == 0) return 0.0;
    const double len = ramp_s[static_cast<std::size_t>(k - 1)];
    const double into = 0.1 * (i - 600 * k);
    return (k - 1) + (len > 0 ? std::min(1.0, (into + 0.05) / len) : 1.0);
  };
  const DiagData d = NoisyRecording(3600, 1, 0.1, 11, ref, real);
  const Context cx = MakeContext(d);
  const auto& tr = cx.conditioning.transitions;
  ASSERT_EQ(tr.size(), 5u);
  std::vector<double> windows;
  for (std::size_t k = 0; k < tr.size(); ++k) {
    const double len = ramp_s[k];
    EXPECT_EQ(tr[k].excluded, len > 0) << "change " << k;
    if (len == 0) continue;
    EXPECT_NEAR(tr[k].application_s, len, 0.1) << "change " << k;
    EXPECT_LE(tr[k].excluded_from_s, tr[k].t_s) << "change " << k;
    EXPECT_GE(tr[k].excluded_to_s, tr[k].t_s + 0.9 * len - 0.1) << "change " << k;
    EXPECT_LE(tr[k].excluded_to_s, tr[k].t_s + len + 0.5) << "change " << k;
    windows.push_back(tr[k].excluded_to_s - tr[k].excluded_from_s);
  }
  ASSERT_EQ(windows.size(), 3u);
  std::sort(windows.begin(), windows.end());
  EXPECT_NEAR(fx::CreepTauFloor(cx), 3.0 * windows[1], 1e-9);
  EXPECT_GE(fx::CreepTauFloor(cx), 3.0 * 1.8);
  EXPECT_LE(fx::CreepTauFloor(cx), 3.0 * 2.6);
  EXPECT_GT(fx::CreepTauFloor(cx), 3.0 * 2.0 + 0.1);  // more than the rise alone gives
  // The floor is creep's physical range too: a time constant below it is not a finding.
  const auto ranges = FindEffect("creep")->ranges(cx);
  ASSERT_FALSE(ranges.empty());
  EXPECT_EQ(ranges.front().lo, fx::CreepTauFloor(cx));
  // Without lagging changes the floor is 3 samples or 0.2 s, whichever is longer.
  Context quiet = cx;
  quiet.conditioning.transitions.clear();
  EXPECT_NEAR(fx::CreepTauFloor(quiet), 0.3, 1e-12);
  quiet.dt = 0.01;
  EXPECT_NEAR(fx::CreepTauFloor(quiet), 0.2, 1e-12);
}

}  // namespace
}  // namespace ftstack::diag
