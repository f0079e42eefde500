#include "diagnosis/report/json_report.hpp"
#include "diagnosis/engine/plausibility.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "measurement/effect_vocabulary.hpp"

namespace ftstack::diag {

using Vec = Eigen::VectorXd;

namespace {

/// Glitches, transitions and the quiet noise (engine/conditioning.hpp), with where and how.
nlohmann::json ConditioningJson(const Report& r) {
  const Conditioning& k = r.cx.conditioning;
  const DiagData& d = *r.cx.data;
  auto noise = nlohmann::json::array();
  for (std::size_t c = 0; c < k.noise.size(); ++c) {
    const QuietNoise& q = k.noise[c];
    nlohmann::json nj = {{"channel", c}, {"holds", q.holds}};
    if (q.holds > 0) {
      nj["sigma_mvv"] = q.sigma_mvv;
      nj["unit"] = d.real_unit_symbol;
      if (d.real_units_per_mvv > 0) nj["sigma_in_unit"] = q.sigma_mvv * d.real_units_per_mvv;
      nj["measured_s"] = {q.from_s, q.to_s};
    }
    noise.push_back(nj);
  }
  auto transitions = nlohmann::json::array();
  std::size_t lagging = 0;
  for (const Transition& t : k.transitions) {
    nlohmann::json tj = {{"t_s", t.t_s},
                         {"channel", t.channel},
                         {"step_mvv", t.step_mvv},
                         {"application_s", t.application_s},
                         {"excluded", t.excluded}};
    if (t.excluded) {
      tj["excluded_s"] = {t.excluded_from_s, t.excluded_to_s};
      ++lagging;
    }
    transitions.push_back(tj);
  }
  return {{"noise_quiet",
           {{"method",
             "robust sigma of first differences (median |diff| / 0.6745 / sqrt 2) in every hold "
             "of the reference (>= 20 rows and 1 s, glitch and transition rows out); the "
             "quietest hold of >= 200 rows (else of any length)"},
            {"channels", noise}}},
          {"transitions",
           {{"handling",
             "rows where the real load had not reached the reference (its normalised value more "
             "than 0.1 from the reference's), widened over the ramp's foot and a decaying "
             "bounce, are excluded from every fit and hold-out score when the real 10-90 % rise "
             "is >= 2 rows slower than the reference's"},
            {"count", k.transitions.size()},
            {"excluded", lagging},
            {"list", transitions}}},
          {"excluded_rows", k.excluded_rows}};
}

/// Findings that are not models of the residual: the converter's wrong codes.
nlohmann::json FindingsJson(const Report& r) {
  const auto& g = r.cx.conditioning.glitches;
  auto out = nlohmann::json::array();
  if (g.empty()) return out;
  std::vector<int> channels;
  std::vector<double> times;
  auto list = nlohmann::json::array();
  for (const Glitch& x : g) {
    if (std::find(channels.begin(), channels.end(), x.channel) == channels.end())
      channels.push_back(x.channel);
    times.push_back(x.t_s);
    list.push_back({{"t_s", x.t_s}, {"channel", x.channel}, {"offset_mvv", x.offset_mvv}});
  }
  std::sort(channels.begin(), channels.end());
  EffectFit located;  // located, not fitted: typed by the same rule as any fit
  located.name = EffectOf(EffectKind::kConverterGlitch).name;
  located.params = {{"count", g.size()}, {"times_s", times}};
  out.push_back({{"name", located.name},
                 {"channels", channels},
                 {"params", located.params},
                 {"parameters", TypedParameters(r.cx, located)},
                 {"glitches", list},
                 {"handling",
                  "each sample replaced by the line through its neighbours in the residual and "
                  "its row excluded from every fit and hold-out score"}});
  return out;
}

/// The real bridges' value grid and the size of effect it lets the record show.
nlohmann::json QuantisationJson(const Report& r) {
  const Quantisation& q = r.cx.quantisation;
  if (!q.quantised()) return {{"quantised", false}};
  auto step = nlohmann::json::array();
  auto smallest = nlohmann::json::array();
  for (Eigen::Index c = 0; c < q.step_mvv.size(); ++c) {
    step.push_back(q.step_mvv(c));
    smallest.push_back(kResolvableSteps * q.step_mvv(c));
  }
  return {
      {"quantised", true},
      {"source", q.source},
      {"step_mvv", step},
      {"smallest_claimable_rms_mvv", smallest},
      {"rule", "an effect whose predicted RMS on the fitted rows is below " +
                   std::to_string(static_cast<int>(kResolvableSteps)) +
                   " steps on every channel is not claimed: an undithered grid's rounding, within "
                   "half a step of every held load, can mimic a smooth function of the load or a "
                   "slow drift of that size"}};
}

}  // namespace

nlohmann::json ToJson(const Report& r) {
  auto vec = [](const Vec& v) {
    auto a = nlohmann::json::array();
    for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
    return a;
  };
  nlohmann::json j;
  j["schema"] = "ftdiag-report/1";
  j["rate_hz"] = r.rate_hz;
  j["noise_rms"] = vec(r.noise_rms);
  j["rms_before"] = vec(r.rms_before);
  auto windows = nlohmann::json::array();
  for (const auto& [a, b] : r.windows) windows.push_back({a, b});
  j["mismatch"] = {{"channels", r.mismatch_channels}, {"windows", windows}};
  if (!r.load_region.is_null()) j["mismatch"]["load_region"] = r.load_region;
  if (!r.cx.peak_hz.empty()) {
    j["mismatch"]["spectral_peaks_hz"] = r.cx.peak_hz;
  }
  j["conditioning"] = ConditioningJson(r);
  j["quantisation"] = QuantisationJson(r);
  j["findings"] = FindingsJson(r);
  j["verdict"] = r.verdict;
  auto effects = nlohmann::json::array();
  for (const auto& e : r.effects) {
    nlohmann::json ej;
    ej["name"] = e.fit.name;
    ej["channels"] = e.fit.channels;
    ej["params"] = e.fit.params;
    ej["parameters"] = TypedParameters(r.cx, e.fit);
    ej["uncertainty"] = e.fit.sigma;
    if (!e.fit.spread.empty()) ej["spread"] = e.fit.spread;
    if (!e.fit.standard.empty()) ej["standard"] = e.fit.standard;
    ej["evidence"] = e.fit.evidence;
    ej["rms_after"] = vec(e.rms_after);
    ej["holdout"] = {{"rms_before", e.hold_rms_before}, {"rms_after", e.hold_rms_after}};
    ej["model"] = e.fit.variant;
    ej["n_params"] = e.fit.n_params;
    ej["identifiable"] = e.confounded_with.empty();
    if (!e.confounded_with.empty()) {
      ej["confounded_with"] = e.confounded_with;
      ej["confounding"] = e.confounding;
    }
    effects.push_back(ej);
  }
  j["effects"] = effects;
  if (!r.dropped.empty()) j["not_claimed"] = r.dropped;
  j["holdout"] = {{"rms_before", r.hold_rms_before},
                  {"rms_after", r.hold_rms_after},
                  {"rows", r.cx.n_hold},
                  {"block_s", r.cx.block_s},
                  {"scheme",
                   "every third block of block_s held out; fits use the other rows; blocks "
                   "restart at every segment"},
                  {"segments", r.cx.segments}};
  auto cands = nlohmann::json::array();
  for (const auto& c : r.candidates) {
    cands.push_back({{"name", c.name},
                     {"model", c.variant},
                     {"n_params", c.n_params},
                     {"holdout_rms_after", c.hold_rms_after},
                     {"z", c.z},
                     {"score", c.score},
                     {"eligible", c.eligible},
                     {"parameters", c.parameters}});
    if (!c.not_resolved.empty()) cands.back()["not_resolved"] = c.not_resolved;
  }
  j["candidates"] = cands;
  return j;
}

}  // namespace ftstack::diag
