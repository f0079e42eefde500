#include "diagnosis/diagnose.hpp"

#include "diagnosis/identifiability.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "diagnosis/signal.hpp"

namespace ftstack::diag {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

constexpr const char* kWrenchNames[6] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz"};

/// z of a χ² statistic with ν degrees of freedom (Wilson–Hilferty).
double ChiSquareZ(double x, double nu) {
  if (nu <= 0) return 0.0;
  const double a = 2.0 / (9.0 * nu);
  return (std::cbrt(x / nu) - (1.0 - a)) / std::sqrt(a);
}

double HoldRms(const Context& cx, const Mat& target, const Mat* pred) {
  double s = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (cx.train[static_cast<std::size_t>(i)]) continue;
      const double e = target(i, c) - (pred != nullptr ? (*pred)(i, c) : 0.0);
      s += e * e;
    }
  }
  return std::sqrt(s / std::max(1.0, static_cast<double>(cx.n_hold) * cx.nc));
}

Vec ChannelRms(const Mat& m) {
  Vec v(m.cols());
  for (Eigen::Index c = 0; c < m.cols(); ++c)
    v(c) = std::sqrt(m.col(c).squaredNorm() / static_cast<double>(m.rows()));
  return v;
}

double HoldPenalty(const Context& cx) {
  return std::log(std::max(2.0, static_cast<double>(cx.n_hold) * cx.nc));
}

struct Scored {
  EffectFit fit;
  double hold_sse = 0.0;
  double delta = 0.0;
  double z = 0.0;
  double score = 0.0;
  bool eligible = false;
  double hold_rms_after = 0.0;  ///< held-out RMS after removing the prediction
};

/// Pairs start from at most this many of the best eligible singles (BestPair).
constexpr std::size_t kPairStarts = 3;
/// Partners tried with each start (the best by their score on what the start leaves).
constexpr std::size_t kPairPartners = 3;

Scored ScoreFit(const Context& cx, const Mat& target, EffectFit fit, double base_hold,
                double z_claim) {
  Scored s;
  const Sums sums = Score(cx, target, &fit.pred);
  s.hold_sse = sums.hold_sse;
  s.delta = base_hold - sums.hold_sse;
  s.z = sums.hold_pp > 0 ? s.delta / (2.0 * std::sqrt(sums.hold_pp)) : 0.0;
  s.score = s.delta - fit.n_params * HoldPenalty(cx);
  s.eligible = s.z > z_claim && s.score > 0;
  s.fit = std::move(fit);
  return s;
}

/// Channels: slow (window means of m rows) and fast (mean square) χ² tests.
void LocateChannels(Report& r, int m, int blocks) {
  const Context& cx = r.cx;
  for (int c = 0; c < cx.nc; ++c) {
    double xlow = 0.0;
    double xfull = 0.0;
    for (int b = 0; b < blocks; ++b) {
      double s = 0.0;
      const int i0 = b * m;
      const int i1 = b + 1 == blocks ? cx.n : i0 + m;
      for (int i = i0; i < i1; ++i) s += cx.resid(i, c);
      const double mean = s / (i1 - i0);
      xlow += mean * mean * (i1 - i0) * cx.weight(c);
    }
    for (int i = 0; i < cx.n; ++i) xfull += cx.resid(i, c) * cx.resid(i, c) * cx.weight(c);
    const double zlow = ChiSquareZ(xlow, blocks);
    const double zfull = ChiSquareZ(xfull, cx.n);
    if (zlow > 6.0 || (zfull > 6.0 && xfull / cx.n > 1.05)) r.mismatch_channels.push_back(c);
  }
}

/// Time windows: blocks of m rows flagged on the mismatching channels, merged.
void LocateWindows(Report& r, int m, int blocks) {
  const Context& cx = r.cx;
  const auto& d = *cx.data;
  const auto nf = static_cast<double>(r.mismatch_channels.size());
  std::vector<bool> flag(static_cast<std::size_t>(blocks), false);
  for (int b = 0; b < blocks; ++b) {
    const int i0 = b * m;
    const int i1 = b + 1 == blocks ? cx.n : i0 + m;
    double xm = 0.0;
    double xs = 0.0;
    for (int c : r.mismatch_channels) {
      double s = 0.0;
      for (int i = i0; i < i1; ++i) {
        s += cx.resid(i, c);
        xs += cx.resid(i, c) * cx.resid(i, c) * cx.weight(c);
      }
      xm += s * s / (i1 - i0) * cx.weight(c);
    }
    flag[static_cast<std::size_t>(b)] =
        ChiSquareZ(xm, nf) > 4.5 || ChiSquareZ(xs, nf * (i1 - i0)) > 4.5;
  }
  // Merge flagged blocks separated by at most one quiet block.
  std::vector<std::pair<int, int>> runs;
  for (int b = 0; b < blocks; ++b) {
    if (!flag[static_cast<std::size_t>(b)]) continue;
    if (!runs.empty() && b - runs.back().second <= 2) {
      runs.back().second = b;
    } else {
      runs.emplace_back(b, b);
    }
  }
  while (runs.size() > 40) {
    std::size_t gi = 1;
    int gap = std::numeric_limits<int>::max();
    for (std::size_t j = 1; j < runs.size(); ++j) {
      if (runs[j].first - runs[j - 1].second < gap) {
        gap = runs[j].first - runs[j - 1].second;
        gi = j;
      }
    }
    runs[gi - 1].second = runs[gi].second;
    runs.erase(runs.begin() + static_cast<std::ptrdiff_t>(gi));
  }
  for (const auto& [b0, b1] : runs) {
    const int i0 = b0 * m;
    const int i1 = std::min(cx.n - 1, b1 + 1 == blocks ? cx.n - 1 : (b1 + 1) * m - 1);
    r.windows.emplace_back(d.t_s[static_cast<std::size_t>(i0)],
                           d.t_s[static_cast<std::size_t>(i1)]);
  }
}

/// Load region: where in the load space the excess over noise lives.
void LocateLoadRegion(Report& r) {
  const Context& cx = r.cx;
  const auto& d = *cx.data;
  const auto nf = static_cast<double>(r.mismatch_channels.size());
  if (!d.has_wrench()) return;
  std::vector<double> excess(static_cast<std::size_t>(cx.n));
  double mean_ex = 0.0;
  for (int i = 0; i < cx.n; ++i) {
    double e = 0.0;
    for (int c : r.mismatch_channels) e += cx.resid(i, c) * cx.resid(i, c) * cx.weight(c) - 1.0;
    excess[static_cast<std::size_t>(i)] = e / nf;
    mean_ex += e / nf;
  }
  mean_ex /= cx.n;
  double best_eta = 0.0;
  int best_k = -1;
  int best_bin = 0;
  double best_bin_mean = 0.0;
  double best_lo = 0.0;
  double best_hi = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double peak = d.wrench.col(k).cwiseAbs().maxCoeff();
    if (peak <= 0) continue;
    double sum[6] = {};
    double cnt[6] = {};
    for (int i = 0; i < cx.n; ++i) {
      const double u = d.wrench(i, k) / peak;
      const int mag = std::min(2, static_cast<int>(std::fabs(u) * 3.0));
      const int bin = (u >= 0 ? 3 : 0) + mag;
      sum[bin] += excess[static_cast<std::size_t>(i)];
      cnt[bin] += 1.0;
    }
    double between = 0.0;
    double total = 0.0;
    for (int i = 0; i < cx.n; ++i)
      total += (excess[static_cast<std::size_t>(i)] - mean_ex) *
               (excess[static_cast<std::size_t>(i)] - mean_ex);
    int top = -1;
    double top_mean = -std::numeric_limits<double>::infinity();
    for (int b = 0; b < 6; ++b) {
      if (cnt[b] < 20) continue;
      const double mb = sum[b] / cnt[b];
      between += cnt[b] * (mb - mean_ex) * (mb - mean_ex);
      if (mb > top_mean) {
        top_mean = mb;
        top = b;
      }
    }
    const double eta = total > 0 ? between / total : 0.0;
    if (top >= 0 && eta > best_eta) {
      best_eta = eta;
      best_k = k;
      best_bin = top;
      best_bin_mean = top_mean;
      const int mag = top % 3;
      const double a = peak * mag / 3.0;
      const double b = peak * (mag + 1) / 3.0;
      best_lo = top >= 3 ? a : -b;
      best_hi = top >= 3 ? b : -a;
    }
  }
  if (best_k >= 0 && best_eta > 0.01) {
    r.load_region = {{"component", kWrenchNames[best_k]},  {"sign", best_bin >= 3 ? "+" : "-"},
                     {"range", {best_lo, best_hi}},        {"excess_ratio", 1.0 + best_bin_mean},
                     {"mean_excess_ratio", 1.0 + mean_ex}, {"eta_squared", best_eta}};
  } else {
    r.load_region = {{"component", nullptr}, {"note", "the excess does not depend on the load"}};
  }
}

void Locate(Report& r) {
  const Context& cx = r.cx;
  const auto m = static_cast<int>(std::llround(cx.block_s * cx.rate_hz));
  const int blocks = std::max(1, cx.n / std::max(1, m));
  LocateChannels(r, m, blocks);
  if (r.mismatch_channels.empty()) return;
  LocateWindows(r, m, blocks);
  LocateLoadRegion(r);
}

/// FTDIAG_DEBUG: the time one fit took, on stderr.
void DebugTime(const char* stage, const char* what, std::chrono::steady_clock::time_point t0) {
  static const bool on = std::getenv("FTDIAG_DEBUG") != nullptr;
  if (!on) return;
  const double s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::fprintf(stderr, "time %-8s %-40s %7.3f s\n", stage, what, s);
}

void Progress(const DiagnoseOptions& o, double f, const char* what) {
  if (o.progress != nullptr) o.progress(f, what, o.progress_user);
}

/// Backfits two effects, twice: B on target − A (A first fitted alone), then A on target − B.
/// b0, when given, is B already fitted to target − A0 (the same fit the first step would make).
bool FitPair(const Context& cx, const Mat& target, const EffectSpec& a, const EffectSpec& b,
             const EffectFit& a0, EffectFit* b0, EffectFit* fa, EffectFit* fb) {
  const EffectFit* first = &a0;
  for (int it = 0; it < 2; ++it) {
    if (it == 0 && b0 != nullptr) {
      *fb = std::move(*b0);
    } else {
      fb->pred = Mat();  // memory: the previous B is replaced; only `first` is used now
      auto nb = b.fit(cx, target - first->pred);
      if (!nb) return false;
      *fb = std::move(*nb);
      if (first == fa) fa->pred = Mat();  // the previous A is replaced below
    }
    auto na = a.fit(cx, target - fb->pred);
    if (!na) return false;
    *fa = std::move(*na);
    first = fa;
  }
  return true;
}

/// A time-based partner of a load effect that one offset per load hold explains as well (a misfit
/// of the first effect's shape left from hold to hold, which a time curve follows) is not
/// claimed: the data cannot tell it from the first effect's remainder. Returns the partner's
/// confounding when it stays (empty otherwise).
std::vector<Confounding> DropUnidentifiedPartner(const Context& cx, double z_claim,
                                                 std::vector<EffectFit>* claimed,
                                                 std::vector<std::string>* dropped) {
  std::vector<Confounding> partner_conf;
  if (claimed->size() != 2 || IsTimeBased((*claimed)[0].name)) return partner_conf;
  const Mat rest = cx.resid - (*claimed)[0].pred;
  partner_conf.push_back(CheckConfounders(cx, rest, (*claimed)[1], z_claim));
  const auto& with = partner_conf.back().with;
  if (std::find(with.begin(), with.end(), "hold_offsets") != with.end()) {
    dropped->push_back((*claimed)[1].name + ": " + partner_conf.back().words);
    claimed->pop_back();
    partner_conf.clear();
  }
  return partner_conf;
}

/// The residual spectrum for the report, whitened and averaged over channels.
void ReportSpectrum(Report& r) {
  const Context& cx = r.cx;
  const auto rows = static_cast<std::size_t>(cx.n);
  const std::size_t seg = WelchSegment(rows);
  if (rows >= seg && seg >= 32) {
    for (int c = 0; c < cx.nc; ++c) {
      const Spectrum s = Welch(cx.resid.col(c).data(), rows, cx.rate_hz, seg);
      if (r.spectrum_power.empty()) {
        r.spectrum_hz = s.freq_hz;
        r.spectrum_power.assign(s.power.size(), 0.0);
      }
      for (std::size_t k = 0; k < s.power.size(); ++k)
        r.spectrum_power[k] += s.power[k] * cx.weight(c) / cx.nc;
    }
  }
}

/// Every effect fitted alone to the residual and scored on the held-out rows, best first; each is
/// listed among the report's candidates.
std::vector<Scored> FitSingles(Report& r, const DiagnoseOptions& options, const Sums& base) {
  const Context& cx = r.cx;
  std::vector<Scored> singles;
  const auto& effects = Effects();
  singles.reserve(effects.size());  // no reallocation (it would copy the kept predictions)
  for (std::size_t j = 0; j < effects.size(); ++j) {
    Progress(options, 0.05 + 0.6 * static_cast<double>(j) / static_cast<double>(effects.size()),
             effects[j].name);
    const auto t0 = std::chrono::steady_clock::now();
    auto fit = effects[j].fit(cx, cx.resid);
    DebugTime("single", effects[j].name, t0);
    if (!fit) continue;
    singles.push_back(ScoreFit(cx, cx.resid, std::move(*fit), base.hold_sse, options.z_claim));
    Scored& s = singles.back();
    s.hold_rms_after = HoldRms(cx, cx.resid, &s.fit.pred);
    // Memory (n × N per prediction): only the kPairStarts best eligible singles are used again
    // (the claim and the pair starts); every other prediction is released at once.
    if (!s.eligible) {
      s.fit.pred = Mat();
      continue;
    }
    std::vector<Scored*> kept;
    for (auto& q : singles) {
      if (q.eligible && q.fit.pred.size() > 0) kept.push_back(&q);
    }
    if (kept.size() > kPairStarts) {
      auto lowest =
          std::min_element(kept.begin(), kept.end(),
                           [](const Scored* a, const Scored* b) { return a->score < b->score; });
      (*lowest)->fit.pred = Mat();
    }
  }
  std::sort(singles.begin(), singles.end(),
            [](const Scored& a, const Scored& b) { return a.score > b.score; });
  for (const auto& s : singles) {
    CandidateScore c;
    c.name = s.fit.name;
    c.variant = s.fit.variant;
    c.n_params = s.fit.n_params;
    c.hold_rms_after = s.hold_rms_after;
    c.z = s.z;
    c.score = s.score;
    c.eligible = s.eligible;
    r.candidates.push_back(c);
  }
  return singles;
}

/// Pairs: the best single with each other eligible candidate among the top six, backfitted.
/// True with *pa, *pb set when a pair beats every model so far.
bool BestPair(const Context& cx, const DiagnoseOptions& options, std::vector<Scored>& singles,
              const Sums& base, EffectFit* pa, EffectFit* pb) {
  const Scored& best = singles.front();
  const auto& effects = Effects();
  bool have_pair = false;
  double pair_score = best.score;
  // Forward selection from each of the three best eligible singles: every other effect is fitted
  // to what the first leaves, the two best partners are kept, the first is refitted to what the
  // partner leaves, and the pair is scored on the held-out rows.
  std::vector<std::size_t> top;
  for (std::size_t j = 0; j < singles.size() && top.size() < kPairStarts; ++j) {
    if (singles[j].eligible && singles[j].fit.pred.size() > 0 &&
        singles[j].score >= 0.5 * best.score) {
      top.push_back(j);
    }
  }
  std::size_t step = 0;
  for (std::size_t x : top) {
    const Scored& first = singles[x];
    const Mat rest = cx.resid - first.fit.pred;
    const Sums rest_base = Score(cx, rest, nullptr);
    std::vector<std::pair<double, std::string>> partners;
    // The fits of the best partners so far, reused as the first step of the backfit (FitPair);
    // the others are released at once (memory: n × N each).
    std::vector<std::pair<std::pair<double, std::string>, EffectFit>> partner_fits;
    for (const auto& spec : effects) {
      Progress(options,
               0.65 + 0.33 * static_cast<double>(step++) / static_cast<double>(3 * effects.size()),
               "pairs");
      if (first.fit.name == spec.name) continue;
      // Partners come from the effects that were claimable on their own.
      const bool claimable = std::any_of(singles.begin(), singles.end(), [&](const Scored& q) {
        return q.eligible && q.fit.name == spec.name;
      });
      if (!claimable) continue;
      const auto t0 = std::chrono::steady_clock::now();
      auto fb = spec.fit(cx, rest);
      DebugTime("partner", spec.name, t0);
      if (!fb) continue;
      Scored sb = ScoreFit(cx, rest, std::move(*fb), rest_base.hold_sse, options.z_claim);
      if (!sb.eligible) continue;
      partners.emplace_back(sb.score, spec.name);
      partner_fits.emplace_back(partners.back(), std::move(sb.fit));
      if (partner_fits.size() > kPairPartners) {
        partner_fits.erase(
            std::min_element(partner_fits.begin(), partner_fits.end(),
                             [](const auto& u, const auto& v) { return u.first < v.first; }));
      }
    }
    std::sort(partners.rbegin(), partners.rend());
    for (std::size_t y = 0; y < std::min<std::size_t>(kPairPartners, partners.size()); ++y) {
      const EffectSpec* sa = FindEffect(first.fit.name);
      const EffectSpec* sb = FindEffect(partners[y].second);
      EffectFit* b0 = nullptr;
      for (auto& pf : partner_fits) {
        if (pf.first == partners[y]) b0 = &pf.second;
      }
      EffectFit fa;
      EffectFit fb;
      const auto t0 = std::chrono::steady_clock::now();
      const bool ok = FitPair(cx, cx.resid, *sa, *sb, first.fit, b0, &fa, &fb);
      DebugTime("backfit", (std::string(sa->name) + "+" + sb->name).c_str(), t0);
      if (!ok) continue;
      const Sums s = ScoreSum(cx, cx.resid, fa.pred, fb.pred);
      const double delta = base.hold_sse - s.hold_sse;
      const double score = delta - (fa.n_params + fb.n_params) * HoldPenalty(cx);
      // The partner must add a significant held-out improvement over the first alone …
      double dd = 0.0;
      for (int c = 0; c < cx.nc; ++c) {
        for (int i = 0; i < cx.n; ++i) {
          if (cx.train[static_cast<std::size_t>(i)]) continue;
          const double diff = (fa.pred(i, c) + fb.pred(i, c)) - first.fit.pred(i, c);
          dd += diff * diff * cx.weight(c);
        }
      }
      const double inc = first.hold_sse - s.hold_sse;
      const double z_inc = dd > 0 ? inc / (2.0 * std::sqrt(dd)) : 0.0;
      // … and carry a visible share (≥ 0.2 %) of the excess over noise, not a misfit's remainder.
      const double excess = base.hold_sse - static_cast<double>(cx.n_hold) * cx.nc;
      if (std::getenv("FTDIAG_DEBUG") != nullptr) {
        std::fprintf(
            stderr, "pair %s + %s: score %.1f (best single %.1f) z_inc %.1f inc %.1f excess %.1f\n",
            fa.name.c_str(), fb.name.c_str(), score, best.score, z_inc, inc, excess);
      }
      // … and the pair must beat every model so far on the penalised held-out score.
      if (z_inc > options.z_claim && inc > 0.002 * excess && score > pair_score) {
        pair_score = score;
        *pa = std::move(fa);
        *pb = std::move(fb);
        have_pair = true;
      }
    }
    // Memory: a start other than the best single is not used again.
    if (x != 0) singles[x].fit.pred = Mat();
  }
  return have_pair;
}

/// Thermal refinement of the claimed effects (see the comment inside).
void RefineThermal(const Context& cx, std::vector<EffectFit>* claimed_effects) {
  std::vector<EffectFit>& claimed = *claimed_effects;
  // A claimed thermal_zero_drift is refined with a thermometer lag τ ≥ 0 where the lag pays for
  // itself (effects/thermal_lag.cpp); ranked without it, so a lag never wins a claim on its own.
  // A claimed zero_drift is replaced by a lagged thermal_zero_drift where temperature exists and
  // the lagged model scores better on the held-out rows (penalised like the ranking): a gauge
  // temperature lagging the thermometer otherwise loses to a drift in time.
  const double log_hold = std::log(std::max<double>(2.0, static_cast<double>(cx.n_hold)));
  for (std::size_t k = 0; k < claimed.size(); ++k) {
    const bool thermal = claimed[k].name == "thermal_zero_drift";
    if (!thermal && !(claimed[k].name == "zero_drift" && !cx.dtemp.empty())) continue;
    Mat rest = cx.resid;
    for (std::size_t o = 0; o < claimed.size(); ++o) {
      if (o != k) rest -= claimed[o].pred;
    }
    auto lagged = FitThermalZeroLagged(cx, rest);
    if (!lagged || !lagged->params.contains("lag_s")) continue;
    const double cost_old =
        Score(cx, rest, &claimed[k].pred).hold_sse + claimed[k].n_params * log_hold;
    const double cost_new = Score(cx, rest, &lagged->pred).hold_sse + lagged->n_params * log_hold;
    if (thermal || cost_new < cost_old) claimed[k] = std::move(*lagged);
  }
}

/// The claimed effects into the report, each with its held-out gain and confounders; the verdict.
void RecordClaims(Report& r, const DiagnoseOptions& options, std::vector<EffectFit>& claimed,
                  const std::vector<Confounding>& partner_conf) {
  const Context& cx = r.cx;
  Mat cum = Mat::Zero(cx.n, cx.nc);
  for (std::size_t k = 0; k < claimed.size(); ++k) {
    EffectFit& f = claimed[k];
    ClaimedEffect ce;
    ce.hold_rms_before = HoldRms(cx, cx.resid, &cum);
    cum += f.pred;
    ce.hold_rms_after = HoldRms(cx, cx.resid, &cum);
    ce.rms_after = ChannelRms(cx.resid - cum);
    // Each effect is tested against its confounders on what the other claimed effects leave.
    const Confounding conf =
        k == 1 && !partner_conf.empty()
            ? partner_conf.front()
            : CheckConfounders(cx, cx.resid - (cum - f.pred), f, options.z_claim);
    ce.confounded_with = conf.with;
    ce.confounding = conf.words;
    ce.fit = std::move(f);
    r.effects.push_back(std::move(ce));
  }
  r.model = cum;
  r.verdict = "undetermined";
  for (const auto& e : r.effects) {
    if (e.confounded_with.empty()) {
      r.verdict = e.fit.name;
      break;
    }
  }
  // The noise reported is re-estimated once the claimed effects are removed (broadband effects
  // such as ringing or skew on fast edges lift the spectrum's median a little).
  for (int c = 0; c < cx.nc; ++c) {
    const Vec rest = cx.resid.col(c) - cum.col(c);
    r.noise_rms(c) = std::min(r.noise_rms(c),
                              RobustNoise(rest.data(), static_cast<std::size_t>(cx.n), cx.rate_hz));
  }
  r.hold_rms_after = HoldRms(cx, cx.resid, &cum);
}

}  // namespace

Report DiagnoseOnce(const DiagData& data, const DiagnoseOptions& options,
                    const Eigen::VectorXd* sigma);

Report Diagnose(const DiagData& data, const DiagnoseOptions& options) {
  Report r = DiagnoseOnce(data, options, nullptr);
  // A strong broadband effect (skew on fast edges, ringing) lifts the spectrum's median and so the
  // first noise estimate; when the claimed model reveals a clearly lower noise, diagnose again
  // with it so that weaker effects are weighed against the true noise.
  if (!r.effects.empty()) {
    bool lower = false;
    for (int c = 0; c < r.noise_rms.size(); ++c)
      lower = lower || r.noise_rms(c) < 0.8 * r.cx.sigma(c);
    if (lower) {
      const Eigen::VectorXd sigma = r.noise_rms;
      r = Report();  // release the first pass (its context and model) before the second
      r = DiagnoseOnce(data, options, &sigma);
    }
  }
  return r;
}

Report DiagnoseOnce(const DiagData& data, const DiagnoseOptions& options,
                    const Eigen::VectorXd* sigma) {
  Report r;
  Progress(options, 0.0, "noise and hold-out split");
  auto t0 = std::chrono::steady_clock::now();
  r.cx = MakeContext(data, options.block_s, sigma);
  DebugTime("context", "", t0);
  const Context& cx = r.cx;
  r.rate_hz = cx.rate_hz;
  r.noise_rms = cx.sigma;
  r.rms_before = ChannelRms(cx.resid);
  r.hold_rms_before = HoldRms(cx, cx.resid, nullptr);
  r.hold_rms_after = r.hold_rms_before;
  Locate(r);
  ReportSpectrum(r);
  const Sums base = Score(cx, cx.resid, nullptr);
  std::vector<Scored> singles = FitSingles(r, options, base);
  if (singles.empty() || !singles.front().eligible) {
    r.model = Mat::Zero(cx.n, cx.nc);  // allocated only now: nothing claimed
    Progress(options, 1.0, "done");
    return r;
  }
  EffectFit pa;
  EffectFit pb;
  const bool have_pair = options.pairs && BestPair(cx, options, singles, base, &pa, &pb);
  std::vector<EffectFit> claimed;
  if (have_pair) {
    // Stronger first: the one whose removal from the pair costs more on held-out rows.
    const Sums only_a = Score(cx, cx.resid, &pa.pred);
    const Sums only_b = Score(cx, cx.resid, &pb.pred);
    if (only_b.hold_sse < only_a.hold_sse) std::swap(pa, pb);
    claimed.push_back(std::move(pa));
    claimed.push_back(std::move(pb));
  } else {
    claimed.push_back(std::move(singles.front().fit));
  }
  singles.clear();  // memory: the kept single predictions are not used again
  singles.shrink_to_fit();
  RefineThermal(cx, &claimed);
  const std::vector<Confounding> partner_conf =
      DropUnidentifiedPartner(cx, options.z_claim, &claimed, &r.dropped);
  RecordClaims(r, options, claimed, partner_conf);
  Progress(options, 1.0, "done");
  return r;
}

}  // namespace ftstack::diag
