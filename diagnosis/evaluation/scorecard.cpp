#include "diagnosis/evaluation/scorecard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string_view>

#include "diagnosis/engine/diagnose.hpp"
#include "measurement/effect_vocabulary.hpp"
#include "sim/record.hpp"

namespace ftstack::diag {
namespace {

std::string Fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

/// `key=value` for an injector parameter of `kind`, the key checked against the vocabulary.
std::string Arg(EffectKind kind, std::string_view key, const std::string& value) {
  return std::string(ParamKey(kind, key, kInjected)) + "=" + value;
}

/// `NAME:arg,arg,…` (just NAME without arguments).
std::string Spec(EffectKind kind, const std::vector<std::string>& args = {}) {
  std::string out(EffectOf(kind).name);
  for (std::size_t i = 0; i < args.size(); ++i) out += (i == 0 ? ":" : ",") + args[i];
  return out;
}

/// The --effect argument of `effect` scaled by `factor` from the simulator's default size.
std::string SpecFor(const std::string& effect, double f, std::uint64_t seed) {
  const double sign = seed % 2 == 0 ? -1.0 : 1.0;
  const EffectDef* def = ftstack::FindEffect(effect);
  if (def == nullptr) return effect;
  const EffectKind k = def->kind;
  switch (k) {
    case EffectKind::kZeroOffset:
      return Spec(k, {Arg(k, "offset", Fmt("%.3g", 4e-4 * f * sign))});
    case EffectKind::kZeroDrift:
      return Spec(k, {Arg(k, "amplitude_mvv", Fmt("%.3g", 4e-4 * f))});
    case EffectKind::kThermalZeroDrift:
      return Spec(k, {Arg(k, "coef_per_K", Fmt("%.3g", 5e-5 * f * sign))});
    case EffectKind::kThermalSpanDrift:
      return Spec(k, {Arg(k, "coef_per_K", Fmt("%.3g", -1.5e-4 * f * sign))});
    case EffectKind::kExcitationDrift:
      return Spec(k, {Arg(k, "amplitude", Fmt("%.3g", 1.5e-3 * f))});
    case EffectKind::kCreep: {
      const double tau[3] = {6.0, 10.0, 20.0};
      return Spec(k, {Arg(k, "fraction", Fmt("%.3g", 4e-3 * f)),
                      Arg(k, "tau_s", Fmt("%g", tau[seed % 3]))});
    }
    case EffectKind::kHysteresis:
      return Spec(k, {Arg(k, "amplitude", Fmt("%.3g", 1.5e-3 * f))});
    case EffectKind::kBridgeNonlinearity:
      return Spec(k, {Arg(k, "coef", Fmt("%.3g", -2e-3 * f))});
    case EffectKind::kGeometricNonlinearity:
      return Spec(k, {Arg(k, "coef", Fmt("%.3g", -3e-3 * f * sign))});
    case EffectKind::kLoadStiffening:
      return Spec(k, {Arg(k, "coef", Fmt("%.3g", -8e-3 * f * sign))});
    case EffectKind::kMisalignment: {
      const char* axes[3] = {"z", "x", "y"};
      return Spec(
          k, {Arg(k, "axis", axes[seed % 3]), Arg(k, "angle_deg", Fmt("%.3g", 0.15 * f * sign))});
    }
    case EffectKind::kGainError:
      return Spec(k, {Arg(k, "gain", Fmt("%.6g", 1.0 + 2.5e-3 * f * sign))});
    case EffectKind::kTimeSkew:
      return Spec(k, {Arg(k, "delay_s", Fmt("%.4g", 0.005 * f))});
    case EffectKind::kOverloadShift:
      return Spec(k, {Arg(k, "shift", Fmt("%.3g", 6e-4 * f * sign))});
    case EffectKind::kMainsInterference:
      return Spec(k, {Arg(k, "amplitude_mvv", Fmt("%.3g", 2.5e-4 * f)),
                      Arg(k, "freq_hz", seed % 2 ? "50" : "60")});
    case EffectKind::kResonance: {
      const double fr[3] = {25.0, 18.0, 37.0};
      return Spec(k, {Arg(k, "freq_hz", Fmt("%g", fr[seed % 3]))});
    }
    default:
      return Spec(k);
  }
}

/// The claimed effect named `name`, if the report names it as identified (an effect the report
/// itself calls confounded is not a claim).
const ClaimedEffect* Claimed(const Report& r, const std::string& name) {
  for (const auto& e : r.effects) {
    if (e.fit.name == name && e.confounded_with.empty()) return &e;
  }
  return nullptr;
}

double RelErr(double got, double want) {
  return std::fabs(got - want) / std::max(std::fabs(want), 1e-300);
}

/// The truth's strongest channel (largest footprint peak) for the effect `name`, or -1; raises
/// `size_sigma` to the truth's footprint size.
int StrongestTruthChannel(const sim::RecordResult& rec, const std::string& name,
                          double* size_sigma) {
  int strongest = -1;
  for (const auto& te : rec.truth["effects"]) {
    if (te["name"] != name) continue;
    const auto& peaks = te["footprint"]["peak_mvv"];
    double best = -1;
    for (std::size_t k = 0; k < peaks.size(); ++k) {
      if (peaks[k].get<double>() > best) {
        best = peaks[k].get<double>();
        strongest = static_cast<int>(k);
      }
    }
    *size_sigma = std::max(*size_sigma, te["footprint"]["size_sigma"].get<double>());
  }
  return strongest;
}

/// How a family's key parameter is compared with its truth.
enum class Compare {
  kRelative,        // relative error of a scalar
  kLargestChannel,  // relative error on the channel with the largest true value
  kGainMinusOne,    // relative error of (gain - 1) on the first channel
  kAbsolute,        // absolute error, in the parameter's unit
  kNone,            // no parameter: only the location rules below
};

struct ParamCheck {
  EffectKind kind;
  const char* key;    // the vocabulary's parameter name
  const char* label;  // how the scorecard prints it
  Compare compare;
  double tolerance;
  bool gates_location;  // a wrong parameter also means the effect was not located
};

constexpr ParamCheck kParamChecks[] = {
    {EffectKind::kCreep, "tau_s", "tau_s", Compare::kRelative, 0.25, false},
    {EffectKind::kThermalZeroDrift, "coef_per_K", "coef_per_K", Compare::kLargestChannel, 0.2,
     false},
    {EffectKind::kThermalSpanDrift, "coef_per_K", "coef_per_K", Compare::kRelative, 0.2, false},
    {EffectKind::kZeroOffset, "offset", "offset", Compare::kLargestChannel, 0.1, false},
    {EffectKind::kGainError, "gain", "gain-1", Compare::kGainMinusOne, 0.2, false},
    {EffectKind::kBridgeNonlinearity, "channels", "", Compare::kNone, 0.0, false},
    {EffectKind::kMisalignment, "angle_deg", "angle_deg", Compare::kRelative, 0.2, false},
    {EffectKind::kTimeSkew, "delay_s", "delay_s", Compare::kRelative, 0.25, true},
    {EffectKind::kSaturation, "limit", "limit", Compare::kRelative, 0.02, false},
    {EffectKind::kOverloadShift, "onset_s", "onset_s (s)", Compare::kAbsolute, 1.0, true},
    {EffectKind::kMainsInterference, "freq_hz", "freq_hz", Compare::kRelative, 0.002, true},
    {EffectKind::kResonance, "freq_hz", "freq_hz", Compare::kRelative, 0.03, true},
};

/// The error of the fitted value `v` against the truth `t`, as `check` compares them.
double ParamError(const ParamCheck& check, const nlohmann::json& v, const sim::Effect& t) {
  switch (check.compare) {
    case Compare::kRelative:
      return RelErr(v.get<double>(), t.num.at(check.key));
    case Compare::kLargestChannel: {
      std::size_t k = 0;
      for (std::size_t i = 0; i < t.per_channel.size(); ++i) {
        if (std::fabs(t.per_channel[i]) > std::fabs(t.per_channel[k])) k = i;
      }
      return RelErr(v[k].get<double>(), t.per_channel[k]);
    }
    case Compare::kGainMinusOne:
      return RelErr(v[0].get<double>() - 1.0, t.num.at(check.key) - 1.0);
    case Compare::kAbsolute:
      return std::fabs(v.get<double>() - t.num.at(check.key));
    case Compare::kNone:
      break;
  }
  return 0.0;
}

/// Whether the claim names the truth's channels or axis, for the families that name them.
bool NamesTheTruthsChannels(const sim::Effect& t, const ClaimedEffect& c,
                            const nlohmann::json* fitted_channels, const nlohmann::json* axis) {
  switch (t.kind) {
    case EffectKind::kGainError:
      return c.fit.channels == t.channels;
    case EffectKind::kBridgeNonlinearity:
      return fitted_channels->get<std::vector<int>>() == t.channels;
    case EffectKind::kMisalignment: {
      const char want[2] = {static_cast<char>('x' + t.axis), 0};
      return axis != nullptr && *axis == want;
    }
    default:
      return true;
  }
}

/// Judges one claimed effect against its truth: location and key parameter.
void Judge(const sim::RecordResult& rec, const Report& r, const sim::Effect& t,
           const ClaimedEffect* c, ScoreResult* out) {
  // Footprint: the truth's strongest channel must be among the located mismatch channels.
  const int strongest = StrongestTruthChannel(rec, t.name, &out->size_sigma);
  const auto& mc = r.mismatch_channels;
  out->located = strongest < 0 || std::find(mc.begin(), mc.end(), strongest) != mc.end();
  if (c == nullptr) {
    out->located = false;
    return;
  }
  const auto& p = c->fit.params;
  // The fitted parameter named `key` in the report, the key checked against the vocabulary.
  auto fitted = [&](std::string_view key) -> const nlohmann::json* {
    const std::string k(ParamKey(t.kind, key, kReported));
    return p.contains(k) ? &p[k] : nullptr;
  };
  const auto* check = std::find_if(std::begin(kParamChecks), std::end(kParamChecks),
                                   [&](const ParamCheck& pc) { return pc.kind == t.kind; });
  if (check == std::end(kParamChecks)) return;
  const nlohmann::json* v = fitted(check->key);
  if (v == nullptr) return;
  const nlohmann::json* axis = t.kind == EffectKind::kMisalignment ? fitted("axis") : nullptr;
  out->located = out->located && NamesTheTruthsChannels(t, *c, v, axis);
  if (check->compare == Compare::kNone) return;
  out->param = check->label;
  out->param_error = ParamError(*check, *v, t);
  out->param_ok = out->param_error <= check->tolerance;
  if (check->gates_location) out->located = out->located && out->param_ok;
}

/// Wrong codes are found by the conditioning, not claimed as a model: right when every injected
/// one is found on an injected channel and no effect is claimed from them.
void JudgeGlitches(const sim::Effect& t, const Report& r, ScoreResult* out) {
  const auto& found = r.cx.conditioning.glitches;
  const double want = t.num.at("count");
  out->named_right = r.effects.empty() && !found.empty();
  out->located = std::all_of(found.begin(), found.end(), [&t](const Glitch& g) {
    return std::find(t.channels.begin(), t.channels.end(), g.channel) != t.channels.end();
  });
  out->param = "count";
  out->param_error = RelErr(static_cast<double>(found.size()), want);
  out->param_ok = out->param_error == 0.0;
  out->detected = out->named_right && out->param_ok;
  // Found wrong codes are excluded rows, not a model: the held-out rows keep none of their excess.
  out->excess_removed = out->detected ? 1.0 : 0.0;
}

}  // namespace

std::vector<ScoreCase> StandardCases(int seeds, double duration_s) {
  std::vector<ScoreCase> cases;
  const double factors[3] = {1.0, 0.5, 2.0};
  for (const auto& name : sim::EffectNames()) {
    for (int s = 1; s <= seeds; ++s) {
      ScoreCase c;
      c.effect = name;
      c.seed = static_cast<std::uint64_t>(s);
      c.factor = factors[(s - 1) % 3];
      c.duration_s = duration_s;
      if (name == "thermal_zero_drift" || name == "thermal_span_drift") c.profile = "thermal";
      if (name != "none") c.specs = {SpecFor(name, c.factor, c.seed)};
      cases.push_back(c);
    }
  }
  // Pairs and subtle distinctions of the proof.
  const std::vector<std::vector<std::string>> pairs = {{"zero_offset", "creep"},
                                                       {"thermal_zero_drift", "mains_interference"},
                                                       {"gain_error", "time_skew"}};
  for (const auto& pr : pairs) {
    ScoreCase c;
    c.effect = pr[0] + "+" + pr[1];
    c.profile = pr[0] == "thermal_zero_drift" ? "thermal" : "rig";
    c.duration_s = duration_s;
    c.specs = {SpecFor(pr[0], 1.0, 1), SpecFor(pr[1], 1.0, 1)};
    cases.push_back(c);
  }
  return cases;
}

ScoreResult RunCase(const ScoreCase& c) {
  sim::RecordRequest req;
  req.profile = c.profile;
  req.seed = c.seed;
  req.duration_s = c.duration_s;
  req.effects = sim::ParseEffects(c.specs);
  const sim::RecordResult rec = sim::MakeRecording(req);
  const DiagData data = FromRecordings(rec.sim, rec.real);
  const auto t0 = std::chrono::steady_clock::now();
  const Report r = Diagnose(data);
  ScoreResult out;
  out.c = c;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.verdict = r.verdict;
  for (const auto& e : r.effects) out.named.push_back(e.fit.name);
  const double sigma = rec.truth["noise_rms_mvv"].get<double>();
  const double lsb = rec.truth.value("lsb_mvv", 0.0);
  const double noise2 = sigma * sigma + lsb * lsb / 12.0;
  const double before = r.hold_rms_before * r.hold_rms_before - noise2;
  const double after = r.hold_rms_after * r.hold_rms_after - noise2;
  out.excess_removed = before > 0 ? 1.0 - std::max(0.0, after) / before : 1.0;
  if (rec.effects.empty()) {
    out.detected = r.verdict == "none" && r.effects.empty();
    out.named_right = out.detected;
    out.located = r.mismatch_channels.empty();
    out.excess_removed = 1.0;
    return out;
  }
  if (rec.effects.size() == 1 && rec.effects.front().kind == EffectKind::kConverterGlitch) {
    JudgeGlitches(rec.effects.front(), r, &out);
    return out;
  }
  out.detected = true;
  out.located = true;
  // Extra effects claimed beside the right ones are penalised: the case is not detected.
  for (const auto& name : out.named) {
    bool truth = false;
    for (const auto& t : rec.effects) truth = truth || t.name == name;
    if (!truth) ++out.extra;
  }
  out.named_right = true;
  for (const auto& t : rec.effects) {
    const ClaimedEffect* ce = Claimed(r, t.name);
    if (ce == nullptr) out.named_right = false;
    ScoreResult part;
    Judge(rec, r, t, ce, &part);
    out.located = out.located && part.located;
    out.size_sigma = std::max(out.size_sigma, part.size_sigma);
    if (!part.param.empty() && (out.param.empty() || !part.param_ok)) {
      out.param = part.param;
      out.param_error = part.param_error;
      out.param_ok = part.param_ok;
    }
  }
  out.detected = out.named_right && out.extra == 0;
  return out;
}

std::string ScorecardMarkdown(const std::vector<ScoreResult>& results, const std::string& command) {
  struct Row {
    int n = 0, detected = 0, located = 0, param_n = 0, param_ok = 0, improved = 0, passed = 0;
    double err_sum = 0.0, err_max = 0.0, removed_min = 1.0, size_min = 1e9, size_max = 0.0,
           secs = 0.0;
    std::string param;
  };
  std::vector<std::string> order;
  std::map<std::string, Row> rows;
  Row total;
  for (const auto& r : results) {
    if (!rows.count(r.c.effect)) order.push_back(r.c.effect);
    for (Row* row : {&rows[r.c.effect], &total}) {
      ++row->n;
      row->detected += r.detected;
      row->located += r.located;
      if (!r.param.empty()) {
        ++row->param_n;
        row->param_ok += r.param_ok;
        row->err_sum += r.param_error;
        row->err_max = std::max(row->err_max, r.param_error);
        row->param = r.param;
      }
      row->improved += r.excess_removed >= 0.7;
      row->removed_min = std::min(row->removed_min, r.excess_removed);
      row->passed += r.passed();
      if (r.size_sigma > 0) {
        row->size_min = std::min(row->size_min, r.size_sigma);
        row->size_max = std::max(row->size_max, r.size_sigma);
      }
      row->secs += r.seconds;
    }
  }
  std::string md;
  md +=
      "# Diagnosis scorecard\n\nGenerated by `" + command +
      "` (simulator recordings made in-process with `sim::MakeRecording`, diagnosed by `ftdiag`'s "
      "library, judged against the recording's truth). Do not edit by hand.\n\n"
      "Columns: *size* the effect's peak in noise σ (truth footprint); *detected* the right "
      "name(s) "
      "claimed (`none`: nothing claimed); *located* the truth's strongest channel among the "
      "located "
      "channels and, where it applies, the right channel/axis, onset (±1 s), frequency or delay; "
      "*parameter error* mean / max of the key parameter's relative error (onset: seconds); "
      "*held-out* cases removing ≥ 70 % of the excess held-out error over noise, and the worst "
      "fraction removed.\n\n";
  md +=
      "| effect | cases | size (σ) | detected | located | key parameter | parameter error mean / "
      "max | "
      "held-out ≥ 70 % | worst removed | all criteria |\n";
  md += "|---|---|---|---|---|---|---|---|---|---|\n";
  auto line = [&](const std::string& name, const Row& row) {
    char b[512];
    const std::string size =
        row.size_max > 0 ? Fmt("%.1f", row.size_min) + "–" + Fmt("%.1f", row.size_max) : "—";
    const std::string perr =
        row.param_n > 0
            ? Fmt("%.3g", row.err_sum / row.param_n) + " / " + Fmt("%.3g", row.err_max) + " (" +
                  std::to_string(row.param_ok) + "/" + std::to_string(row.param_n) + " ok)"
            : "—";
    std::snprintf(b, sizeof b,
                  "| %s | %d | %s | %d/%d | %d/%d | %s | %s | %d/%d | %.2f | %d/%d |\n",
                  name.c_str(), row.n, size.c_str(), row.detected, row.n, row.located, row.n,
                  row.param.empty() ? "—" : row.param.c_str(), perr.c_str(), row.improved, row.n,
                  row.removed_min, row.passed, row.n);
    md += b;
  };
  for (const auto& name : order) line(name, rows[name]);
  total.param = "(each effect's own)";
  line("**total**", total);
  md +=
      "\nMean diagnosis time per case: " + Fmt("%.2f", total.secs / std::max(total.n, 1)) + " s.\n";
  return md;
}

}  // namespace ftstack::diag
