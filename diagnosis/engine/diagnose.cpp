#include "diagnosis/engine/diagnose.hpp"

#include "diagnosis/engine/identifiability.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/ranking.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "diagnosis/engine/signal.hpp"
#include "measurement/wrench.hpp"

namespace ftstack::diag {
namespace {

using Mat = Eigen::MatrixXd;
using Vec = Eigen::VectorXd;

/// z of a χ² statistic with ν degrees of freedom (Wilson–Hilferty).
double ChiSquareZ(double x, double nu) {
  if (nu <= 0) return 0.0;
  const double a = 2.0 / (9.0 * nu);
  return (std::cbrt(x / nu) - (1.0 - a)) / std::sqrt(a);
}

/// RMS per channel of a − b (b nullptr: of a), accumulated in double.
Vec ChannelRms(const Series& a, const Series* b = nullptr) {
  Vec v(a.cols());
  for (Eigen::Index c = 0; c < a.cols(); ++c) {
    double s = 0.0;
    for (Eigen::Index i = 0; i < a.rows(); ++i) {
      const double e = static_cast<double>(a(i, c)) - (b != nullptr ? (*b)(i, c) : 0.0f);
      s += e * e;
    }
    v(c) = std::sqrt(s / static_cast<double>(a.rows()));
  }
  return v;
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
    for (int i = 0; i < cx.n; ++i)
      xfull += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c);
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
        xs += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c);
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
    for (int c : r.mismatch_channels)
      e += static_cast<double>(cx.resid(i, c)) * cx.resid(i, c) * cx.weight(c) - 1.0;
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
    r.load_region = {{"component", kWrenchAxisNames[best_k]}, {"sign", best_bin >= 3 ? "+" : "-"},
                     {"range", {best_lo, best_hi}},           {"excess_ratio", 1.0 + best_bin_mean},
                     {"mean_excess_ratio", 1.0 + mean_ex},    {"eta_squared", best_eta}};
  } else {
    r.load_region = {{"component", nullptr}, {"note", "the excess does not depend on the load"}};
  }
}

/// Rows per location block (block_s of rows) and the number of blocks.
std::pair<int, int> LocateBlocks(const Context& cx) {
  const auto m = static_cast<int>(std::llround(cx.block_s * cx.rate_hz));
  return {m, std::max(1, cx.n / std::max(1, m))};
}

/// One-sided normal quantile: z with P(Z > z) = p (bisection on erfc; 0 < p < 0.5).
double UpperZ(double p) {
  double lo = 0.0;
  double hi = 40.0;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

/// Model-informed location, after a claim: a channel the model-free tests missed joins the
/// mismatch channels when the claimed model removes a significant held-out χ² there, by the
/// claim's own statistic on that channel alone. The claim has established the effect; which
/// channels carry it is then N one-channel tests, held at a family-wise error of 0.1 %
/// (Bonferroni: z above the upper 0.001/N quantile, 3.7 for 8 channels). A matched filter sees
/// a weak structured effect (ringing after load steps) that block means and variances cannot.
/// Windows and the load region are then located again on the grown set.
void LocateByModel(Report& r) {
  const Context& cx = r.cx;
  const double z_channel = UpperZ(1e-3 / std::max(1, cx.nc));
  bool grew = false;
  for (int c = 0; c < cx.nc; ++c) {
    if (std::find(r.mismatch_channels.begin(), r.mismatch_channels.end(), c) !=
        r.mismatch_channels.end()) {
      continue;
    }
    double delta = 0.0;
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double e = cx.resid(i, c);
      const double m = r.model(i, c);
      delta += (e * e - (e - m) * (e - m)) * cx.weight(c);
      pp += m * m * cx.weight(c);
    }
    if (pp > 0 && delta / (2.0 * std::sqrt(pp)) > z_channel) {
      r.mismatch_channels.push_back(c);
      grew = true;
    }
  }
  if (!grew) return;
  std::sort(r.mismatch_channels.begin(), r.mismatch_channels.end());
  const auto [m, blocks] = LocateBlocks(cx);
  r.windows.clear();
  r.load_region = nlohmann::json();
  LocateWindows(r, m, blocks);
  LocateLoadRegion(r);
}

void Locate(Report& r) {
  const auto [m, blocks] = LocateBlocks(r.cx);
  LocateChannels(r, m, blocks);
  if (r.mismatch_channels.empty()) return;
  LocateWindows(r, m, blocks);
  LocateLoadRegion(r);
}

/// A time-based partner of a load effect that one offset per load hold or a smooth (quadratic)
/// function of the load explains as well (a misfit of the first effect's shape left as a function
/// of the load, which a time curve follows) is not claimed: the data cannot tell it from the first
/// effect's remainder. Returns the partner's
/// confounding when it stays (empty otherwise).
std::vector<Confounding> DropUnidentifiedPartner(const Context& cx, double z_claim,
                                                 std::vector<EffectFit>* claimed,
                                                 std::vector<std::string>* dropped) {
  std::vector<Confounding> partner_conf;
  if (claimed->size() != 2 || HasTrait((*claimed)[0], kTimeBased)) return partner_conf;
  const Series rest = cx.resid - (*claimed)[0].pred;
  partner_conf.push_back(CheckConfounders(cx, rest, (*claimed)[1], z_claim));
  const auto& with = partner_conf.back().with;
  if (std::find(with.begin(), with.end(), "hold_offsets") != with.end() ||
      std::find(with.begin(), with.end(), "load_polynomial") != with.end()) {
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
      const Vec col = cx.resid.col(c).cast<double>();
      const Spectrum s = Welch(col.data(), rows, cx.rate_hz, seg);
      if (r.spectrum_power.empty()) {
        r.spectrum_hz = s.freq_hz;
        r.spectrum_power.assign(s.power.size(), 0.0);
      }
      for (std::size_t k = 0; k < s.power.size(); ++k)
        r.spectrum_power[k] += s.power[k] * cx.weight(c) / cx.nc;
    }
  }
}

/// Refines the claimed effects whose plug-in has a refine_claim, each fitted to what the other
/// claimed effects leave (ranked without it, so a refinement never wins a claim on its own): the
/// refinement replaces the claim where it applies, or with kRefineOnlyIfBetter only where it scores
/// better on the held-out rows, penalised like the ranking.
void RefineClaims(const Context& cx, std::vector<EffectFit>* claimed_effects) {
  std::vector<EffectFit>& claimed = *claimed_effects;
  const double log_hold = std::log(std::max<double>(2.0, static_cast<double>(cx.n_hold)));
  for (std::size_t k = 0; k < claimed.size(); ++k) {
    const EffectSpec* spec = FindEffect(claimed[k].name);
    if (spec == nullptr || spec->refine_claim == nullptr) continue;
    Series rest = cx.resid;
    for (std::size_t o = 0; o < claimed.size(); ++o) {
      if (o != k) rest -= claimed[o].pred;
    }
    auto refined = spec->refine_claim(cx, rest);
    if (!refined) continue;
    const double cost_old =
        Score(cx, rest, &claimed[k].pred).hold_sse + claimed[k].n_params * log_hold;
    const double cost_new = Score(cx, rest, &refined->pred).hold_sse + refined->n_params * log_hold;
    if (!spec->Has(kRefineOnlyIfBetter) || cost_new < cost_old) claimed[k] = std::move(*refined);
  }
}

/// Each claimed fit's parameter spreads across pieces of the record (PieceSpreads), each refitted
/// to what the other claimed effects leave; pieces that disagree are said in its evidence.
void SpreadClaims(Context* cx, std::vector<EffectFit>* claimed_effects) {
  std::vector<EffectFit>& claimed = *claimed_effects;
  for (std::size_t k = 0; k < claimed.size(); ++k) {
    Series rest = cx->resid;
    for (std::size_t o = 0; o < claimed.size(); ++o) {
      if (o != k) rest -= claimed[o].pred;
    }
    PieceSpreads(cx, rest, &claimed[k]);
    const std::string words = SpreadWords(claimed[k]);
    if (!words.empty()) {
      claimed[k].evidence += "; the pieces of the record scatter beyond the curvature σ: " + words;
    }
  }
}

/// Claims the engine's rule no longer lets stand once their pieces are known (NotResolved: a
/// parameter at a bound, not identified, or whose pieces of the record disagree in sign) are not
/// findings: they leave the claims for r.dropped ("not_claimed"), with the reason. At least one
/// claim is kept only when it stands (an empty list means nothing is claimed).
void DropContradictedClaims(const Context& cx, std::vector<EffectFit>* claimed,
                            std::vector<std::string>* dropped) {
  std::vector<EffectFit> kept;
  for (EffectFit& f : *claimed) {
    const std::string why = NotResolved(cx, f);
    if (why.empty()) {
      kept.push_back(std::move(f));
    } else {
      dropped->push_back(f.name + ": " + why);
    }
  }
  *claimed = std::move(kept);
}

/// The claimed effects into the report, each with its held-out gain and confounders; the verdict.
void RecordClaims(Report& r, const DiagnoseOptions& options, std::vector<EffectFit>& claimed,
                  const std::vector<Confounding>& partner_conf) {
  const Context& cx = r.cx;
  Series cum;  // the claimed effects so far (memory: no n × N buffer for the first's target)
  for (std::size_t k = 0; k < claimed.size(); ++k) {
    EffectFit& f = claimed[k];
    ClaimedEffect ce;
    ce.hold_rms_before = HoldRms(cx, cx.resid, k == 0 ? nullptr : &cum);
    if (k == 0) {
      cum = f.pred;
    } else {
      cum += f.pred;
    }
    ce.hold_rms_after = HoldRms(cx, cx.resid, &cum);
    ce.rms_after = ChannelRms(cx.resid, &cum);
    // Each effect is tested against its confounders on what the other claimed effects leave.
    const auto check = [&] {
      if (k == 0) return CheckConfounders(cx, cx.resid, f, options.z_claim);
      const Series others_left = cx.resid - (cum - f.pred);
      return CheckConfounders(cx, others_left, f, options.z_claim);
    };
    const Confounding conf = k == 1 && !partner_conf.empty() ? partner_conf.front() : check();
    ce.confounded_with = conf.with;
    ce.confounding = conf.words;
    ce.fit = std::move(f);
    r.effects.push_back(std::move(ce));
  }
  r.model = cum.size() > 0 ? std::move(cum) : Series(Series::Zero(cx.n, cx.nc));
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
    const Vec rest = cx.resid.col(c).cast<double>() - r.model.col(c).cast<double>();
    r.noise_rms(c) = std::min(r.noise_rms(c),
                              RobustNoise(rest.data(), static_cast<std::size_t>(cx.n), cx.rate_hz));
  }
  r.hold_rms_after = HoldRms(cx, cx.resid, &r.model);
}

}  // namespace

/// One pass on a context made already (the noise is the context's).
Report DiagnoseWith(Context cx, const DiagnoseOptions& options);

namespace {

/// A strong broadband effect (skew on fast edges, ringing) lifts the spectrum's median and so the
/// first noise estimate; when the claimed model reveals a clearly lower noise, diagnose again
/// with it (on the same context, its noise replaced) so that weaker effects are weighed against
/// the true noise.
Report WithRefinedNoise(Report r, const DiagnoseOptions& options) {
  if (r.effects.empty()) return r;
  bool lower = false;
  for (int c = 0; c < r.noise_rms.size(); ++c)
    lower = lower || r.noise_rms(c) < 0.8 * r.cx.sigma(c);
  if (!lower) return r;
  const Eigen::VectorXd sigma = r.noise_rms;
  Context cx = std::move(r.cx);
  r = Report();  // release the first pass (its model) before the second
  SetNoise(&cx, sigma);
  return DiagnoseWith(std::move(cx), options);
}

}  // namespace

Report Diagnose(const DiagData& data, const DiagnoseOptions& options) {
  Progress(options, 0.0, "noise and hold-out split");
  return WithRefinedNoise(DiagnoseWith(MakeContext(data, options.block_s), options), options);
}

Report Diagnose(DiagData* data, const DiagnoseOptions& options) {
  Progress(options, 0.0, "noise and hold-out split");
  return WithRefinedNoise(DiagnoseWith(MakeContext(data, options.block_s), options), options);
}

Report DiagnoseOnce(const DiagData& data, const DiagnoseOptions& options,
                    const Eigen::VectorXd* sigma) {
  return DiagnoseWith(MakeContext(data, options.block_s, sigma), options);
}

Report DiagnoseWith(Context context, const DiagnoseOptions& options) {
  Report r;
  auto t0 = std::chrono::steady_clock::now();
  r.cx = std::move(context);
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
  t0 = std::chrono::steady_clock::now();
  std::vector<Scored> singles = FitSingles(r, options, base);
  DebugTime("stage", "singles", t0);
  if (singles.empty() || !singles.front().eligible) {
    r.model = Series::Zero(cx.n, cx.nc);  // allocated only now: nothing claimed
    Progress(options, 1.0, "done");
    return r;
  }
  EffectFit pa;
  EffectFit pb;
  t0 = std::chrono::steady_clock::now();
  const bool have_pair = options.pairs && BestPair(cx, options, singles, base, &pa, &pb);
  DebugTime("stage", "pairs", t0);
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
  // The growth stage starts from the significant singles' fits (their predictions released).
  const std::vector<EffectFit> near =
      have_pair ? SignificantFits(singles) : std::vector<EffectFit>();
  singles.clear();  // memory: the kept single predictions are not used again
  singles.shrink_to_fit();
  t0 = std::chrono::steady_clock::now();
  RefineClaims(cx, &claimed);
  DebugTime("claims", "refinements", t0);
  std::vector<Confounding> partner_conf =
      DropUnidentifiedPartner(cx, options.z_claim, &claimed, &r.dropped);
  DebugTime("claims", "partner identifiability", t0);
  // A third refits the pair beside it: the partner's confounders are then checked anew.
  if (claimed.size() == 2 && GrowThird(cx, options, near, &claimed)) partner_conf.clear();
  DebugTime("stage", "third", t0);
  SpreadClaims(&r.cx, &claimed);
  DropContradictedClaims(r.cx, &claimed, &r.dropped);
  DebugTime("claims", "spreads across pieces", t0);
  RecordClaims(r, options, claimed, partner_conf);
  DebugTime("claims", "claims and confounders", t0);
  LocateByModel(r);
  DebugTime("stage", "claims", t0);
  if (DebugOn() && r.cx.lag_cache) {
    std::fprintf(stderr, "lag memo: %llu found, %llu filtered\n",
                 static_cast<unsigned long long>(r.cx.lag_cache->hits()),
                 static_cast<unsigned long long>(r.cx.lag_cache->misses()));
  }
  Progress(options, 1.0, "done");
  return r;
}

}  // namespace ftstack::diag
