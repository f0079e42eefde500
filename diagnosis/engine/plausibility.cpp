#include "diagnosis/engine/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/engine/parallel.hpp"
#include "diagnosis/engine/separable_fit.hpp"

namespace ftstack::diag {

using fx::Fmt;

namespace {

/// Why one scalar value is not resolved against range r, or "".
std::string ScalarWords(const ParamSpec& r, double v) {
  if (!std::isfinite(v)) return Fmt("%s is not finite", r.key);
  if (StatusOf(r, v) == ParamStatus::kResolved) return "";  // the engine's rule; below, its words
  const bool log_scale = r.lo > 0.0 && v > 0.0;
  const double below = log_scale ? std::log(v / r.lo) : (v - r.lo) / (r.hi - r.lo);
  const double above = log_scale ? std::log(r.hi / v) : (r.hi - v) / (r.hi - r.lo);
  if (below < 0.0) return Fmt("%s = %.4g below its range (%s, %.4g)", r.key, v, r.lo_what, r.lo);
  if (above < 0.0) return Fmt("%s = %.4g above its range (%s, %.4g)", r.key, v, r.hi_what, r.hi);
  if (below < above) {
    return Fmt("%s = %.4g at its lower bound (%s, %.4g)", r.key, v, r.lo_what, r.lo);
  }
  return Fmt("%s = %.4g at its upper bound (%s, %.4g)", r.key, v, r.hi_what, r.hi);
}

/// The values of a parameter (one, or one per channel) as doubles; empty when not numbers.
std::vector<double> Values(const nlohmann::json& v) {
  std::vector<double> out;
  if (v.is_number()) out.push_back(v.get<double>());
  if (v.is_array()) {
    for (const auto& x : v) {
      if (!x.is_number()) return {};
      out.push_back(x.get<double>());
    }
  }
  return out;
}

/// The numbers of a parameter at any depth (per level and channel, say), in order; empty when any
/// element is not a number.
std::vector<double> FlatValues(const nlohmann::json& v) {
  if (!v.is_array()) return Values(v);
  std::vector<double> out;
  for (const auto& x : v) {
    const std::vector<double> inner = FlatValues(x);
    if (inner.empty() && !(x.is_array() && x.empty())) return {};
    out.insert(out.end(), inner.begin(), inner.end());
  }
  return out;
}

/// The typed entry of a value the fit chose rather than fitted: a count (a model order, a tally)
/// or a label. No σ, range or spread, and status "chosen": not a parameter the fit resolved or
/// failed to resolve (a claim's numbers are judged by the others).
nlohmann::json ChosenNotFitted(const std::string& key, const nlohmann::json& unit,
                               const nlohmann::json& v) {
  return {{"key", key},
          {"unit", unit},
          {"value", v},
          {"sigma", nullptr},
          {"range", nullptr},
          {"spread", nullptr},
          {"spread_why", "a count or label the fit chose, not a fitted number"},
          {"status", StatusName(ParamStatus::kChosen)}};
}

/// Restricts cx's training rows to the piece [t_lo, t_hi) of the record (and back: `train`).
void SelectPiece(Context* cx, const std::vector<std::uint8_t>& train, double t_lo, double t_hi) {
  const auto& t = cx->data->t_s;
  cx->n_train = 0;
  for (int i = 0; i < cx->n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    cx->train[k] = train[k] != 0 && t[k] >= t_lo && t[k] < t_hi ? 1 : 0;
    cx->n_train += cx->train[k];
  }
}

/// Pieces whose values differ by less than this fraction of their size read as one value.
constexpr double kSameValue = 1e-4;

/// The spread of one parameter from its per-piece values (piece × element) and curvature σ;
/// "scatter_over_curvature" when the pieces scatter over 3 × what the curvature σ allows (√pieces
/// σ per piece) on some element — with residuals correlated in time, true effects do.
nlohmann::json OneSpread(const std::vector<std::vector<double>>& pieces,
                         const std::vector<std::vector<double>>& piece_sigmas,
                         const nlohmann::json& sigma) {
  const std::vector<double> curv = Values(sigma);
  const std::size_t m = pieces.size();
  const std::size_t dim = pieces.front().size();
  nlohmann::json lo = nlohmann::json::array();
  nlohmann::json hi = nlohmann::json::array();
  nlohmann::json sd = nlohmann::json::array();
  nlohmann::json larger = nlohmann::json::array();
  nlohmann::json lo_sigma = nlohmann::json::array();  // the own σ of the piece giving the min
  nlohmann::json hi_sigma = nlohmann::json::array();
  bool over = false;
  for (std::size_t e = 0; e < dim; ++e) {
    double mn = std::numeric_limits<double>::infinity();
    double mx = -mn;
    double sum = 0.0;
    double s_mn = std::numeric_limits<double>::quiet_NaN();
    double s_mx = s_mn;
    for (std::size_t k = 0; k < m; ++k) {
      const double x = pieces[k][e];
      if (x < mn) s_mn = piece_sigmas[k][e];
      if (x > mx) s_mx = piece_sigmas[k][e];
      mn = std::min(mn, x);
      mx = std::max(mx, x);
      sum += x;
    }
    const double mean = sum / static_cast<double>(m);
    double ss = 0.0;
    for (const auto& p : pieces) ss += (p[e] - mean) * (p[e] - mean);
    const double sd_piece = std::sqrt(ss / static_cast<double>(m - 1));
    const double s_whole = sd_piece / std::sqrt(static_cast<double>(m));
    const double c = e < curv.size() ? curv[e] : std::numeric_limits<double>::quiet_NaN();
    // Pieces equal to 1e-4 of their size agree whatever their curvature σ: a supply's frequency
    // wandering by 0.01 % is one frequency, and "98.28–98.28" is not a disagreement.
    const bool distinct = mx - mn > kSameValue * std::max(std::fabs(mn), std::fabs(mx));
    if (std::isfinite(c) && distinct && sd_piece > 3.0 * std::sqrt(static_cast<double>(m)) * c)
      over = true;
    lo.push_back(mn);
    hi.push_back(mx);
    lo_sigma.push_back(fx::JsonNum(s_mn));
    hi_sigma.push_back(fx::JsonNum(s_mx));
    sd.push_back(s_whole);
    larger.push_back(std::isfinite(c) ? std::max(c, s_whole) : s_whole);
  }
  const auto flat = [dim](nlohmann::json a) { return dim == 1 ? a[0] : a; };
  return {{"pieces", m},
          {"min", flat(lo)},
          {"max", flat(hi)},
          {"sigma", flat(sd)},
          {"larger", flat(larger)},
          {"min_sigma", flat(lo_sigma)},
          {"max_sigma", flat(hi_sigma)},
          {"scatter_over_curvature", over}};
}

/// The element of largest |value| of a parameter (per-channel parameters: the channel that carries
/// it) and that value; (0, 0) when none is a number.
std::pair<std::size_t, double> LargestElement(const nlohmann::json& v) {
  std::size_t e = 0;
  double value = 0.0;
  const std::size_t dim = v.is_array() ? v.size() : 1;
  for (std::size_t k = 0; k < dim; ++k) {
    const nlohmann::json& x = v.is_array() ? v[k] : v;
    if (x.is_number() && std::fabs(x.get<double>()) > std::fabs(value)) {
      value = x.get<double>();
      e = k;
    }
  }
  return {e, value};
}

/// Why a declared parameter's value is not resolved against its range, or "": a scalar by the
/// engine's StatusOf, per-channel values by the largest |value| above hi.
std::string BoundWords(const EffectFit& fit, const ParamSpec& r) {
  if (!fit.params.contains(r.key)) return "";
  const std::vector<double> v = Values(fit.params[r.key]);
  if (v.size() == 1 && fit.params[r.key].is_number()) return ScalarWords(r, v[0]);
  double largest = 0.0;
  for (double x : v) largest = std::max(largest, std::fabs(x));
  if (largest > r.hi) {
    return Fmt("%s up to %.4g beyond its range (%s, %.4g)", r.key, largest, r.hi_what, r.hi);
  }
  return "";
}

/// The declaration of `key` among `declared`, or nullptr.
const ParamSpec* DeclarationOf(const std::vector<ParamSpec>& declared, const std::string& key) {
  for (const ParamSpec& p : declared) {
    if (key == p.key) return &p;
  }
  return nullptr;
}

/// Whether a σ entry holds only finite numbers (a number or one per channel).
bool FiniteSigma(const nlohmann::json& sigma) {
  const std::vector<double> s = FlatValues(sigma);
  return !s.empty() && std::all_of(s.begin(), s.end(), [](double x) { return std::isfinite(x); });
}

/// A value the fit chose rather than fitted: a count (a model order, a tally), a list of them
/// (the channels it acts on) or a label.
bool Chosen(const nlohmann::json& v) {
  if (v.is_array() && !v.empty()) {
    return std::all_of(v.begin(), v.end(), [](const auto& x) { return x.is_number_integer(); });
  }
  return v.is_number_integer() || v.is_boolean() || FlatValues(v).empty();
}

/// Whether `key` is a figure computed from the fit rather than a parameter it searched or
/// reports with a σ: a number without a declaration and without a σ entry (a derived value such
/// as a damped frequency, a participation, a span, a linear solve's levels).
bool Derived(const EffectFit& fit, const std::string& key, const ParamSpec* d) {
  return d == nullptr && !fit.sigma.contains(key);
}

/// Pieces of one sign whose values differ by more than this factor do not give one value.
constexpr double kPiecesFactor = 2.0;

/// Why the pieces of the record contradict a parameter, or "". One of one sign by its declaration
/// (lo ≥ 0): the pieces' values of its largest-|value| element straddle zero, or, for a scale
/// searched in log, they differ by more than kPiecesFactor and by more than 3 σ between two pieces
/// (each piece's σ √pieces times the whole record's curvature σ). A signed or undeclared parameter
/// (a delay, an angle, a linear coefficient) is not judged by its pieces: near zero it may take
/// either sign in a piece; its spread is reported (min, max and their σ). A spread within a factor
/// kPiecesFactor is an uncertain size, which the spread's σ reports (the curvature σ alone is too
/// small where residuals are correlated).
std::string PiecesWords(const EffectFit& fit, const std::string& key, const ParamSpec* d) {
  if (!fit.spread.contains(key) || !fit.params.contains(key)) return "";
  const auto& s = fit.spread[key];
  if (!s.contains("min")) return "";
  const auto [e, value] = LargestElement(fit.params[key]);
  const nlohmann::json& lo_j = s["min"].is_array() ? s["min"][e] : s["min"];
  const nlohmann::json& hi_j = s["max"].is_array() ? s["max"][e] : s["max"];
  if (value == 0.0 || !lo_j.is_number() || !hi_j.is_number()) return "";
  const double lo = lo_j.get<double>();
  const double hi = hi_j.get<double>();
  const std::vector<double> curv =
      fit.sigma.contains(key) ? Values(fit.sigma[key]) : std::vector<double>{};
  // Without a finite σ there is no telling a factor from noise (PieceSpreads always has one).
  const double c = e < curv.size() ? curv[e] : std::numeric_limits<double>::quiet_NaN();
  const double piece_sigma = std::sqrt(s.value("pieces", 2.0)) * c;
  // A signed parameter (a delay, an angle, a linear coefficient) may take either sign in a piece:
  // a piece without the load's coverage, or on a converter's grid, reads a coefficient of
  // either sign, however small its own σ (min_sigma, max_sigma).
  if (d == nullptr || d->lo < 0.0) return "";
  if (lo * hi < 0.0) {
    return Fmt("not resolved: pieces disagree (%s = %.4g, per piece %.4g–%.4g)", key.c_str(), value,
               lo, hi);
  }
  // A factor is a scale's test (searched in log); a linear amplitude is fitted at the nonlinear
  // parameters' values, so its pieces move with theirs by more than its σ says.
  if (d->scale != ParamScale::kLog || d->lo <= 0.0) return "";
  const double small = std::min(std::fabs(lo), std::fabs(hi));
  const double factor = small > 0.0 ? std::max(std::fabs(lo), std::fabs(hi)) / small
                                    : std::numeric_limits<double>::infinity();
  if (!std::isfinite(c) || factor <= kPiecesFactor ||
      hi - lo <= 3.0 * std::sqrt(2.0) * piece_sigma) {
    return "";
  }
  return Fmt("not resolved: pieces disagree (%s = %.4g, per piece %.4g–%.4g, a factor %.3g)",
             key.c_str(), value, lo, hi, factor);
}

}  // namespace

ParamVerdict VerdictOf(const EffectFit& fit, const std::string& key,
                       const std::vector<ParamSpec>& declared) {
  ParamVerdict out;
  const nlohmann::json& v = fit.params[key];
  if (Chosen(v)) {
    out.status = ParamStatus::kChosen;
    return out;
  }
  const ParamSpec* d = DeclarationOf(declared, key);
  if (Derived(fit, key, d)) {  // judged by what it is computed from
    out.derived = true;
    for (auto it = fit.params.begin(); it != fit.params.end(); ++it) {
      const ParamSpec* di = DeclarationOf(declared, it.key());
      if (it.key() == key || Chosen(it.value()) || Derived(fit, it.key(), di)) continue;
      out.derived_from.push_back(it.key());
      const ParamVerdict source = VerdictOf(fit, it.key(), declared);
      if (out.status == ParamStatus::kResolved && source.status != ParamStatus::kResolved) {
        out.status = source.status;
        out.why = Fmt("computed from %s: %s", it.key().c_str(), source.why.c_str());
      }
    }
    return out;
  }
  const std::vector<double> values = FlatValues(v);
  if (d != nullptr) out.why = BoundWords(fit, *d);
  if (out.why.empty() &&
      !std::all_of(values.begin(), values.end(), [](double x) { return std::isfinite(x); })) {
    out.why = Fmt("%s is not finite", key.c_str());
  }
  if (!out.why.empty()) {
    const bool finite = out.why.find("not finite") == std::string::npos;
    out.status = finite ? ParamStatus::kAtBound : ParamStatus::kNotIdentified;
    return out;
  }
  if (fit.sigma_computed && fit.sigma.contains(key) && !FiniteSigma(fit.sigma[key])) {
    out.status = ParamStatus::kNotIdentified;
    out.why = Fmt("%s has no finite σ (the fit does not change with it there)", key.c_str());
    return out;
  }
  out.why = PiecesWords(fit, key, d);
  if (!out.why.empty()) out.status = ParamStatus::kPiecesDisagree;
  return out;
}

std::vector<ParamSpec> DeclaredParams(const Context& cx, const EffectFit& fit,
                                      const EffectSpec& spec) {
  if (spec.fit_ranges != nullptr) return spec.fit_ranges(cx, fit);
  if (spec.ranges != nullptr) return spec.ranges(cx);
  return {};
}

std::string NotResolved(const Context& cx, const EffectFit& fit) {
  const EffectSpec* spec = FindEffect(fit.name);
  return spec == nullptr ? "" : NotResolved(cx, fit, *spec);
}

std::string NotResolved(const Context& cx, const EffectFit& fit, const EffectSpec& spec) {
  const std::vector<ParamSpec> declared = DeclaredParams(cx, fit, spec);
  // The declared parameters first, in their order, then the others; a bound or a flat profile
  // before the pieces (its words name the cause, not a symptom of it).
  std::vector<std::string> keys;
  for (const ParamSpec& r : declared) {
    if (fit.params.contains(r.key)) keys.emplace_back(r.key);
  }
  for (auto it = fit.params.begin(); it != fit.params.end(); ++it) {
    if (DeclarationOf(declared, it.key()) == nullptr) keys.push_back(it.key());
  }
  std::string pieces;
  for (const std::string& key : keys) {
    const ParamVerdict v = VerdictOf(fit, key, declared);
    if (v.derived || v.status == ParamStatus::kResolved || v.status == ParamStatus::kChosen) {
      continue;
    }
    if (v.status != ParamStatus::kPiecesDisagree) return v.why;
    if (pieces.empty()) pieces = v.why;
  }
  if (!pieces.empty()) return pieces;
  return WithinGrid(cx, fit);
}

std::string WithinGrid(const Context& cx, const EffectFit& fit) {
  const Quantisation& q = cx.quantisation;
  if (!q.quantised() || fit.pred.rows() != cx.n || fit.pred.cols() != q.step_mvv.size()) return "";
  double largest = 0.0;  // the prediction's RMS in steps, on the channel where it is largest
  int at = 0;
  // About kGridSampleRows rows estimate an RMS well enough for a threshold (cost on 10^6 rows).
  const int every = std::max(1, cx.n / static_cast<int>(kGridSampleRows));
  for (int c = 0; c < cx.nc; ++c) {
    double s = 0.0;
    std::size_t rows = 0;
    for (int i = 0; i < cx.n; i += every) {
      const auto iu = static_cast<std::size_t>(i);
      if (cx.train[iu] == 0 || (!cx.excluded.empty() && cx.excluded[iu] != 0)) continue;
      s += static_cast<double>(fit.pred(i, c)) * fit.pred(i, c);
      ++rows;
    }
    const double rms = rows > 0 ? std::sqrt(s / static_cast<double>(rows)) : 0.0;
    if (rms > 0 && q.step_mvv(c) <= 0) return "";  // acts where no grid limits what is seen
    const double steps = rms > 0 ? rms / q.step_mvv(c) : 0.0;
    if (steps > largest) {
      largest = steps;
      at = c;
    }
  }
  if (largest >= kResolvableSteps) return "";
  return Fmt(
      "within the converter's grid: its predicted RMS is %.2g steps on b%d (step %.3g mV/V, "
      "%s), below the %.0f steps a quantised record can show",
      largest, at, q.step_mvv(at), q.source.c_str(), kResolvableSteps);
}

nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit) {
  const EffectSpec* spec = FindEffect(fit.name);
  if (spec != nullptr) return TypedParameters(cx, fit, *spec);
  const EffectSpec none{};
  return TypedParameters(cx, fit, none);
}

nlohmann::json TypedParameters(const Context& cx, const EffectFit& fit, const EffectSpec& plugin) {
  const EffectSpec* spec = plugin.kind == EffectKind::kNone ? nullptr : &plugin;
  const std::vector<ParamSpec> declared = DeclaredParams(cx, fit, plugin);
  auto out = nlohmann::json::array();
  for (auto it = fit.params.begin(); it != fit.params.end(); ++it) {
    const std::string& key = it.key();
    const nlohmann::json& v = it.value();
    const ParamSpec* d = DeclarationOf(declared, key);
    nlohmann::json unit = nullptr;
    const EffectParam* vocab =
        spec != nullptr ? FindParam(EffectOf(spec->kind), key, false) : nullptr;
    if (vocab != nullptr) {
      unit = std::string(vocab->unit);
    } else if (d != nullptr) {
      unit = d->unit;
    }
    const ParamVerdict verdict = VerdictOf(fit, key, declared);
    if (verdict.status == ParamStatus::kChosen) {
      out.push_back(ChosenNotFitted(key, unit, v));
      continue;
    }
    nlohmann::json p = {{"key", key},
                        {"unit", unit},
                        {"value", v},
                        {"sigma", fit.sigma.contains(key) ? fit.sigma[key] : nlohmann::json()},
                        {"range", d != nullptr ? nlohmann::json{d->lo, d->hi} : nlohmann::json()},
                        {"spread", nullptr},
                        {"status", StatusName(verdict.status)}};
    if (verdict.derived) {
      p["derived_from"] = verdict.derived_from;
      p["spread_why"] = "computed from the fitted parameters in derived_from, not fitted itself";
    } else if (fit.spread.contains(key) && fit.spread[key].contains("sigma")) {
      p["spread"] = fit.spread[key]["sigma"];
    } else if (fit.spread.contains(key)) {
      p["spread_why"] = "fewer than two pieces resolved it";
    } else {
      p["spread_why"] = fit.spread.empty() ? "not refitted on pieces (only claimed effects are)"
                                           : "no σ to compare pieces with";
    }
    if (!verdict.why.empty()) p["why"] = verdict.why;
    out.push_back(p);
  }
  return out;
}

void PieceSpreads(Context* cx, const Series& target, EffectFit* fit) {
  const EffectSpec* spec = FindEffect(fit->name);
  if (spec != nullptr) PieceSpreads(cx, target, fit, *spec);
}

namespace {

/// The fit refitted near itself on each of the kSpreadPieces pieces of the record's training rows
/// (nullopt where a piece's refit fails or is not resolved); leaves cx's training rows as they
/// were. The pieces are independent refits: side by side, each thread on its own RefitCopy (the row
/// masks and the temperature; the load is shared) with its own refit's prediction, while those
/// fit the side-by-side budget.
std::vector<std::optional<EffectFit>> RefitPieces(Context* cx, const Series& target,
                                                  const EffectFit& fit, const EffectSpec& spec) {
  const std::vector<std::uint8_t> train = cx->train;
  const std::size_t n_train = cx->n_train;
  const auto& t = cx->data->t_s;
  const double span = (t.back() - t.front()) / kSpreadPieces;
  const double copy_bytes =
      static_cast<double>(cx->n) *
      (3.0 + (cx->dtemp.empty() ? 0.0 : sizeof(double)) + cx->nc * sizeof(float));
  const int threads = std::min(SideBySide(cx->threads, copy_bytes), kSpreadPieces);
  std::vector<Context> copies;
  for (int k = 1; k < threads; ++k) copies.push_back(RefitCopy(cx));
  std::vector<Context*> free_contexts{cx};
  for (Context& c : copies) free_contexts.push_back(&c);
  std::mutex mu;
  std::vector<std::optional<EffectFit>> pieces(kSpreadPieces);
  ParallelFor(pieces.size(), threads, [&](std::size_t k) {
    Context* pcx = nullptr;
    {
      const std::lock_guard<std::mutex> lock(mu);
      pcx = free_contexts.back();
      free_contexts.pop_back();
    }
    const int p = static_cast<int>(k);
    const double t_lo = t.front() + span * p;
    SelectPiece(pcx, train, t_lo, p + 1 == kSpreadPieces ? t.back() + 1.0 : t_lo + span);
    std::optional<EffectFit> piece = FitNear(spec, *pcx, target, &fit, false);
    if (piece && NotResolved(*pcx, *piece, spec).empty()) pieces[k] = std::move(piece);
    const std::lock_guard<std::mutex> lock(mu);
    free_contexts.push_back(pcx);
  });
  cx->train = train;
  cx->n_train = n_train;
  return pieces;
}

}  // namespace

void PieceSpreads(Context* cx, const Series& target, EffectFit* fit, const EffectSpec& spec) {
  if (fit->sigma.empty()) return;
  const std::vector<ParamSpec> declared = DeclaredParams(*cx, *fit, spec);
  struct PerPiece {
    std::string key;
    std::vector<std::vector<double>> values;
    std::vector<std::vector<double>> sigmas;  ///< each piece's own σ (NaN where it has none)
  };
  std::vector<PerPiece> values;
  for (auto it = fit->sigma.begin(); it != fit->sigma.end(); ++it) {
    values.push_back({it.key(), {}, {}});
  }
  const std::vector<std::optional<EffectFit>> pieces = RefitPieces(cx, target, *fit, spec);
  int unresolved = 0;
  for (const std::optional<EffectFit>& piece : pieces) {
    if (!piece) {
      ++unresolved;
      continue;
    }
    for (PerPiece& pp : values) {
      if (!piece->params.contains(pp.key)) continue;
      pp.values.push_back(Values(piece->params[pp.key]));
      std::vector<double> own =
          piece->sigma.contains(pp.key) ? Values(piece->sigma[pp.key]) : std::vector<double>{};
      own.resize(pp.values.back().size(), std::numeric_limits<double>::quiet_NaN());
      pp.sigmas.push_back(own);
    }
  }
  for (PerPiece& pp : values) {
    const std::string& key = pp.key;
    const std::size_t dim = Values(fit->params[key]).size();
    std::vector<std::vector<double>> per_piece;
    std::vector<std::vector<double>> own;
    for (std::size_t k = 0; k < pp.values.size(); ++k) {
      if (pp.values[k].size() != dim || dim == 0) continue;
      per_piece.push_back(pp.values[k]);
      own.push_back(pp.sigmas[k]);
    }
    nlohmann::json s = {{"pieces", per_piece.size()}, {"agree", nullptr}};
    if (per_piece.size() >= 2) s = OneSpread(per_piece, own, fit->sigma[key]);
    s["unresolved_pieces"] = unresolved;
    fit->spread[key] = s;
    // "agree" is the claim rule's word on the pieces (VerdictOf), nothing else.
    if (per_piece.size() >= 2) {
      fit->spread[key]["agree"] = PiecesWords(*fit, key, DeclarationOf(declared, key)).empty();
    }
  }
}

std::string SpreadWords(const EffectFit& fit) {
  std::string out;
  for (auto it = fit.spread.begin(); it != fit.spread.end(); ++it) {
    const auto& s = it.value();
    const bool disagree = s.contains("agree") && s["agree"].is_boolean() && !s["agree"].get<bool>();
    const bool over =
        s.contains("scatter_over_curvature") && s["scatter_over_curvature"].get<bool>();
    if (!disagree && !over) continue;
    if (s["min"].is_number()) {
      out += Fmt("%s%s per piece %.6g–%.6g", out.empty() ? "" : "; ", it.key().c_str(),
                 s["min"].get<double>(), s["max"].get<double>());
      continue;
    }
    // Per-channel pieces: those of the channel that carries the parameter.
    if (!s["min"].is_array() || !s["max"].is_array() || !fit.params.contains(it.key())) continue;
    const std::size_t e = LargestElement(fit.params[it.key()]).first;
    if (e >= s["min"].size() || e >= s["max"].size() || !s["min"][e].is_number() ||
        !s["max"][e].is_number())
      continue;
    out += Fmt("%s%s on b%zu per piece %.6g–%.6g", out.empty() ? "" : "; ", it.key().c_str(), e,
               s["min"][e].get<double>(), s["max"][e].get<double>());
  }
  return out;
}

}  // namespace ftstack::diag
