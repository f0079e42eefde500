// Resonance with more than one mode (issue 12 item 5), from a generator written for this test
// only (not sim/effects.cpp, not the diagnosis's filters): damped oscillators integrated by RK4
// in fine substeps under a continuous-time load, sampled on a jittered clock in two segments.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/report/html_report.hpp"
#include "diagnosis/report/json_report.hpp"
#include "tests/diagnosis/random_sensor.hpp"

namespace ftstack::diag {
namespace {

struct Mode {
  double freq_hz;
  double zeta;
  double participation;  // nominal; each bridge gets 0.7–1.0 of it
};

/// One oscillator state: position x and velocity v of ẍ + 2ζω ẋ + ω² x = ω² b(t).
struct Osc {
  double x = 0.0;
  double v = 0.0;
};

/// 6 bridges, nominal 1 kHz with ±20 % jitter per sample, two segments of `segment_s` (a 5 s gap,
/// the sensor at rest at the start of each). The wrench moves to new random values every
/// 0.5–1.5 s by a 4 ms linear ramp in continuous time; the bridges' quasi-static output
/// b_c(t) = S_c·w(t), and what is recorded is (1 − Σ p_kc)·b_c + Σ p_kc·x_kc with each x_kc an
/// oscillator driven by b_c, integrated with RK4 at 16 substeps per sample. Noise σ = 1e-3 mV/V.
/// `true_p` receives the participations per mode and bridge.
DiagData Ringing(const std::vector<Mode>& modes, double segment_s, unsigned seed,
                 std::vector<std::array<double, 6>>* true_p) {
  constexpr int nc = 6;
  testing::RandomSensor sensor(seed, nc);
  auto& rng = sensor.rng;
  auto& u = sensor.u;
  auto& g = sensor.g;
  const Eigen::MatrixXd& s = sensor.s;
  true_p->assign(modes.size(), {});
  for (std::size_t k = 0; k < modes.size(); ++k) {
    for (int c = 0; c < nc; ++c) {
      (*true_p)[k][c] = modes[k].participation * (0.85 + 0.15 * u(rng));
    }
  }
  // The load: ramps between random wrenches (each change starts at t_change, lasts 4 ms).
  struct Change {
    double t_s;
    Eigen::VectorXd from, to;
  };
  const double ramp_s = 0.004;
  DiagData d;
  d.sim_name = "independent generator";
  d.real_name = "multi-mode resonance";
  std::vector<std::array<double, 6>> sim_rows;
  std::vector<std::array<double, 6>> real_rows;
  std::vector<std::array<double, 6>> w_rows;
  for (int seg = 0; seg < 2; ++seg) {
    const double t0 = seg * (segment_s + 5.0);
    std::vector<Change> ch;
    Eigen::VectorXd w = Eigen::VectorXd::Zero(6);
    for (double t = t0 + 0.3; t < t0 + segment_s; t += 1.0 + 0.5 * u(rng)) {
      Eigen::VectorXd next(6);
      for (int a = 0; a < 6; ++a) next(a) = 40.0 * u(rng);
      ch.push_back({t, w, next});
      w = next;
    }
    std::size_t cur = 0;  // the change in effect (or the next one)
    auto wrench = [&](double t) -> Eigen::VectorXd {
      while (cur + 1 < ch.size() && t >= ch[cur + 1].t_s) ++cur;
      if (ch.empty() || t < ch.front().t_s) return Eigen::VectorXd::Zero(6);
      const Change& c = ch[cur];
      const double a = std::clamp((t - c.t_s) / ramp_s, 0.0, 1.0);
      return (1.0 - a) * c.from + a * c.to;
    };
    std::vector<std::vector<Osc>> osc(modes.size(), std::vector<Osc>(nc));  // at rest, b = 0
    double t = t0;
    while (t < t0 + segment_s) {
      const Eigen::VectorXd b = s * wrench(t);
      std::array<double, 6> sr{}, rr{}, wr{};
      for (int a = 0; a < 6; ++a) wr[a] = wrench(t)(a);
      for (int c = 0; c < nc; ++c) {
        double out = b(c);
        for (std::size_t k = 0; k < modes.size(); ++k) {
          out += (*true_p)[k][c] * (osc[k][c].x - b(c));
        }
        sr[c] = b(c);
        rr[c] = out + 1e-3 * g(rng);
      }
      d.t_s.push_back(t);
      d.segment.push_back(seg);
      sim_rows.push_back(sr);
      real_rows.push_back(rr);
      w_rows.push_back(wr);
      // Advance to the next sample time with RK4 substeps (the load evaluated in continuous time).
      const double dt = 1e-3 * (1.0 + 0.2 * u(rng));
      const int sub = 16;
      const double hs = dt / sub;
      for (int j = 0; j < sub; ++j) {
        const double ta = t + j * hs;
        const Eigen::VectorXd b0 = s * wrench(ta);
        const Eigen::VectorXd bm = s * wrench(ta + 0.5 * hs);
        const Eigen::VectorXd b1 = s * wrench(ta + hs);
        for (std::size_t k = 0; k < modes.size(); ++k) {
          const double om = 2.0 * M_PI * modes[k].freq_hz;
          const double ze = modes[k].zeta;
          auto acc = [&](double x, double v, double in) {
            return om * om * (in - x) - 2.0 * ze * om * v;
          };
          for (int c = 0; c < nc; ++c) {
            Osc& o = osc[k][c];
            const double k1x = o.v;
            const double k1v = acc(o.x, o.v, b0(c));
            const double k2x = o.v + 0.5 * hs * k1v;
            const double k2v = acc(o.x + 0.5 * hs * k1x, o.v + 0.5 * hs * k1v, bm(c));
            const double k3x = o.v + 0.5 * hs * k2v;
            const double k3v = acc(o.x + 0.5 * hs * k2x, o.v + 0.5 * hs * k2v, bm(c));
            const double k4x = o.v + hs * k3v;
            const double k4v = acc(o.x + hs * k3x, o.v + hs * k3v, b1(c));
            o.x += hs / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
            o.v += hs / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
          }
        }
      }
      t += dt;
    }
  }
  const auto n = static_cast<Eigen::Index>(sim_rows.size());
  d.sim_mvv.resize(n, nc);
  d.real_mvv.resize(n, nc);
  d.wrench.resize(n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (int c = 0; c < 6; ++c) {
      d.sim_mvv(i, c) = sim_rows[static_cast<std::size_t>(i)][c];
      d.real_mvv(i, c) = real_rows[static_cast<std::size_t>(i)][c];
      d.wrench(i, c) = w_rows[static_cast<std::size_t>(i)][c];
    }
  }
  return d;
}

/// Held-out error falls by at least half of its excess over the noise (σ = 1e-3 mV/V).
void ExpectHeldOutHalved(const Report& r) {
  const double noise2 = 1e-6;
  const double before = r.hold_rms_before * r.hold_rms_before - noise2;
  const double after = r.hold_rms_after * r.hold_rms_after - noise2;
  EXPECT_LT(after, 0.5 * before) << r.hold_rms_before << " -> " << r.hold_rms_after;
}

TEST(DiagResonance, TwoModesAreNamedWithBothFrequencies) {
  const std::vector<Mode> modes{{38.0, 0.02, 0.06}, {125.0, 0.04, 0.05}};
  std::vector<std::array<double, 6>> p;
  const DiagData d = Ringing(modes, 40.0, 11, &p);
  const Report r = Diagnose(d);
  ASSERT_FALSE(r.effects.empty());
  EXPECT_EQ(r.verdict, "resonance") << ToJson(r)["candidates"].dump();
  const EffectFit& f = r.effects.front().fit;
  EXPECT_EQ(f.variant, "two modes") << f.evidence;
  ASSERT_TRUE(f.params.contains("freq2_hz")) << f.params.dump();
  const double f1 = f.params["freq_hz"].get<double>();
  const double f2 = f.params["freq2_hz"].get<double>();
  const double z1 = f.params["damping_ratio"].get<double>();
  const double z2 = f.params["damping_ratio2"].get<double>();
  EXPECT_NEAR(f1, modes[0].freq_hz, 0.05 * modes[0].freq_hz);
  EXPECT_NEAR(f2, modes[1].freq_hz, 0.05 * modes[1].freq_hz);
  EXPECT_NEAR(z1, modes[0].zeta, 0.3 * modes[0].zeta);
  EXPECT_NEAR(z2, modes[1].zeta, 0.3 * modes[1].zeta);
  for (const char* key : {"freq_hz", "freq2_hz", "damping_ratio", "damping_ratio2"}) {
    EXPECT_GT(f.sigma[key].get<double>(), 0.0) << key;
  }
  for (int c = 0; c < 6; ++c) {
    EXPECT_NEAR(f.params["participation"][c].get<double>(), p[0][c], 0.3 * p[0][c]) << c;
    EXPECT_NEAR(f.params["participation2"][c].get<double>(), p[1][c], 0.3 * p[1][c]) << c;
  }
  ExpectHeldOutHalved(r);
  std::printf(
      "two modes: f1 %.3f ± %.2g Hz (true %.1f), ζ1 %.4f ± %.2g (true %.3f), f2 %.3f ± %.2g Hz "
      "(true %.1f), ζ2 %.4f ± %.2g (true %.3f), b0 participation %.4f / %.4f (true %.4f / %.4f), "
      "held-out %.4g -> %.4g mV/V\n",
      f1, f.sigma["freq_hz"].get<double>(), modes[0].freq_hz, z1,
      f.sigma["damping_ratio"].get<double>(), modes[0].zeta, f2, f.sigma["freq2_hz"].get<double>(),
      modes[1].freq_hz, z2, f.sigma["damping_ratio2"].get<double>(), modes[1].zeta,
      f.params["participation"][0].get<double>(), f.params["participation2"][0].get<double>(),
      p[0][0], p[1][0], r.hold_rms_before, r.hold_rms_after);
  const std::string html = std::string(FTSTACK_BIN_DIR) + "/../diag_resonance_two_modes.html";
  WriteHtml(html, d, r);
  std::ifstream in(html);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("<tr><td>freq2_hz</td>"), std::string::npos);
  EXPECT_NE(text.find("<tr><td>participation2</td>"), std::string::npos);
  EXPECT_NE(text.find("two modes"), std::string::npos);
}

TEST(DiagResonance, OneModeIsNotGivenASecond) {
  const std::vector<Mode> modes{{52.0, 0.03, 0.08}};
  std::vector<std::array<double, 6>> p;
  const DiagData d = Ringing(modes, 40.0, 12, &p);
  const Report r = Diagnose(d);
  ASSERT_FALSE(r.effects.empty());
  EXPECT_EQ(r.verdict, "resonance") << ToJson(r)["candidates"].dump();
  const EffectFit& f = r.effects.front().fit;
  EXPECT_EQ(f.variant, "one mode") << f.evidence;
  EXPECT_FALSE(f.params.contains("freq2_hz")) << f.params.dump();
  EXPECT_NEAR(f.params["freq_hz"].get<double>(), modes[0].freq_hz, 0.05 * modes[0].freq_hz);
  EXPECT_NEAR(f.params["damping_ratio"].get<double>(), modes[0].zeta, 0.3 * modes[0].zeta);
  for (int c = 0; c < 6; ++c) {
    EXPECT_NEAR(f.params["participation"][c].get<double>(), p[0][c], 0.3 * p[0][c]) << c;
  }
  ExpectHeldOutHalved(r);
  std::printf("one mode: f %.3f ± %.2g Hz (true %.1f), ζ %.4f (true %.3f); %s\n",
              f.params["freq_hz"].get<double>(), f.sigma["freq_hz"].get<double>(), modes[0].freq_hz,
              f.params["damping_ratio"].get<double>(), modes[0].zeta, f.evidence.c_str());
}

// A weak mode (ringing about as high as the noise): the model-free location tests may miss it,
// but once the resonance is claimed the channels carrying it must be located (the matched filter
// of the claimed model, docs/diagnosis.md step 4): every bridge carries it here.
TEST(DiagResonance, WeakRingingIsLocatedOnItsChannels) {
  const std::vector<Mode> modes{{47.0, 0.03, 0.0012}};
  std::vector<std::array<double, 6>> p;
  const DiagData d = Ringing(modes, 30.0, 13, &p);
  const Report r = Diagnose(d);
  ASSERT_EQ(r.verdict, "resonance") << ToJson(r)["candidates"].dump();
  const std::size_t strongest =
      static_cast<std::size_t>(std::max_element(p[0].begin(), p[0].end()) - p[0].begin());
  EXPECT_NE(std::find(r.mismatch_channels.begin(), r.mismatch_channels.end(),
                      static_cast<int>(strongest)),
            r.mismatch_channels.end())
      << ToJson(r)["mismatch"].dump();
  std::printf("weak ringing (participation %.4f on b%zu): mismatch channels %s, %s\n",
              p[0][strongest], strongest, ToJson(r)["mismatch"]["channels"].dump().c_str(),
              r.effects.front().fit.evidence.c_str());
}

}  // namespace
}  // namespace ftstack::diag
