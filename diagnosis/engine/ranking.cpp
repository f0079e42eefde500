#include "diagnosis/engine/ranking.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/engine/identifiability.hpp"
#include "diagnosis/engine/parallel.hpp"
#include "diagnosis/engine/plausibility.hpp"

namespace ftstack::diag {
namespace {

double HoldPenalty(const Context& cx) {
  return std::log(std::max(2.0, static_cast<double>(cx.n_hold) * cx.nc));
}

Scored ScoreFit(const Context& cx, const Series& target, EffectFit fit, double base_hold,
                double z_claim) {
  Scored s;
  const Sums sums = Score(cx, target, &fit.pred);
  s.hold_sse = sums.hold_sse;
  s.delta = base_hold - sums.hold_sse;
  s.z = sums.hold_pp > 0 ? s.delta / (2.0 * std::sqrt(sums.hold_pp)) : 0.0;
  s.score = s.delta - fit.n_params * HoldPenalty(cx);
  // A fit on a search bound or outside its physical range is never claimed, however it scores.
  fit.not_resolved = NotResolved(cx, fit);
  s.significant = s.z > z_claim && s.score > 0;
  s.eligible = s.significant && fit.not_resolved.empty();
  s.fit = std::move(fit);
  return s;
}

/// target − the start's prediction.
Series Remainder(const Series& target, const Scored& start) { return target - start.fit.pred; }

/// Backfits two effects, twice: B on target − A (A first fitted alone: a0, with a0_rest = target −
/// its prediction), then A on target − B. Every fit starts from the effect's previous one
/// (FitNear; B's first from b_near, its fit to what A0 leaves). The first pass's fits skip the
/// parameters' uncertainties: only the second pass's fits are kept (and reported).
/// Memory: each remainder is formed in the memory of the prediction it removes (target − p in
/// place), so a fit holds one n × N remainder and no other prediction. The last B's prediction is
/// restored from its remainder afterwards, target − (target − p): p to within an ulp of the
/// target.
bool FitPair(const Context& cx, const Series& target, const EffectSpec& a, const EffectSpec& b,
             const EffectFit& a0, Series a0_rest, const EffectFit* b_near, EffectFit* fa,
             EffectFit* fb) {
  const EffectFit* first = &a0;
  for (int it = 0; it < 2; ++it) {
    fb->pred = Series();  // the previous B is replaced; only `first` is used now
    Series rest;
    if (it == 0) {
      rest = std::move(a0_rest);
    } else {  // the previous A is refitted below (near its parameters)
      fa->pred = target - fa->pred;
      rest = std::move(fa->pred);
    }
    auto nb = FitNear(b, cx, rest, it == 0 ? b_near : fb, it == 1);
    rest = Series();
    if (!nb) return false;
    *fb = std::move(*nb);
    fb->pred = target - fb->pred;  // now A's remainder
    auto na = FitNear(a, cx, fb->pred, first, it == 1);
    if (!na) return false;
    *fa = std::move(*na);
    first = fa;
    if (it == 1) fb->pred = target - fb->pred;
  }
  return true;
}

/// Indices of `effects` costliest first (the order parallel fits are started in).
std::vector<std::size_t> CostOrder(const std::vector<EffectSpec>& effects) {
  std::vector<std::size_t> order(effects.size());
  for (std::size_t j = 0; j < order.size(); ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t u, std::size_t v) { return effects[u].cost > effects[v].cost; });
  return order;
}

/// Keeps the predictions of the `keep` best eligible fits in `all` and releases the others'
/// (memory: n × N each); the result does not depend on the order the fits arrived in.
void KeepBestPredictions(std::vector<std::optional<Scored>>* all, std::size_t keep) {
  std::vector<Scored*> kept;
  for (auto& q : *all) {
    if (q && q->eligible && q->HasPrediction()) kept.push_back(&*q);
  }
  const auto by_score = [](const Scored* u, const Scored* v) { return u->score < v->score; };
  while (kept.size() > keep) {
    auto lowest = std::min_element(kept.begin(), kept.end(), by_score);
    (*lowest)->fit.pred = Series();
    kept.erase(lowest);
  }
}

/// The fit of effect `name` alone (its prediction may have been released), or nullptr.
const EffectFit* SingleOf(const std::vector<Scored>& singles, const std::string& name) {
  for (const auto& q : singles) {
    if (q.fit.name == name) return &q.fit;
  }
  return nullptr;
}

/// A partner fitted to what a pair's first effect leaves: its score there and its fit's parameters
/// (the prediction is not kept: memory; the backfit refits it near these parameters).
struct Partner {
  std::pair<double, std::string> key;  ///< (score, name)
  EffectFit fit;                       ///< without pred
};

/// For every start (singles[top[t]]), every other effect claimable alone, refitted near its single
/// fit to what the start leaves: the eligible ones per start, best first. All (start, partner)
/// fits run as one parallel batch, costliest first.
std::vector<std::vector<Partner>> FitPartners(const Context& cx, const DiagnoseOptions& options,
                                              const std::vector<Scored>& singles,
                                              const std::vector<std::size_t>& top) {
  const auto& effects = Effects();
  std::vector<std::vector<std::size_t>> todo(top.size());  // per start: effects j
  std::size_t total = 0;
  for (std::size_t j : CostOrder(effects)) {
    // Partners come from the effects that were significant on their own (resolved or not: fitted
    // to what the start leaves, a partner may resolve; the pair is claimed only if it does).
    const bool claimable = std::any_of(singles.begin(), singles.end(), [&](const Scored& q) {
      return q.significant && q.fit.name == effects[j].name;
    });
    for (std::size_t t = 0; t < top.size(); ++t) {
      if (claimable && singles[top[t]].fit.name != effects[j].name) {
        todo[t].push_back(j);
        ++total;
      }
    }
  }
  std::vector<std::vector<Partner>> partners(top.size());
  std::mutex mu;
  std::size_t done = 0;
  // One start at a time, its partners in parallel on one shared remainder (memory: one n × N
  // remainder, not one per running fit).
  for (std::size_t t = 0; t < top.size(); ++t) {
    const Scored& first = singles[top[t]];
    const Series rest = Remainder(cx.resid, first);
    ParallelFor(todo[t].size(), ResolveThreads(options.threads), [&](std::size_t k) {
      const EffectSpec& spec = effects[todo[t][k]];
      const auto t0 = std::chrono::steady_clock::now();
      auto fb = FitNear(spec, cx, rest, SingleOf(singles, spec.name), false);
      DebugTime("partner", spec.name, t0);
      std::optional<Scored> sb;
      // first.hold_sse is the held-out SSE of rest: the baseline the partner is scored against.
      if (fb) sb = ScoreFit(cx, rest, std::move(*fb), first.hold_sse, options.z_claim);
      const std::lock_guard<std::mutex> lock(mu);
      if (sb && sb->eligible) {
        sb->fit.pred = Series();
        partners[t].push_back({{sb->score, spec.name}, std::move(sb->fit)});
      }
      Progress(options, Stage::kPartners, static_cast<double>(++done) / static_cast<double>(total),
               "pairs: partners");
    });
  }
  for (auto& list : partners) {
    std::sort(list.begin(), list.end(),
              [](const Partner& u, const Partner& v) { return u.key > v.key; });
  }
  return partners;
}

/// The pair (first, partner) after backfitting, scored; `won` when it qualifies (below).
struct PairResult {
  EffectFit fa;
  EffectFit fb;
  double score = 0.0;
  bool won = false;
};

/// Backfits first with `partner` and tests the pair: the partner must add a significant held-out
/// improvement over the first alone and carry a visible share of the excess over noise.
std::optional<PairResult> TryPair(const Context& cx, const DiagnoseOptions& options,
                                  const Scored& first, Partner* partner, const Sums& base,
                                  double best_score) {
  const EffectSpec* sa = FindEffect(first.fit.name);
  const EffectSpec* sb = FindEffect(partner->key.second);
  PairResult p;
  const auto t0 = std::chrono::steady_clock::now();
  const bool ok = FitPair(cx, cx.resid, *sa, *sb, first.fit, Remainder(cx.resid, first),
                          &partner->fit, &p.fa, &p.fb);
  DebugTime("backfit", (std::string(sa->name) + "+" + sb->name).c_str(), t0);
  if (!ok) return std::nullopt;
  const Sums s = ScoreSum(cx, cx.resid, p.fa.pred, p.fb.pred);
  const double delta = base.hold_sse - s.hold_sse;
  p.score = delta - (p.fa.n_params + p.fb.n_params) * HoldPenalty(cx);
  // The partner must add a significant held-out improvement over the first alone …
  double dd = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double diff = (static_cast<double>(p.fa.pred(i, c)) + p.fb.pred(i, c)) -
                          static_cast<double>(first.fit.pred(i, c));
      dd += diff * diff * cx.weight(c);
    }
  }
  const double inc = first.hold_sse - s.hold_sse;
  const double z_inc = dd > 0 ? inc / (2.0 * std::sqrt(dd)) : 0.0;
  // … and carry a visible share (≥ 0.2 %) of the excess over noise, not a misfit's remainder.
  const double excess = base.hold_sse - static_cast<double>(cx.n_hold) * cx.nc;
  if (DebugOn()) {
    std::fprintf(stderr,
                 "pair %s + %s: score %.1f (best single %.1f) z_inc %.1f inc %.1f excess %.1f\n",
                 p.fa.name.c_str(), p.fb.name.c_str(), p.score, best_score, z_inc, inc, excess);
  }
  p.won = z_inc > options.z_claim && inc > kVisibleShare * excess &&
          NotResolved(cx, p.fa).empty() && NotResolved(cx, p.fb).empty();
  return p;
}

}  // namespace

double HoldRms(const Context& cx, const Series& target, const Series* pred) {
  double s = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double e = static_cast<double>(target(i, c)) - (pred != nullptr ? (*pred)(i, c) : 0.0);
      s += e * e;
    }
  }
  return std::sqrt(s / std::max(1.0, static_cast<double>(cx.n_hold) * cx.nc));
}

void Progress(const DiagnoseOptions& options, Stage stage, double within, const char* what) {
  if (options.progress == nullptr) return;
  const StageShare& s = kStageShares[static_cast<int>(stage)];
  options.progress(s.from + (s.to - s.from) * within, what, options.progress_user);
}

/// Every effect fitted alone to the residual and scored on the held-out rows, best first; each is
/// listed among the report's candidates. The fits run in parallel (options.threads); the result
/// does not depend on their number.
std::vector<Scored> FitSingles(Report& r, const DiagnoseOptions& options, const Sums& base) {
  const Context& cx = r.cx;
  const auto& effects = Effects();
  std::vector<std::optional<Scored>> slot(effects.size());
  const std::vector<std::size_t> order = CostOrder(effects);
  std::mutex mu;
  std::size_t done = 0;
  ParallelFor(order.size(), ResolveThreads(options.threads), [&](std::size_t k) {
    const std::size_t j = order[k];
    const auto t0 = std::chrono::steady_clock::now();
    auto fit = effects[j].fit(cx, cx.resid);
    DebugTime("single", effects[j].name, t0);
    std::optional<Scored> s;
    if (fit) {
      s = ScoreFit(cx, cx.resid, std::move(*fit), base.hold_sse, options.z_claim);
      s->hold_rms_after = HoldRms(cx, cx.resid, &s->fit.pred);
      // Memory (n × N per prediction): only the kPairStarts best eligible singles are used again
      // (the claim and the pair starts); every other prediction is released at once.
      if (!s->eligible) s->fit.pred = Series();
    }
    const std::lock_guard<std::mutex> lock(mu);
    slot[j] = std::move(s);
    KeepBestPredictions(&slot, kPairStarts);
    Progress(options, Stage::kCandidates,
             static_cast<double>(++done) / static_cast<double>(order.size()), effects[j].name);
  });
  std::vector<Scored> singles;
  for (auto& q : slot) {
    if (q) singles.push_back(std::move(*q));
  }
  // Stable: of equal scores the earlier effect first; a fit that is not resolved after every
  // resolved one (it never starts a claim, whatever its score).
  std::stable_sort(singles.begin(), singles.end(), [](const Scored& a, const Scored& b) {
    const bool ra = a.fit.not_resolved.empty();
    const bool rb = b.fit.not_resolved.empty();
    return ra != rb ? ra : a.score > b.score;
  });
  for (const auto& s : singles) {
    CandidateScore c;
    c.name = s.fit.name;
    c.variant = s.fit.variant;
    c.n_params = s.fit.n_params;
    c.hold_rms_after = s.hold_rms_after;
    c.z = s.z;
    c.score = s.score;
    c.eligible = s.eligible;
    c.not_resolved = s.fit.not_resolved;
    c.parameters = TypedParameters(r.cx, s.fit);
    r.candidates.push_back(c);
  }
  return singles;
}

/// Pairs: forward selection from each of the three best eligible singles: every other effect is
/// fitted to what the first leaves, the best partners are kept, each pair is backfitted and scored
/// on the held-out rows. True with *pa, *pb set when a pair beats every model so far (the best
/// penalised held-out score among the qualifying pairs; independent of the thread count).
bool BestPair(const Context& cx, const DiagnoseOptions& options, std::vector<Scored>& singles,
              const Sums& base, EffectFit* pa, EffectFit* pb, int* backfit_threads) {
  const Scored& best = singles.front();
  bool have_pair = false;
  double pair_score = best.score;
  std::size_t win_order = 0;
  std::vector<std::size_t> top;
  for (std::size_t j = 0; j < singles.size() && top.size() < kPairStarts; ++j) {
    if (singles[j].eligible && singles[j].HasPrediction() && singles[j].score >= 0.5 * best.score) {
      top.push_back(j);
    }
  }
  // Memory: a kept prediction that starts no pair is not used again (only the best single's may
  // be claimed): released before the partners and backfits run.
  for (std::size_t j = 1; j < singles.size(); ++j) {
    if (std::find(top.begin(), top.end(), j) == top.end()) singles[j].fit.pred = Series();
  }
  std::vector<std::vector<Partner>> partners = FitPartners(cx, options, singles, top);
  // Every start with each of its kPairPartners best partners, backfitted: one parallel batch.
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // (start t, partner y)
  for (std::size_t t = 0; t < top.size(); ++t) {
    for (std::size_t y = 0; y < std::min(kPairPartners, partners[t].size()); ++y) {
      pairs.emplace_back(t, y);
    }
  }
  std::mutex mu;
  std::size_t done = 0;
  // Memory: a start's prediction is released once its last pair is done (the best single's only
  // when a pair has won: else it may be claimed alone).
  std::vector<std::size_t> left(top.size(), 0);
  for (const auto& [t, y] : pairs) ++left[t];
  const auto release = [&](std::size_t t) {
    if (top[t] != 0 || have_pair) singles[top[t]].fit.pred = Series();
  };
  *backfit_threads =
      static_cast<int>(std::min<std::size_t>(pairs.size(), ResolveThreads(options.threads)));
  ParallelFor(pairs.size(), ResolveThreads(options.threads), [&](std::size_t k) {
    const auto [t, y] = pairs[k];
    auto p = TryPair(cx, options, singles[top[t]], &partners[t][y], base, best.score);
    const std::lock_guard<std::mutex> lock(mu);
    Progress(options, Stage::kPairs,
             static_cast<double>(++done) / static_cast<double>(pairs.size()), "pairs: backfits");
    --left[t];
    // The best qualifying pair wins; of equal scores the earlier start and better partner (as a
    // sequential search would keep).
    const std::size_t order = t * kPairPartners + y;
    if (p && p->won &&
        (p->score > pair_score || (have_pair && p->score == pair_score && order < win_order))) {
      pair_score = p->score;
      win_order = order;
      *pa = std::move(p->fa);
      *pb = std::move(p->fb);
      have_pair = true;
    }
    p.reset();
    for (std::size_t u = 0; u < top.size(); ++u) {
      if (left[u] == 0) release(u);
    }
  });
  for (std::size_t x : top) {
    if (x != 0) singles[x].fit.pred = Series();
  }
  return have_pair;
}

std::vector<EffectFit> SignificantFits(std::vector<Scored>& singles) {
  std::vector<EffectFit> out;
  for (Scored& q : singles) {
    if (!q.significant) continue;
    q.fit.pred = Series();
    out.push_back(std::move(q.fit));
  }
  return out;
}

namespace {

/// Backfits three effects twice, each refitted near its current fit to what the other two leave;
/// the first pass skips the parameters' uncertainties. False when a refit fails.
bool FitTriple(const Context& cx, std::array<EffectFit, 3>* fits) {
  std::array<const EffectSpec*, 3> spec{};
  for (std::size_t k = 0; k < 3; ++k) spec[k] = FindEffect((*fits)[k].name);
  for (int it = 0; it < 2; ++it) {
    for (std::size_t k = 0; k < 3; ++k) {
      Series rest = cx.resid;
      for (std::size_t o = 0; o < 3; ++o) {
        if (o != k) rest -= (*fits)[o].pred;
      }
      auto f = FitNear(*spec[k], cx, rest, &(*fits)[k], it == 1);
      if (!f) return false;
      (*fits)[k] = std::move(*f);
    }
  }
  return true;
}

/// A candidate for the third claim: its fit to what the pair leaves (with its prediction) and its
/// single fit.
struct ThirdCandidate {
  Scored on_rest;
  const EffectFit* single = nullptr;
};

/// Every candidate refitted near its single fit to what the pair leaves (`rest`; the full grid
/// where the optimum leaves the local window), as the partners are: those significant there,
/// resolved or not (beside the refitted pair they may resolve, and are claimed only if they do),
/// that already carry the visible share of the excess a claim needs (the backfits are what costs:
/// they run only for these), at most kGrowthTries, best first. Only those keep their predictions
/// (memory: n × N each).
std::vector<ThirdCandidate> ScanThirds(const Context& cx, const DiagnoseOptions& options,
                                       const std::vector<const EffectFit*>& todo,
                                       const Series& rest, double rest_hold_sse, double excess) {
  std::vector<std::optional<Scored>> tried(todo.size());
  // The costliest fits start first (the threads then end together); each lands in its own slot.
  std::vector<std::size_t> order(todo.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  const auto cost = [&](std::size_t k) {
    const EffectSpec* spec = FindEffect(todo[k]->name);
    return spec != nullptr ? spec->cost : 0;
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t u, std::size_t v) { return cost(u) > cost(v); });
  std::mutex mu;
  ParallelFor(order.size(), ResolveThreads(options.threads), [&](std::size_t o) {
    const std::size_t k = order[o];
    const EffectSpec* spec = FindEffect(todo[k]->name);
    const auto t0 = std::chrono::steady_clock::now();
    auto f = spec != nullptr ? FitNear(*spec, cx, rest, todo[k], false) : std::nullopt;
    DebugTime("third", todo[k]->name.c_str(), t0);
    std::optional<Scored> q;
    if (f) q = ScoreFit(cx, rest, std::move(*f), rest_hold_sse, options.z_claim);
    if (q && (!q->significant || q->delta <= kVisibleShare * excess)) q.reset();
    const std::lock_guard<std::mutex> lock(mu);
    tried[k] = std::move(q);
    std::vector<Scored*> kept;
    for (auto& t : tried) {
      if (t && t->HasPrediction()) kept.push_back(&*t);
    }
    if (kept.size() > kGrowthTries) {
      (*std::min_element(kept.begin(), kept.end(), [](const Scored* u, const Scored* v) {
        return u->score < v->score;
      }))->fit.pred = Series();
    }
  });
  std::vector<ThirdCandidate> out;
  for (std::size_t k = 0; k < todo.size(); ++k) {
    if (tried[k] && tried[k]->HasPrediction()) out.push_back({std::move(*tried[k]), todo[k]});
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const auto& a, const auto& b) { return a.on_rest.score > b.on_rest.score; });
  return out;
}

/// The candidate backfitted with the pair from two starts, as backfitting finds the optimum
/// nearest its start: as fitted to what the pair leaves, and as fitted alone (refitted near its
/// single fit), the pair then refitted first. A time spline that took a creep's slow part leaves
/// the creep only its fast part in the first; from the second, the pair's drift can find its steps
/// again. The start of lower penalised held-out cost among those that qualify (significant over
/// the pair, a visible share, a gain above its parameters' penalty, all three resolved), if any.
std::optional<std::array<EffectFit, 3>> BackfitThird(const Context& cx, double z_claim,
                                                     const std::vector<EffectFit>& pair,
                                                     const Series& rest, double excess,
                                                     ThirdCandidate* candidate) {
  const double rest_hold_sse = Score(cx, rest, nullptr).hold_sse;
  const double penalty = HoldPenalty(cx);
  const int pair_params = pair[0].n_params + pair[1].n_params;
  std::vector<EffectFit> starts;
  starts.push_back(std::move(candidate->on_rest.fit));
  const EffectSpec& spec = *FindEffect(candidate->single->name);
  if (auto alone = FitNear(spec, cx, cx.resid, candidate->single, false)) {
    starts.push_back(std::move(*alone));
  }
  std::optional<std::array<EffectFit, 3>> best;
  double best_cost = 0.0;
  for (EffectFit& start : starts) {
    std::array<EffectFit, 3> fits{pair[0], pair[1], std::move(start)};
    start = EffectFit();
    if (!FitTriple(cx, &fits)) continue;
    Series model = fits[0].pred + fits[1].pred;
    model += fits[2].pred;
    const Sums s = Score(cx, cx.resid, &model);
    const double inc = rest_hold_sse - s.hold_sse;
    // What the three add over the pair on the held-out rows: model − (resid − rest).
    double dd = 0.0;
    for (int c = 0; c < cx.nc; ++c) {
      for (int i = 0; i < cx.n; ++i) {
        if (!cx.held_out(static_cast<std::size_t>(i))) continue;
        const double d = static_cast<double>(model(i, c)) - cx.resid(i, c) + rest(i, c);
        dd += d * d * cx.weight(c);
      }
    }
    model = Series();
    const double z_inc = dd > 0 ? inc / (2.0 * std::sqrt(dd)) : 0.0;
    const bool resolved = NotResolved(cx, fits[0]).empty() && NotResolved(cx, fits[1]).empty() &&
                          NotResolved(cx, fits[2]).empty();
    const int params = fits[0].n_params + fits[1].n_params + fits[2].n_params;
    const double gain = inc - (params - pair_params) * penalty;
    const double cost = s.hold_sse + params * penalty;
    if (DebugOn()) {
      std::fprintf(stderr,
                   "triple + %s: z_inc %.1f inc %.1f (excess %.1f) gain %.1f resolved %d "
                   "cost %.1f\n",
                   fits[2].name.c_str(), z_inc, inc, excess, gain, resolved ? 1 : 0, cost);
    }
    if (z_inc > z_claim && inc > kVisibleShare * excess && gain > 0 && resolved &&
        (!best || cost < best_cost)) {
      best = std::move(fits);
      best_cost = cost;
    }
  }
  return best;
}

}  // namespace

bool GrowThird(const Context& cx, const DiagnoseOptions& options,
               const std::vector<EffectFit>& near, std::vector<EffectFit>* claimed) {
  if (claimed->size() != 2) return false;
  Series rest = cx.resid - (*claimed)[0].pred;
  rest -= (*claimed)[1].pred;
  std::vector<const EffectFit*> todo;
  for (const EffectFit& f : near) {
    if (f.name != (*claimed)[0].name && f.name != (*claimed)[1].name) todo.push_back(&f);
  }
  const double excess =
      Score(cx, cx.resid, nullptr).hold_sse - static_cast<double>(cx.n_hold) * cx.nc;
  Progress(options, Stage::kThird, 0.0, "a third: candidates");
  std::vector<ThirdCandidate> thirds =
      ScanThirds(cx, options, todo, rest, Score(cx, rest, nullptr).hold_sse, excess);
  for (ThirdCandidate& candidate : thirds) {
    Progress(options, Stage::kThird, 0.5, "a third: backfits");
    auto best = BackfitThird(cx, options.z_claim, *claimed, rest, excess, &candidate);
    if (!best) continue;
    // Identified beside the refitted pair, or not claimed: an offset per hold, a function of the
    // load or a drift in time that explains it as well leaves the pair as it was.
    Series others = cx.resid - (*best)[0].pred;
    others -= (*best)[1].pred;
    const Confounding conf = CheckConfounders(cx, others, (*best)[2], options.z_claim);
    if (DebugOn()) {
      std::fprintf(stderr, "third %s beside the pair: confounded with %zu\n",
                   (*best)[2].name.c_str(), conf.with.size());
    }
    if (!conf.with.empty()) continue;
    claimed->assign(std::make_move_iterator(best->begin()), std::make_move_iterator(best->end()));
    return true;
  }
  return false;
}

}  // namespace ftstack::diag
