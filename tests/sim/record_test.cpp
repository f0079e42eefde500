// Recordings: profiles, determinism per seed, noise statistics, truth, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "record_test_util.hpp"
#include "tests/support/temp_dir.hpp"

namespace ftstack::sim {
namespace {

using namespace testing_util;

TEST(RecordProfiles, RigCoversStepsSweepsCombinedLoadsAndTaps) {
  const Wrench rated = TestRated();
  const LoadProfile p = MakeProfile("rig", rated, 3);
  EXPECT_GT(p.duration_s(), 150.0);
  EXPECT_EQ(p.default_rate_hz(), 200.0);
  // Sample at 200 Hz and classify.
  bool pos[6] = {};
  bool neg[6] = {};
  bool preload_moment = false;
  int fast_edges = 0;
  bool was_fast = false;
  for (double t = 0.005; t <= p.duration_s(); t += 0.005) {
    const Wrench w = p.LoadAt(t);
    for (int k = 0; k < 6; ++k) {
      pos[k] = pos[k] || w(k) > 0.5 * rated(k);
      neg[k] = neg[k] || w(k) < -0.5 * rated(k);
    }
    if (std::abs(w(2)) > 0.4 * rated(2) &&
        (std::abs(w(3)) > 0.3 * rated(3) || std::abs(w(4)) > 0.3 * rated(4))) {
      preload_moment = true;
    }
    // A tap changes the load by > 25 % of rated within 10 ms (its 5 ms edge may straddle samples).
    const bool fast = ((w - p.LoadAt(t - 0.01)).cwiseQuotient(rated)).cwiseAbs().maxCoeff() > 0.25;
    if (fast && !was_fast) ++fast_edges;
    was_fast = fast;
  }
  for (int k = 0; k < 6; ++k) EXPECT_TRUE(pos[k] && neg[k]) << "axis " << k;
  EXPECT_TRUE(preload_moment);
  EXPECT_GE(fast_edges, 16);  // 8 taps, each up and down
  // Deterministic per seed, different across seeds.
  const LoadProfile same = MakeProfile("rig", rated, 3);
  const LoadProfile other = MakeProfile("rig", rated, 4);
  EXPECT_EQ((same.LoadAt(77.7) - p.LoadAt(77.7)).norm(), 0.0);
  EXPECT_GT(
      (other.LoadAt(77.7) - p.LoadAt(77.7)).norm() + std::abs(other.duration_s() - p.duration_s()),
      0.0);
}

TEST(RecordProfiles, SweepsReachTheSameLoadFromBelowAndAbove) {
  const Wrench rated = TestRated();
  const LoadProfile p = MakeProfile("rig", rated, 5);
  const auto& kt = p.key_times_s();
  const auto& kw = p.key_loads();
  // Some held level on an axis is approached once from below and once from above.
  int both = 0;
  for (std::size_t i = 1; i + 1 < kt.size(); ++i) {
    if ((kw[i] - kw[i + 1]).norm() != 0.0) continue;  // not the start of a hold
    for (std::size_t j = i + 1; j + 1 < kt.size(); ++j) {
      if ((kw[j] - kw[j + 1]).norm() != 0.0 || (kw[j] - kw[i]).norm() > 1e-9 || kw[i].norm() == 0)
        continue;
      const double from_i = (kw[i] - kw[i - 1]).sum();
      const double from_j = (kw[j] - kw[j - 1]).sum();
      if (from_i * from_j < 0) ++both;
    }
  }
  EXPECT_GE(both, 12);  // two levels per sign per axis
}

TEST(RecordProfiles, ThermalWarmsWithTheLoadSequence) {
  const LoadProfile p = MakeProfile("thermal", TestRated(), 1);
  const double t0 = p.TemperatureAt(0);
  const double t_end = p.TemperatureAt(p.duration_s());
  EXPECT_NEAR(t0, 20.0, 1e-9);
  EXPECT_GT(t_end - t0, 5.0);
  EXPECT_LT(t_end - t0, 12.0);
  // Slow: never more than 0.1 K per second.
  for (double t = 0; t + 1 <= p.duration_s(); t += 1) {
    EXPECT_LT(std::abs(p.TemperatureAt(t + 1) - p.TemperatureAt(t)), 0.1);
  }
  const LoadProfile rig = MakeProfile("rig", TestRated(), 1);
  EXPECT_EQ((rig.LoadAt(100) - p.LoadAt(100)).norm(), 0.0);  // same load sequence as the rig
}

TEST(RecordProfiles, HoldHasLongHoldsAndUnloads) {
  const LoadProfile p = MakeProfile("hold", TestRated(), 2);
  EXPECT_EQ(p.default_rate_hz(), 100.0);
  const auto& kt = p.key_times_s();
  const auto& kw = p.key_loads();
  int loaded = 0;
  int unloaded = 0;
  for (std::size_t i = 0; i + 1 < kt.size(); ++i) {
    if ((kw[i] - kw[i + 1]).norm() == 0.0 && kt[i + 1] - kt[i] >= 40.0) {
      (kw[i].norm() > 0 ? loaded : unloaded)++;
    }
  }
  EXPECT_GE(loaded, 4);
  EXPECT_GE(unloaded, 4);
}

TEST(RecordProfiles, DurationCutsOrRepeats) {
  const LoadProfile shortp = MakeProfile("taps", TestRated(), 1, 10.0);
  EXPECT_EQ(shortp.duration_s(), 10.0);
  const LoadProfile longp = MakeProfile("taps", TestRated(), 1, 150.0);
  EXPECT_EQ(longp.duration_s(), 150.0);
  EXPECT_GT(longp.key_times_s().back(), 150.0);
}

TEST(RecordProfiles, FromCsvAndJsonFiles) {
  const std::string csv = ftstack::test::ProcessTempDir() + "/prof.csv";
  {
    std::ofstream out(csv);
    out << "# "
           "a\nt,Fx,Fy,Fz,Mx,My,Mz,temp_C\n0,0,0,0,0,0,0,21\n0.5,10,0,0,0,0,0,21.5\n1,0,0,0,0,0,0,"
           "22\n";
  }
  const LoadProfile p = MakeProfile(csv, TestRated(), 1);
  EXPECT_DOUBLE_EQ(p.LoadAt(0.25)(0), 5.0);
  EXPECT_DOUBLE_EQ(p.TemperatureAt(0.75), 21.75);
  EXPECT_DOUBLE_EQ(p.default_rate_hz(), 2.0);
  const std::string js = WriteProfile("j", {0, 2}, {Wrench::Zero(), Along(5, 4.0)}, 50.0, {20, 24});
  const LoadProfile q = MakeProfile("file:" + js, TestRated(), 1);
  EXPECT_DOUBLE_EQ(q.LoadAt(1.0)(5), 2.0);
  EXPECT_DOUBLE_EQ(q.TemperatureAt(1.0), 22.0);
  EXPECT_DOUBLE_EQ(q.default_rate_hz(), 50.0);
}

std::string ErrorOf(const std::string& spec) {
  try {
    (void)MakeProfile(spec, TestRated(), 1);
  } catch (const ProfileError& e) {
    return e.what();
  }
  return "";
}

TEST(RecordProfiles, BadFilesNameTheFaultyPlace) {
  const std::string dir = ftstack::test::ProcessTempDir();
  {
    std::ofstream(dir + "/bad.json")
        << "{\"schema\": \"ftstack-profile/1\",\n \"keyframes\": [ {\"t_s\": 0,, } ]}";
  }
  EXPECT_NE(ErrorOf(dir + "/bad.json").find("bad.json:2:"), std::string::npos)
      << ErrorOf(dir + "/bad.json");
  {
    std::ofstream(dir + "/dec.json")
        << R"({"schema": "ftstack-profile/1", "keyframes": [{"t_s": 1, "wrench": [0,0,0,0,0,0]}, {"t_s": 1, "wrench": [0,0,0,0,0,0]}]})";
  }
  // The second keyframe's brace is at column 84 of line 1.
  EXPECT_NE(ErrorOf(dir + "/dec.json").find("dec.json:1:84: keyframes[1].t_s does not increase"),
            std::string::npos)
      << ErrorOf(dir + "/dec.json");
  {
    std::ofstream(dir + "/str.json") << "{\"schema\": \"ftstack-profile/1\", \"keyframes\": [\n"
                                        "  {\"t_s\": 0, \"wrench\": [0,0,0,0,0,0]},\n"
                                        "  {\"t_s\": \"1,]\", \"wrench\": [0,0,0,0,0,0]}]}";
  }
  EXPECT_NE(
      ErrorOf(dir + "/str.json").find("str.json:3:3: keyframes[1].t_s is not a finite number"),
      std::string::npos)
      << ErrorOf(dir + "/str.json");
  { std::ofstream(dir + "/bad.csv") << "t,Fx,Fy,Fz,Mx,My,Mz\n0,0,0,0,0,0,0\n1,0,nan,0,0,0,0\n"; }
  EXPECT_NE(ErrorOf(dir + "/bad.csv").find("bad.csv:3:"), std::string::npos)
      << ErrorOf(dir + "/bad.csv");
  // Found by fuzzing (fuzz/corpus/profile/regression_number_overflow.json): a number beyond
  // double, or a schema of the wrong JSON type, escaped as a JSON library exception.
  {
    std::ofstream(dir + "/big.json") << "{\"schema\": \"ftstack-profile/1\", \"rate_hz\": 11e308}";
  }
  EXPECT_NE(ErrorOf(dir + "/big.json").find("big.json: not valid JSON"), std::string::npos)
      << ErrorOf(dir + "/big.json");
  // Found by reading the fuzz harness's new check (fuzz/corpus/profile/regression_time_span.json):
  // finite keyframe times whose span overflows a double were accepted with an infinite duration.
  const std::string span =
      R"({"schema": "ftstack-profile/1", "keyframes": [{"t_s": -1e308, "wrench": [0,0,0,0,0,0]},)"
      R"( {"t_s": 1e308, "wrench": [1,0,0,0,0,0]}]})";
  { std::ofstream(dir + "/span.json") << span; }
  EXPECT_NE(ErrorOf(dir + "/span.json").find("span.json: keyframe times span more than a finite"),
            std::string::npos)
      << ErrorOf(dir + "/span.json");
  EXPECT_THROW((void)ftstack::sim::ParseProfileJson(span, "span.json"), ftstack::sim::ProfileError);
  // The largest span a double holds is still accepted, with that duration.
  const ftstack::sim::LoadProfile wide = ftstack::sim::ParseProfileJson(
      R"({"schema": "ftstack-profile/1", "keyframes": [{"t_s": -8e307, "wrench": [0,0,0,0,0,0]},)"
      R"( {"t_s": 8e307, "wrench": [1,0,0,0,0,0]}]})",
      "wide.json");
  EXPECT_DOUBLE_EQ(wide.duration_s(), 1.6e308);
  { std::ofstream(dir + "/type.json") << "{\"schema\": 1, \"keyframes\": []}"; }
  EXPECT_NE(ErrorOf(dir + "/type.json").find("schema is not"), std::string::npos)
      << ErrorOf(dir + "/type.json");
  EXPECT_NE(ErrorOf("sinewave").find("unknown profile 'sinewave'"), std::string::npos);
  EXPECT_NE(ErrorOf(dir + "/missing.json").find("cannot open"), std::string::npos);
}

TEST(Record, DeterministicPerSeed) {
  RecordRequest q = TestRequest("taps", {"creep", "zero_drift", "gain_error"}, 20.0);
  q.noise_mvv = 1e-4;
  const RecordResult a = MakeRecording(q);
  const RecordResult b = MakeRecording(q);
  EXPECT_EQ(a.real.columns, b.real.columns);
  EXPECT_EQ(a.sim.columns, b.sim.columns);
  EXPECT_EQ(a.truth.dump(), b.truth.dump());
  q.seed = 8;
  const RecordResult c = MakeRecording(q);
  EXPECT_NE(a.real.Column("b0"), c.real.Column("b0"));
}

TEST(Record, NoiseRmsMatchesRequest) {
  for (const double sigma : {1e-4, 3e-4}) {
    RecordRequest q = TestRequest("rig", {}, 60.0);
    q.noise_mvv = sigma;
    const RecordResult r = MakeRecording(q);
    const double n = static_cast<double>(r.real.rows());
    // Rounding to counts adds LSB²/12 of variance; the sample RMS of n Gaussian values has a
    // relative standard deviation of 1/√(2n): allow 5 of those.
    const double expect = std::sqrt(sigma * sigma + Lsb() * Lsb() / 12.0);
    for (int ch = 0; ch < 6; ++ch) {
      double ss = 0;
      for (const double v : Residual(r, ch)) ss += v * v;
      EXPECT_NEAR(std::sqrt(ss / n), expect, 5.0 * expect / std::sqrt(2.0 * n)) << ch;
    }
    EXPECT_DOUBLE_EQ(r.truth["noise_rms_mvv"].get<double>(), sigma);
  }
}

TEST(Record, TruthCarriesParametersAndFootprint) {
  const RecordResult r =
      MakeRecording(TestRequest("rig", {"gain_error:channels=[3],gain=1.004", "creep"}, 60.0));
  const auto& e = r.truth["effects"];
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0]["name"], "gain_error");
  EXPECT_DOUBLE_EQ(e[0]["params"]["gain"].get<double>(), 1.004);
  EXPECT_EQ(e[0]["footprint"]["channels"], nlohmann::json::array({3}));
  EXPECT_DOUBLE_EQ(e[1]["params"]["tau_s"].get<double>(), 10.0);
  EXPECT_EQ(r.truth["schema"], "ftsim-truth/1");
  EXPECT_EQ(r.truth["rows"], r.real.rows());
  // Windows lie inside the record and are ordered.
  double last = -1;
  for (const auto& w : e[0]["footprint"]["windows"]) {
    EXPECT_GE(w[0].get<double>(), last);
    EXPECT_GE(w[1].get<double>(), w[0].get<double>());
    last = w[1];
  }
  EXPECT_LE(last, 60.0);
  // The real file conceals the effects.
  for (const auto& m : r.real.metadata) EXPECT_EQ(m.find("gain"), std::string::npos) << m;
}

TEST(Record, ColumnsAndNoTemp) {
  RecordRequest q = TestRequest("taps", {}, 2.0);
  const RecordResult r = MakeRecording(q);
  const std::vector<std::string> want = {"t",  "Fx", "Fy", "Fz", "Mx", "My", "Mz",
                                         "b0", "b1", "b2", "b3", "b4", "b5", "temp_C"};
  EXPECT_EQ(r.real.names, want);
  EXPECT_EQ(r.sim.names, want);
  q.temperature = false;
  EXPECT_FALSE(MakeRecording(q).real.Has("temp_C"));
  EXPECT_NO_THROW(CheckAligned(r.sim, r.real));
}

std::string SpecError(const std::string& text) {
  try {
    (void)ParseEffectSpec(text);
  } catch (const EffectSpecError& e) {
    return e.what();
  }
  return "";
}

TEST(RecordEffectSpec, ParsesKeysListsAndRejectsBadInput) {
  const EffectSpec s = ParseEffectSpec("zero_offset:offset=[1e-4,-2e-4],channels=0/5");
  ASSERT_EQ(s.params.size(), 2u);
  EXPECT_EQ(s.params[0].second, "[1e-4,-2e-4]");
  EXPECT_EQ(s.params[1].second, "0/5");
  EXPECT_EQ(ParseEffectSpec("creep").params.size(), 0u);
  EXPECT_NE(SpecError("crepe").find("unknown effect 'crepe'"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau=3")
                .find("unknown key 'tau' for creep (keys: tau_s, fraction, channels)"),
            std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s=nan").find("not a finite number"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s=inf").find("not a finite number"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s=3x").find("not a finite number"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s=").find("not a finite number"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s").find("is not key=value"), std::string::npos);
  EXPECT_NE(SpecError("creep:tau_s=3,tau_s=4").find("given twice"), std::string::npos);
  EXPECT_NE(SpecError("gain_error:channels=1.5").find("not a bridge index"), std::string::npos);
  EXPECT_NE(SpecError("misalignment:axis=w").find("must be x, y or z"), std::string::npos);
  EXPECT_NE(SpecError("overload_shift:axis=Fw").find("Fx, Fy, Fz"), std::string::npos);
  EXPECT_NE(SpecError("zero_offset:offset=[1,2").find("unbalanced"), std::string::npos);
  EXPECT_NE(SpecError("none:x=1").find("keys: none"), std::string::npos);
}

// Keys come from the effect vocabulary (measurement/effect_vocabulary.hpp): an unknown key names
// itself and every valid key with its alias; an older key (alias) is read as its canonical key.
TEST(RecordEffectSpec, KeysAndAliasesFromTheVocabulary) {
  EXPECT_NE(SpecError("mains_interference:amp=1e-4")
                .find("unknown key 'amp' for mains_interference (keys: freq_hz, amplitude_mvv "
                      "(alias amplitude), phase_deg, channels)"),
            std::string::npos);
  const EffectSpec old_key = ParseEffectSpec("mains_interference:amplitude=3e-4");
  ASSERT_EQ(old_key.params.size(), 1u);
  EXPECT_EQ(old_key.params[0].first, "amplitude_mvv");
  EXPECT_NE(SpecError("zero_drift:amplitude=1e-4,amplitude_mvv=2e-4").find("given twice"),
            std::string::npos);
  const std::vector<std::string> keys = {"freq_hz", "amplitude_mvv", "phase_deg", "channels"};
  EXPECT_EQ(EffectKeys("mains_interference"), keys);
  // The old and the new key make the same recording; the truth carries the canonical key.
  const RecordResult a = MakeRecording(TestRequest("taps", {"zero_drift:amplitude=3e-4"}, 5.0));
  const RecordResult b = MakeRecording(TestRequest("taps", {"zero_drift:amplitude_mvv=3e-4"}, 5.0));
  EXPECT_EQ(a.real.columns, b.real.columns);
  EXPECT_DOUBLE_EQ(b.truth["effects"][0]["params"]["amplitude_mvv"].get<double>(), 3e-4);
  EXPECT_FALSE(b.truth["effects"][0]["params"].contains("amplitude"));
}

TEST(RecordEffectSpec, RangesCheckedAgainstTheSensor) {
  auto err = [](const std::string& text) {
    try {
      (void)MakeRecording(TestRequest("taps", {text}, 5.0));
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(
      err("gain_error:channels=6").find("channel 6 does not exist (the sensor has 6 bridges)"),
      std::string::npos);
  EXPECT_NE(err("resonance:damping_ratio=1.5").find("damping_ratio"), std::string::npos);
  EXPECT_NE(err("creep:tau_s=-1").find("tau_s must be > 0"), std::string::npos);
  EXPECT_NE(err("overload_shift:onset_s=4.9").find("onset_s"), std::string::npos);
  EXPECT_NE(err("zero_offset:offset=[1,2,3],channels=[0,1]").find("one per channel"),
            std::string::npos);
  EXPECT_NE(err("time_skew:delay_s=2").find("delay_s"), std::string::npos);
  RecordRequest q = TestRequest("taps", {}, 5.0);
  q.noise_mvv = -1.0;
  EXPECT_THROW((void)MakeRecording(q), std::invalid_argument);
  q = TestRequest("taps", {}, 5.0);
  q.rate_hz = NAN;
  EXPECT_THROW((void)MakeRecording(q), std::invalid_argument);
}

}  // namespace
}  // namespace ftstack::sim
