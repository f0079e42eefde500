// The diagnosis pipeline (diagnose.hpp), stage by stage, in the order DiagnoseWith runs them:
//   1. load         loader/: both recordings read, converted to mV/V and aligned (DiagData)
//   2. context      residual real − sim, noise per channel, the converter's grid, hold-out blocks
//   3. locate       locate.cpp: the channels, windows and load region that exceed the noise
//   4. candidates   ranking.cpp: every effect plug-in solved alone by the engine (solve.hpp:
//                   search, bounds, σ, status per parameter), scored on the held-out rows and
//                   ranked by its penalised score; a fit that is not resolved never starts a claim
//   5. pairs        ranking.cpp: forward selection from the best starts, backfitted
//   6. refine       claims.cpp: refinements; a partner the data cannot identify dropped; a third
//   7. pieces       claims.cpp: spreads across pieces of the record; the claim rule once more
//   8. confounders  claims.cpp, identifiability.cpp: each claim against its row of the confounder
//      and hold-out table on held-out rows, its held-out gain, the verdict
//   9. report       report/: JSON and HTML (written by the caller)
// stages.hpp gives each stage its share of the progress bar.
#include "diagnosis/engine/claims.hpp"
#include "diagnosis/engine/diagnose.hpp"
#include "diagnosis/engine/locate.hpp"
#include "diagnosis/engine/memory.hpp"
#include "diagnosis/engine/ranking.hpp"
#include "diagnosis/engine/stages.hpp"

#include <chrono>
#include <cstdio>

namespace ftstack::diag {

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

/// Stage 5: the best pair when one beats the best single, stronger first (the one whose removal
/// from the pair costs more on held-out rows); else the best single alone. *backfit_threads: the
/// threads the pairs' backfits ran on (BestPair).
std::vector<EffectFit> FirstClaims(const Context& cx, const DiagnoseOptions& options,
                                   std::vector<Scored>& singles, const Sums& base, bool* have_pair,
                                   int* backfit_threads) {
  EffectFit pa;
  EffectFit pb;
  const auto t0 = std::chrono::steady_clock::now();
  *have_pair = options.pairs && BestPair(cx, options, singles, base, &pa, &pb, backfit_threads);
  DebugTime("stage", "pairs", t0);
  std::vector<EffectFit> claimed;
  if (*have_pair) {
    const Sums only_a = Score(cx, cx.resid, &pa.pred);
    const Sums only_b = Score(cx, cx.resid, &pb.pred);
    if (only_b.hold_sse < only_a.hold_sse) std::swap(pa, pb);
    claimed.push_back(std::move(pa));
    claimed.push_back(std::move(pb));
  } else {
    claimed.push_back(std::move(singles.front().fit));
  }
  return claimed;
}

}  // namespace

Report Diagnose(const DiagData& data, const DiagnoseOptions& options) {
  Progress(options, Stage::kSplit, 0.0, "noise and hold-out split");
  return WithRefinedNoise(
      DiagnoseWith(MakeContext(data, options.block_s, nullptr, options.threads), options), options);
}

Report Diagnose(DiagData* data, const DiagnoseOptions& options) {
  Progress(options, Stage::kSplit, 0.0, "noise and hold-out split");
  return WithRefinedNoise(
      DiagnoseWith(MakeContext(data, options.block_s, nullptr, options.threads), options), options);
}

Report DiagnoseOnce(const DiagData& data, const DiagnoseOptions& options,
                    const Eigen::VectorXd* sigma) {
  return DiagnoseWith(MakeContext(data, options.block_s, sigma, options.threads), options);
}

Report DiagnoseWith(Context context, const DiagnoseOptions& options) {
  // 2. context (made by the caller: MakeContext)
  Report r;
  auto t0 = std::chrono::steady_clock::now();
  r.cx = std::move(context);
  ReturnFreedPages();  // the reading's columns, copied into the context
  DebugTime("context", "", t0);
  const Context& cx = r.cx;
  r.rate_hz = cx.rate_hz;
  r.noise_rms = cx.sigma;
  r.rms_before = ChannelRms(cx.resid);
  r.hold_rms_before = HoldRms(cx, cx.resid, nullptr);
  r.hold_rms_after = r.hold_rms_before;
  // 3. locate
  Locate(r);
  ReportSpectrum(r);
  // 4. candidates
  const Sums base = Score(cx, cx.resid, nullptr);
  t0 = std::chrono::steady_clock::now();
  std::vector<Scored> singles = FitSingles(r, options, base);
  ReturnFreedPages();  // the candidates' buffers (all but the pair starts' predictions)
  DebugTime("stage", "singles", t0);
  if (singles.empty() || !singles.front().eligible) {
    r.model = Series::Zero(cx.n, cx.nc);  // allocated only now: nothing claimed
    Progress(options, Stage::kDone, 0.0, "done");
    return r;
  }
  // 5. pairs
  bool have_pair = false;
  int backfit_threads = 0;
  std::vector<EffectFit> claimed =
      FirstClaims(cx, options, singles, base, &have_pair, &backfit_threads);
  // The growth stage starts from the significant singles' fits (their predictions released).
  const std::vector<EffectFit> near =
      have_pair ? SignificantFits(singles) : std::vector<EffectFit>();
  singles.clear();  // memory: the kept single predictions are not used again
  singles.shrink_to_fit();
  ReturnFreedPages();  // … nor the partners' and backfits' buffers
  // 6. refine
  t0 = std::chrono::steady_clock::now();
  RefineClaims(cx, &claimed);
  DebugTime("claims", "refinements", t0);
  std::vector<Confounding> partner_conf =
      DropUnidentifiedPartner(cx, options, &claimed, &r.dropped, backfit_threads);
  ReturnFreedPages();  // the confounders' joint fits
  DebugTime("claims", "partner identifiability", t0);
  // A third refits the pair beside it: the partner's confounders are then checked anew.
  if (claimed.size() == 2 && GrowThird(cx, options, near, &claimed)) partner_conf.clear();
  ReturnFreedPages();  // the thirds' fits and backfits
  DebugTime("stage", "third", t0);
  // 7. pieces
  SpreadClaims(&r.cx, &claimed);
  DropContradictedClaims(r.cx, &claimed, &r.dropped);
  DebugTime("claims", "spreads across pieces", t0);
  // 8. confounders and hold-out
  RecordClaims(r, options, claimed, partner_conf);
  DebugTime("claims", "claims and confounders", t0);
  LocateByModel(r);
  DebugTime("stage", "claims", t0);
  if (DebugOn() && r.cx.lag_cache) {
    std::fprintf(stderr, "lag memo: %llu found, %llu filtered\n",
                 static_cast<unsigned long long>(r.cx.lag_cache->hits()),
                 static_cast<unsigned long long>(r.cx.lag_cache->misses()));
  }
  // 9. report: the caller's writers (report/)
  Progress(options, Stage::kDone, 0.0, "done");
  return r;
}

}  // namespace ftstack::diag
