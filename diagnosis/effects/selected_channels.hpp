// The fit of one coefficient per channel on a feature of the channel's load, kept on the
// significant channels only (gain_error, bridge_nonlinearity).
#pragma once

#include <optional>
#include <vector>

#include "diagnosis/effects/families.hpp"

namespace ftstack::diag::fx {

template <class F>
std::optional<EffectFit> SelectedChannelFit(const Context& cx, const Series& target, F feat,
                                            const char* name, const char* coef_name,
                                            std::vector<int>* chosen, ChannelFit* fit) {
  Series pred;
  const auto all = FitChannels(cx, target, 1, feat, &pred);
  std::vector<int> sel = SignificantChannels(cx, all, pred, 0);
  if (sel.empty()) {
    // Keep the single strongest channel so the candidate still exists (and will lose on hold-out).
    sel.push_back(DominantChannel(cx, pred));
  }
  EffectFit e;
  e.name = name;
  *fit = FitChannels(cx, target, 1, feat, &e.pred, &sel);
  e.train_sse_w = fit->sse_w;
  e.n_params = static_cast<int>(sel.size());
  e.channels = sel;
  auto coefs = nlohmann::json::array();
  auto sig = nlohmann::json::array();
  const Vec s = CoefSigmas(cx, *fit, 0);
  for (int c : sel) {
    coefs.push_back(fit->beta(0, c));
    sig.push_back(s(c));
  }
  e.params["channels"] = IntList(sel);
  e.params[coef_name] = coefs;
  e.sigma[coef_name] = sig;
  *chosen = sel;
  return e;
}

}  // namespace ftstack::diag::fx
