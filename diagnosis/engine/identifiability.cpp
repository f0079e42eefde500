#include "diagnosis/engine/identifiability.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>

#include "diagnosis/engine/debug.hpp"
#include "diagnosis/engine/parallel.hpp"
#include "diagnosis/engine/signal.hpp"

namespace ftstack::diag {
namespace {

using Mat = Eigen::MatrixXd;

/// Offsets per channel and group from the training rows' mean of `target`; groups without a
/// training row predict 0.
Series GroupOffsets(const Context& cx, const Series& target, const std::vector<int>& group,
                    int groups) {
  Mat sum = Mat::Zero(groups, cx.nc);
  std::vector<double> count(static_cast<std::size_t>(groups), 0.0);
  for (int i = 0; i < cx.n; ++i) {
    if (cx.train[static_cast<std::size_t>(i)] == 0) continue;
    const int g = group[static_cast<std::size_t>(i)];
    sum.row(g) += target.row(i).cast<double>();
    count[static_cast<std::size_t>(g)] += 1.0;
  }
  Series pred(cx.n, cx.nc);
  for (int i = 0; i < cx.n; ++i) {
    const int g = group[static_cast<std::size_t>(i)];
    const double k = count[static_cast<std::size_t>(g)];
    pred.row(i) = k > 0 ? Eigen::RowVectorXf((sum.row(g) / k).cast<float>())
                        : Eigen::RowVectorXf::Zero(cx.nc);
  }
  return pred;
}

/// Number of terms of LoadPolynomial: 1, the 6 wrench components, their 21 products (the
/// report's words say 28).
constexpr int kLoadTerms = 28;

/// Per channel, target ≈ a quadratic polynomial of the reference wrench (each component scaled by
/// its peak), fitted on the training rows: a smooth function of the load, ramps included.
Series LoadPolynomial(const Context& cx, const Series& target) {
  const auto& w = cx.data->wrench;
  Eigen::Matrix<double, 6, 1> scale;
  for (int k = 0; k < 6; ++k) scale(k) = std::max<double>(w.col(k).cwiseAbs().maxCoeff(), 1e-300);
  auto terms = [&](int i, double* x) {
    int j = 0;
    x[j++] = 1.0;
    double u[6];
    for (int k = 0; k < 6; ++k) x[j++] = u[k] = w(i, k) / scale(k);
    for (int k = 0; k < 6; ++k) {
      for (int l = k; l < 6; ++l) x[j++] = u[k] * u[l];
    }
  };
  Series pred(cx.n, cx.nc);
  double x[kLoadTerms];
  for (int c = 0; c < cx.nc; ++c) {
    NormalEq ne(kLoadTerms);
    for (int i = 0; i < cx.n; i += cx.search_stride) {
      if (!cx.train[static_cast<std::size_t>(i)]) continue;
      terms(i, x);
      ne.Add(x, target(i, c));
    }
    const Eigen::VectorXd beta = ne.Solve().beta;
    for (int i = 0; i < cx.n; ++i) {
      terms(i, x);
      pred(i, c) = static_cast<float>(Eigen::Map<const Eigen::VectorXd>(x, kLoadTerms).dot(beta));
    }
  }
  return pred;
}

/// Held-out improvement of `pred` on `target` and its significance (in noise standard deviations
/// of Σ 2·r·p over the held-out rows).
void Improvement(const Context& cx, const Series& target, const Series& pred, double* delta,
                 double* z) {
  const Sums s0 = Score(cx, target, nullptr);
  const Sums s1 = Score(cx, target, &pred);
  *delta = s0.hold_sse - s1.hold_sse;
  *z = *delta / (2.0 * std::sqrt(std::max(s1.hold_pp, 1e-300)));
}

double SpearmanWithTime(const std::vector<double>& temp) {
  const std::size_t n = temp.size();
  std::vector<std::size_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(),
            [&](std::size_t a, std::size_t b) { return temp[a] < temp[b]; });
  std::vector<double> rank(n);
  for (std::size_t r = 0; r < n; ++r) rank[idx[r]] = static_cast<double>(r);
  const double mean = 0.5 * static_cast<double>(n - 1);
  double sxy = 0.0;
  double sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (rank[i] - mean) * (static_cast<double>(i) - mean);
    sxx += (static_cast<double>(i) - mean) * (static_cast<double>(i) - mean);
  }
  return sxx > 0 ? sxy / sxx : 0.0;
}

std::string Fmt(const char* f, double a, double b) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b);
  return buf;
}

/// The rest of a confounding sentence: the effect's held-out improvement beyond the confounder.
std::string BeyondWords(double z_rest, double z_alone) {
  return Fmt(
      " explains it as well: beyond that, the effect improves the held-out rows by z = %.1f "
      "only (alone z = %.1f)",
      z_rest, z_alone);
}

/// The confounding sentence of one offset per load hold where the effect lies within it and only
/// the load states (LoadStateGroups) could tell them apart: the design's limit when the states
/// cannot reach z_claim even for an exact effect, else the effect's z beyond them.
std::string StateWords(int holds, int states, double z_states, double z_rest, double z_claim,
                       double z_alone) {
  const std::string head =
      Fmt("one offset per load hold (%.0f holds: a function of the load's history, tested as one "
          "offset per load state, a load and the load before it: %.0f states)",
          holds, states);
  if (z_states <= z_claim) {
    return head + Fmt(" explains it as well: too few holds repeat a load state for a zero that "
                      "moved to show (even an exact effect would improve the held-out rows "
                      "beyond the states by z = %.1f at most; alone z = %.1f)",
                      z_states, z_alone);
  }
  return head + BeyondWords(z_rest, z_alone);
}

/// The confounding sentences of `effect` joined into one for a person (empty without any).
std::string ConfoundingSentence(const std::string& effect, const std::vector<std::string>& words) {
  std::string all;
  for (std::size_t i = 0; i < words.size(); ++i) all += (i == 0 ? "" : "; ") + words[i];
  if (all.empty()) return all;
  return "The data cannot separate " + effect + " from another explanation: " + all + ".";
}

/// Wrench of every row quantised to 0.5 % of each axis's range.
std::vector<std::array<long long, 6>> LoadKeys(const DiagData& d, int n) {
  std::array<double, 6> step{};
  for (int a = 0; a < 6; ++a) {
    const double range = d.wrench.col(a).maxCoeff() - d.wrench.col(a).minCoeff();
    step[static_cast<std::size_t>(a)] = range > 0 ? 0.005 * range : 1.0;
  }
  std::vector<std::array<long long, 6>> keys(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 6; ++a) {
      keys[static_cast<std::size_t>(i)][static_cast<std::size_t>(a)] =
          std::llround(d.wrench(i, a) / step[static_cast<std::size_t>(a)]);
    }
  }
  return keys;
}

/// One group per load hold (a run of ≥ 0.25 s at one quantised load) together with the movement
/// that leads into it; a new group also at every segment start.
std::vector<int> HoldGroups(const Context& cx, int* groups) {
  const auto keys = LoadKeys(*cx.data, cx.n);
  const int min_run = std::max(3, static_cast<int>(std::lround(0.25 * cx.rate_hz)));
  std::vector<int> g(static_cast<std::size_t>(cx.n), 0);
  int id = 0;
  int run = 1;
  bool counted = false;  // the current run already opened a group
  for (int i = 1; i < cx.n; ++i) {
    const bool restart = !cx.restart.empty() && cx.restart[static_cast<std::size_t>(i)] != 0;
    if (restart) {
      ++id;
      run = 1;
      counted = true;
    } else if (keys[static_cast<std::size_t>(i)] == keys[static_cast<std::size_t>(i - 1)]) {
      ++run;
    } else {
      run = 1;
      counted = false;
    }
    if (run >= min_run && !counted) {
      counted = true;
      // The hold began min_run − 1 rows ago: the group changes after the previous hold.
      if (i > min_run) ++id;
      for (int k = std::max(0, i - min_run + 1); k <= i; ++k) g[static_cast<std::size_t>(k)] = id;
    }
    g[static_cast<std::size_t>(i)] = id;
  }
  *groups = id + 1;
  if (*groups < 2 || *groups * 20 > cx.n) {
    *groups = 0;
    return {};
  }
  return g;
}

/// One group per load state: a hold's quantised load together with the previous hold's (none at
/// a segment's start), from the hold groups `hold` of HoldGroups (each opens at its hold's first
/// row). *states receives the number of states.
std::vector<int> LoadStateGroups(const Context& cx, const std::vector<int>& hold, int holds,
                                 int* states) {
  const auto keys = LoadKeys(*cx.data, cx.n);
  std::vector<int> first(static_cast<std::size_t>(holds), -1);
  for (int i = 0; i < cx.n; ++i) {
    int& f = first[static_cast<std::size_t>(hold[static_cast<std::size_t>(i)])];
    if (f < 0) f = i;
  }
  // Load, a flag for "a previous hold in this segment", the previous hold's load.
  using State = std::array<long long, 13>;
  std::map<State, int> seen;
  std::vector<int> state_of(static_cast<std::size_t>(holds), 0);
  for (int h = 0; h < holds; ++h) {
    const int a = first[static_cast<std::size_t>(h)];
    if (a < 0) continue;
    State s{};
    const auto& load = keys[static_cast<std::size_t>(a)];
    std::copy(load.begin(), load.end(), s.begin());
    const bool restart = !cx.restart.empty() && cx.restart[static_cast<std::size_t>(a)] != 0;
    const int prev = h > 0 ? first[static_cast<std::size_t>(h - 1)] : -1;
    if (prev >= 0 && !restart) {
      s[6] = 1;
      const auto& before = keys[static_cast<std::size_t>(prev)];
      std::copy(before.begin(), before.end(), s.begin() + 7);
    }
    state_of[static_cast<std::size_t>(h)] =
        seen.emplace(s, static_cast<int>(seen.size())).first->second;
  }
  *states = static_cast<int>(seen.size());
  std::vector<int> g(static_cast<std::size_t>(cx.n));
  for (int i = 0; i < cx.n; ++i) {
    g[static_cast<std::size_t>(i)] =
        state_of[static_cast<std::size_t>(hold[static_cast<std::size_t>(i)])];
  }
  return g;
}

/// Noise-weighted power (Σ d²/σ²) on the held-out rows of the part d of `pred` that one offset
/// per group, fitted on the training rows, leaves. Were `pred` exactly true, its gain beyond those
/// offsets would be this power with z ≈ √power / 2: the most the design lets the data show.
double PowerBeyondOffsets(const Context& cx, const Series& pred, const std::vector<int>& group,
                          int groups) {
  const Series off = GroupOffsets(cx, pred, group, groups);
  double power = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double d = static_cast<double>(pred(i, c)) - off(i, c);
      pp += d * d;
    }
    power += pp * cx.weight(c);
  }
  return power;
}

}  // namespace

std::vector<int> ConfounderGroups(const Context& cx, Confounder which, int* groups) {
  const DiagData& d = *cx.data;
  std::vector<int> g;
  *groups = 0;
  if (which == kHoldOffsets) return d.has_wrench() ? HoldGroups(cx, groups) : g;
  if (which == kSegmentOffsets) {
    if (cx.segments < 2 || d.segment.size() != static_cast<std::size_t>(cx.n)) return g;
    *groups = cx.segments;
    return d.segment;
  }
  if (which == kLoadOffsets && d.has_wrench()) {
    const auto keys = LoadKeys(d, cx.n);
    std::map<std::array<long long, 6>, int> seen;
    g.resize(static_cast<std::size_t>(cx.n));
    for (int i = 0; i < cx.n; ++i) {
      g[static_cast<std::size_t>(i)] =
          seen.emplace(keys[static_cast<std::size_t>(i)], static_cast<int>(seen.size()))
              .first->second;
    }
    if (seen.size() < 2 || static_cast<int>(seen.size()) * 20 > cx.n) return {};
    *groups = static_cast<int>(seen.size());
  }
  return g;
}

/// The joint model (the confounder fitted to what the effect leaves, the effect refitted to what
/// the confounder leaves, 3 times from the effect's fit) against the confounder alone (s_alone):
/// the held-out improvement *delta and its z. Memory: one n × N work buffer; the confounder alone
/// is formed again for the spread instead of held.
double JointBeyond(const Context& cx, const Series& target, const EffectFit& fit,
                   const EffectSpec& spec, const std::function<Series(const Series&)>& confounder,
                   const Sums& s_alone, double* delta) {
  Series eff;  // the effect's refit (empty: the effect's own prediction, fit.pred)
  bool eff_zero = false;
  Series conf;  // assigned in the first iteration
  Series work;
  for (int iter = 0; iter < 3; ++iter) {
    work = target - (eff.size() > 0 ? eff : fit.pred);
    eff = Series();
    conf = confounder(work);
    work = target - conf;
    auto refit = spec.fit(cx, work);
    if (!refit) {
      eff_zero = true;
      break;
    }
    eff = std::move(refit->pred);
  }
  work = Series();
  if (eff_zero) eff = Series::Zero(cx.n, cx.nc);
  const Sums s_joint = ScoreSum(cx, target, conf, eff);
  const Series alone = confounder(target);
  // Score(cx, target, &(joint − alone)).hold_pp without an n × N difference matrix.
  double spread = 0.0;
  for (int c = 0; c < cx.nc; ++c) {
    double pp = 0.0;
    for (int i = 0; i < cx.n; ++i) {
      if (!cx.held_out(static_cast<std::size_t>(i))) continue;
      const double p = static_cast<double>(conf(i, c)) + eff(i, c) - alone(i, c);
      pp += p * p;
    }
    spread += pp * cx.weight(c);
  }
  *delta = s_alone.hold_sse - s_joint.hold_sse;
  return *delta / (2.0 * std::sqrt(std::max(spread, 1e-300)));
}

namespace {

/// Tests whether one confounder, fitted in `n_params` parameters, leaves the effect identified
/// (CheckConfounders' test); *z_rest gets the effect's z beyond it.
using BeyondFn =
    std::function<bool(const std::function<Series(const Series&)>&, int n_params, double* z_rest)>;

/// Whether one confounder alone, penalised for its `n_params` like the ranking, scores below the
/// effect (CheckConfounders' shortcut); *s_alone gets the confounder alone's held-out sums.
using SimplerFn =
    std::function<bool(const std::function<Series(const Series&)>&, int n_params, Sums* s_alone)>;

/// The drift in time (the kDriftInTime effect) as a confounder of a temperature-driven effect where
/// the temperature is monotone in time: its sentence, and its name in out->with, when it confounds.
std::string DriftInTimeConfounds(const Context& cx, const Series& target, const BeyondFn& beyond,
                                 Confounding* out) {
  const double rho = SpearmanWithTime(cx.data->temp_c);
  const EffectSpec* drift = FindEffectWith(kDriftInTime);
  if (!(std::fabs(rho) > 0.95) || drift == nullptr) return "";
  const auto in_time = [&](const Series& y) {
    auto f = drift->fit(cx, y);
    return f ? std::move(f->pred) : Series(Series::Zero(cx.n, cx.nc));
  };
  double z_rest = 0.0;
  const auto probe = drift->fit(cx, target);
  if (!probe || beyond(in_time, probe->n_params, &z_rest)) return "";
  out->with.emplace_back(drift->name);
  return Fmt(
      "the temperature is monotone in time (Spearman rho = %.2f), and a drift in time explains it "
      "as well (beyond it z = %.1f)",
      rho, z_rest);
}

/// Where the effect lies within one offset per hold (were it exact, it could not beat them by
/// z_claim) the data cannot decide between the two as fitted. The holds' offsets are then tested
/// in the form the design can refute, a function of the load's history: one offset per load state
/// (the hold's load and the load before it). A zero that moved shows as holds reached the same way
/// whose levels differ by more than the noise allows. An effect with fewer parameters than the
/// holds' offsets is identified by the penalised comparison (`simpler`) as everywhere; with as
/// many it is the same model and that comparison scatter. True when identified; else *words gets
/// the confounding sentence.
bool StatesIdentify(const Context& cx, const EffectFit& fit, double z_claim,
                    const std::vector<int>& hold, int holds, const SimplerFn& simpler,
                    const BeyondFn& beyond, double z_alone, std::string* words) {
  const auto hold_offsets = [&](const Series& y) { return GroupOffsets(cx, y, hold, holds); };
  Sums s_holds;
  if (fit.n_params < holds * cx.nc && simpler(hold_offsets, holds * cx.nc, &s_holds)) return true;
  int states = 0;
  const std::vector<int> sg = LoadStateGroups(cx, hold, holds, &states);
  const double z_states = std::sqrt(PowerBeyondOffsets(cx, fit.pred, sg, states)) / 2.0;
  const auto state_offsets = [&](const Series& y) { return GroupOffsets(cx, y, sg, states); };
  double z_rest = 0.0;
  const bool identified = z_states > z_claim && beyond(state_offsets, states * cx.nc, &z_rest);
  if (DebugOn()) {
    std::fprintf(stderr,
                 "confounder hold_offsets (%d holds, %d load states) for %s: design z %.1f beyond "
                 "states; z_rest %.1f -> %s\n",
                 holds, states, fit.name.c_str(), z_states, z_rest,
                 identified ? "identified" : "confounded");
  }
  if (!identified) *words = StateWords(holds, states, z_states, z_rest, z_claim, z_alone);
  return identified;
}

/// The confounder table: the models an effect's declared Confounder bits name, in the order they
/// are tried, with their key in the report and what each is in words (%.0f: its groups or terms;
/// "… explains it as well" follows). The drift in time (kTimeDrift) is an effect of the registry
/// and is tried last (DriftInTimeConfounds).
struct ConfounderRow {
  Confounder bit;
  const char* name;
  const char* words;
};
constexpr ConfounderRow kConfounderTable[] = {
    {kSegmentOffsets, "segment_offsets", "one offset per joined recording (%.0f segments)"},
    {kLoadOffsets, "load_function", "one offset per distinct static load (%.0f loads)"},
    {kHoldOffsets, "hold_offsets",
     "one offset per load hold (%.0f holds: a function of the load's history)"},
    {kLoadPolynomial, "load_polynomial",
     "a quadratic function of the reference wrench per channel (%.0f terms)"},
};

/// The held-out test of one row of the table against the effect (CheckConfounders'): true when the
/// effect is identified beside it or the row does not apply to the data; else *sentence says why
/// not. A per-hold offset the effect lies within is tested as the load states (StatesIdentify).
bool RowIdentifies(const Context& cx, const EffectFit& fit, const ConfounderRow& row,
                   double z_claim, double z_alone, const SimplerFn& simpler, const BeyondFn& beyond,
                   std::string* sentence) {
  double z_rest = 0.0;
  if (row.bit == kLoadPolynomial) {  // a smooth function of the load, ramps included
    if (!cx.data->has_wrench() || cx.n <= 20 * kLoadTerms) return true;
    if (beyond([&](const Series& y) { return LoadPolynomial(cx, y); }, kLoadTerms * cx.nc,
               &z_rest)) {
      return true;
    }
    *sentence = Fmt(row.words, kLoadTerms, 0) + BeyondWords(z_rest, z_alone);
    return false;
  }
  int groups = 0;
  const std::vector<int> g = ConfounderGroups(cx, row.bit, &groups);
  if (g.empty()) return true;
  if (row.bit == kHoldOffsets &&
      std::sqrt(PowerBeyondOffsets(cx, fit.pred, g, groups)) / 2.0 <= z_claim) {
    return StatesIdentify(cx, fit, z_claim, g, groups, simpler, beyond, z_alone, sentence);
  }
  const auto offsets = [&](const Series& y) { return GroupOffsets(cx, y, g, groups); };
  const bool identified = beyond(offsets, groups * cx.nc, &z_rest);
  if (DebugOn()) {
    std::fprintf(stderr, "confounder %s (%d groups) for %s: z_rest %.1f -> %s\n", row.name, groups,
                 fit.name.c_str(), z_rest, identified ? "identified" : "confounded");
  }
  if (!identified) *sentence = Fmt(row.words, groups, 0) + BeyondWords(z_rest, z_alone);
  return identified;
}

}  // namespace

Confounding CheckConfounders(const Context& cx, const Series& target, const EffectFit& fit,
                             double z_claim, int backfit_threads) {
  Confounding out;
  const EffectSpec* spec = FindEffect(fit.name);
  if (spec == nullptr || spec->confounders == kNoConfounders) return out;
  double delta_alone = 0.0;
  double z_alone = 0.0;
  Improvement(cx, target, fit.pred, &delta_alone, &z_alone);
  // Joint model by backfitting: the confounder fitted to what the effect leaves, the effect
  // refitted to what the confounder leaves. Identified when the joint model beats the confounder
  // alone on the held-out rows (z > z_claim), or when the confounder alone, penalised for its
  // parameters as the ranking does (Δχ² − p·ln n_hold), scores below the effect (`simpler`): a
  // simpler explanation is not confounded by a far richer one.
  const double log_hold = std::log(std::max<double>(2.0, static_cast<double>(cx.n_hold)));
  const double score_effect = delta_alone - fit.n_params * log_hold;
  const double base_sse = Score(cx, target, nullptr).hold_sse;
  // Memory: the confounder alone is scored here and formed again in JointBeyond, not held.
  const SimplerFn simpler = [&](const std::function<Series(const Series&)>& confounder,
                                int confounder_params, Sums* s_alone) {
    *s_alone = [&] {
      const Series alone = confounder(target);
      return Score(cx, target, &alone);
    }();
    return base_sse - s_alone->hold_sse - confounder_params * log_hold < score_effect;
  };
  const BeyondFn beyond = [&](const std::function<Series(const Series&)>& confounder,
                              int confounder_params, double* z_rest) {
    Sums s_alone;
    *z_rest = 0.0;
    if (simpler(confounder, confounder_params, &s_alone)) return true;
    double delta = 0.0;
    *z_rest = JointBeyond(cx, target, fit, *spec, confounder, s_alone, &delta);
    return *z_rest > z_claim && delta > 0.0;
  };
  // The rows are independent tests: run side by side (threads), reported in the table's order.
  std::vector<const ConfounderRow*> rows;
  for (const ConfounderRow& row : kConfounderTable) {
    if ((spec->confounders & row.bit) != 0U) rows.push_back(&row);
  }
  std::vector<std::optional<std::string>> confounds(rows.size());
  // Memory: a row's joint fit holds about four n × N series (10^5 rows × 8 channels fit the
  // side-by-side budget; 10^6 run one by one unless backfits as large just ran side by side).
  const double row_bytes = 4.0 * static_cast<double>(cx.n) * cx.nc * sizeof(float);
  const int side_by_side =
      std::max(SideBySide(cx.threads, row_bytes), std::min(cx.threads, backfit_threads));
  ParallelFor(rows.size(), side_by_side, [&](std::size_t k) {
    std::string sentence;
    if (!RowIdentifies(cx, fit, *rows[k], z_claim, z_alone, simpler, beyond, &sentence)) {
      confounds[k] = std::move(sentence);
    }
  });
  std::vector<std::string> words;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!confounds[k]) continue;
    out.with.emplace_back(rows[k]->name);
    words.push_back(std::move(*confounds[k]));
  }
  if ((spec->confounders & kTimeDrift) != 0U && cx.data->has_temp()) {
    std::string sentence = DriftInTimeConfounds(cx, target, beyond, &out);
    if (!sentence.empty()) words.push_back(std::move(sentence));
  }
  out.words = ConfoundingSentence(fit.name, words);
  return out;
}

}  // namespace ftstack::diag
