#include "diagnosis/engine/claims.hpp"

#include <algorithm>
#include <cmath>

#include "diagnosis/engine/parallel.hpp"
#include "diagnosis/engine/plausibility.hpp"
#include "diagnosis/engine/ranking.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag {

Eigen::VectorXd ChannelRms(const Series& a, const Series* b) {
  Eigen::VectorXd v(a.cols());
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

std::vector<Confounding> DropUnidentifiedPartner(const Context& cx, const DiagnoseOptions& options,
                                                 std::vector<EffectFit>* claimed,
                                                 std::vector<std::string>* dropped,
                                                 int backfit_threads) {
  std::vector<Confounding> partner_conf;
  if (claimed->size() != 2 || HasTrait((*claimed)[0], kTimeBased)) return partner_conf;
  const Series rest = cx.resid - (*claimed)[0].pred;
  partner_conf.push_back(
      CheckConfounders(cx, rest, (*claimed)[1], options.z_claim, backfit_threads));
  const auto& with = partner_conf.back().with;
  if (std::find(with.begin(), with.end(), "hold_offsets") != with.end() ||
      std::find(with.begin(), with.end(), "load_polynomial") != with.end()) {
    dropped->push_back((*claimed)[1].name + ": " + partner_conf.back().words);
    claimed->pop_back();
    partner_conf.clear();
  }
  return partner_conf;
}

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
    const Eigen::VectorXd rest = cx.resid.col(c).cast<double>() - r.model.col(c).cast<double>();
    r.noise_rms(c) = std::min(r.noise_rms(c),
                              RobustNoise(rest.data(), static_cast<std::size_t>(cx.n), cx.rate_hz));
  }
  r.hold_rms_after = HoldRms(cx, cx.resid, &r.model);
}

}  // namespace ftstack::diag
