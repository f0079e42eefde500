#include "diagnosis/report/json_report.hpp"

#include <string>

namespace ftstack::diag {

using Vec = Eigen::VectorXd;

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
  j["verdict"] = r.verdict;
  auto effects = nlohmann::json::array();
  for (const auto& e : r.effects) {
    nlohmann::json ej;
    ej["name"] = e.fit.name;
    ej["channels"] = e.fit.channels;
    ej["params"] = e.fit.params;
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
                     {"eligible", c.eligible}});
    if (!c.not_resolved.empty()) cands.back()["not_resolved"] = c.not_resolved;
  }
  j["candidates"] = cands;
  return j;
}

}  // namespace ftstack::diag
