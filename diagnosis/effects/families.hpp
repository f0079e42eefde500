// The effect families' fit functions (diagnosis/effects/, one file per family) as the registry and
// the families' variants call them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/separable_fit.hpp"
#include "diagnosis/engine/solve.hpp"

namespace ftstack::diag {

/// thermal_zero_drift against a given temperature history dtemp (°C from 20 °C, one per row):
/// r_c = a_c + k_c·dtemp (effects/thermal_zero_drift.cpp).
[[nodiscard]] std::optional<EffectFit> FitThermalZeroOn(const Context& cx, const Series& target,
                                                        const std::vector<double>& dtemp);
/// thermal_zero_drift with a first-order lag τ ≥ 0 between the thermometer and the gauges:
/// dtemp is replaced by LP_τ[dtemp] (restarting per segment), τ found by grid + golden search on
/// the training rows (effects/thermal_zero_drift.cpp).
[[nodiscard]] std::optional<EffectFit> FitThermalZeroLagged(const Context& cx,
                                                            const Series& target);

/// The thermometer lag's declared range: 2 samples to a sixth of the record.
[[nodiscard]] std::vector<ParamSpec> ThermalLagSpecs(const Context& cx);
/// A claimed thermal_zero_drift or zero_drift refined to thermal_zero_drift with a thermometer lag
/// (FitThermalZeroLagged), or nullopt when the data has no temperature or the lag does not pay for
/// itself (the plain model wins): the RefineFn of both.
[[nodiscard]] std::optional<EffectFit> RefineWithThermalLag(const Context& cx,
                                                            const Series& target);

/// hysteresis as one rate-independent operator (Dahl or play, width searched) per bridge.
[[nodiscard]] std::optional<EffectFit> FitHysteresisOperator(const Context& cx,
                                                             const Series& target);
/// hysteresis in the load path: one operator (Dahl or play, width searched) or a
/// Prandtl–Ishlinskii sum of plays of fixed widths on each reference wrench axis, mapped to the
/// bridges by the sensitivity cx.sens (effects/hysteresis_load_path.cpp).
[[nodiscard]] std::optional<EffectFit> FitHysteresisAxes(const Context& cx, const Series& target);
/// hysteresis of general rate-independent shape: the one-operator fit or a Preisach superposition
/// of relays (thresholds on 8 quantiles of each bridge's load, weights fitted per bridge; this
/// class contains Prandtl–Ishlinskii sums of play operators), whichever has the lower training
/// BIC (effects/hysteresis.cpp).
[[nodiscard]] std::optional<EffectFit> FitHysteresisFamily(const Context& cx, const Series& target);
/// hysteresis refitted near an earlier fit (RefitFn): only the sub-family (load-path operators,
/// one operator per bridge, or Preisach per bridge) that fit came from.
[[nodiscard]] std::optional<EffectFit> RefitHysteresis(const Context& cx, const Series& target,
                                                       const EffectFit& near, bool uncertainty);

}  // namespace ftstack::diag

namespace ftstack::diag::fx {

/// The hysteresis families' evidence opening, on the channel that carries e->pred most: "at the
/// same load bC reads up to X mV/V differently depending on the load's past reversals (Z σ)";
/// sets e->channels (effects/hysteresis.cpp).
[[nodiscard]] std::string ReversalEvidence(const Context& cx, EffectFit* e);

/// The shortest creep time constant the data can show (3 samples, 0.2 s, 3 times the typical
/// excluded window of a lagging load change): the search's lower bound and the range's.
double CreepTauFloor(const Context& cx);

/// hysteresis' declared parameter: the operator width as a fraction of the load's travel.
std::vector<ParamSpec> HysteresisSpecs(const Context& cx);

std::optional<EffectFit> FitZeroOffset(const Context& cx, const Series& target);
std::optional<EffectFit> FitZeroDrift(const Context& cx, const Series& target);
std::optional<EffectFit> FitThermalZeroPlain(const Context& cx, const Series& target);
std::optional<EffectFit> FitThermalSpan(const Context& cx, const Series& target);
std::optional<EffectFit> FitExcitation(const Context& cx, const Series& target);
/// excitation_drift refitted near an earlier fit (RefitFn): near's knot count and its neighbours.
std::optional<EffectFit> RefitExcitation(const Context& cx, const Series& target,
                                         const EffectFit& near, bool uncertainty);
/// creep: the one-τ search on the full log grid (near == nullptr) or in a window of ±0.5 in log τ
/// around near's τ (τ1 when near is two-τ; the full range when the optimum lands on the window's
/// edge), then the two-τ variant: searched in full alone, from near's pair when near is two-τ,
/// not at all when near is one-τ (effects/creep.cpp).
std::optional<EffectFit> CreepSearch(const Context& cx, const Series& target, const EffectFit* near,
                                     bool uncertainty);
/// creep with two time constants τ1 < τ2 (effects/creep.cpp): τ2 searched with τ1 at the
/// one-τ optimum `log_tau1`, then τ1 and τ2 refined in turn; replaces *best (and fills tau,
/// tau_sigma, the channel fit and whether a gain term is in it) only when its training BIC is
/// below `best_bic`. Returns whether it did.
/// `start` (log τ1, log τ2), when given, replaces the coarse pair search and one refinement round
/// (a refit near an earlier two-τ fit).
bool FitCreepTwo(const Context& cx, const Series& target, double log_tau1, double best_bic,
                 EffectFit* best, std::vector<double>* tau, std::vector<double>* tau_sigma,
                 ChannelFit* best_f, bool* best_gamma, const double* start = nullptr,
                 bool uncertainty = true);
/// The fitted creep model (time constants tau, channel fit f with a_k per τ then γ when `gamma`)
/// in OIML R 60's terms: e->standard["oiml_r60"] (docs/spec/diagnosis.md).
void CreepOimlR60(const Context& cx, const std::vector<double>& tau,
                  const std::vector<double>& tau_sigma, const ChannelFit& f, bool gamma,
                  EffectFit* e);
std::optional<EffectFit> FitGainError(const Context& cx, const Series& target);
std::optional<EffectFit> FitBridgeNonlinearity(const Context& cx, const Series& target);
std::optional<EffectFit> FitGeometric(const Context& cx, const Series& target);
std::optional<EffectFit> FitLoadStiffening(const Context& cx, const Series& target);
std::optional<EffectFit> FitMisalignment(const Context& cx, const Series& target);
std::optional<EffectFit> FitTimeSkew(const Context& cx, const Series& target);
std::optional<EffectFit> FitSaturation(const Context& cx, const Series& target);
std::optional<EffectFit> FitOverloadShift(const Context& cx, const Series& target);
/// mains_interference: the best harmonic series of a supply among the residual's lines; none when
/// no line belongs to one (effects/mains_interference.cpp).
std::optional<EffectFit> FitMains(const Context& cx, const Series& target);
/// mains_interference's declared parameter: the supply's fundamental frequency.
std::vector<ParamSpec> MainsSpecs(const Context& cx);
/// resonance: LockedRingingSearch and RingingPerChange, the better kept (a mode on its search bound
/// loses, else the lower penalised training SSE); from near, only near's variant is refitted.
std::optional<EffectFit> ResonanceSearch(const Context& cx, const Series& target,
                                         const EffectFit* near, bool uncertainty);
/// resonance's modes rung by the reference's steps themselves: a coarse grid at the residual's
/// lines (a log grid without any) then golden refinements of (f, ζ), and the second-mode search
/// (near == nullptr); or the refinements only, from near's mode(s), a second mode only when near
/// has one (effects/resonance.cpp).
std::optional<EffectFit> LockedRingingSearch(const Context& cx, const Series& target,
                                             const EffectFit* near, bool uncertainty);
/// First rows of the stretches between load changes: every load change the conditioning found
/// (between holds of the reference) and every joined recording's first row; sorted, unique
/// (effects/ringing_per_change.cpp).
std::vector<int> LoadChangeStarts(const Context& cx);
/// zero_drift's variant name for a level per stretch between load changes.
inline constexpr const char* kZeroStepsAtChanges = "steps at load changes";
/// resonance's variant name for RingingPerChange.
inline constexpr const char* kRingingPerChange = "ringing per load change";
/// The declared parameters of resonance's variant kRingingPerChange: (f, ζ) from 3 periods of the
/// median stretch between load changes to 0.98 × Nyquist, ζ 1e-3 … 0.05.
std::vector<ParamSpec> RingingSpecs(const Context& cx);
/// resonance, variant kRingingPerChange (effects/ringing_per_change.cpp): a lightly damped mode
/// (ζ 1e-3 … 0.05) restarted at every load change the conditioning found with a free amplitude and
/// phase per change and channel (two decaying quadrature columns, linear given f and ζ); (f, ζ)
/// shared, searched from the residual's median-periodogram lines (or from near's) inside
/// RingingSpecs; a line resolved inside them preferred to one on a bound. nullopt without load
/// changes or lines.
std::optional<EffectFit> RingingPerChange(const Context& cx, const Series& target,
                                          const EffectFit* near, bool uncertainty);
/// The two-mode variant of a one-mode resonance fit *e at (f1_hz, zeta1) (effects/resonance.cpp):
/// mode 2 searched at the lines of the residual spectrum, both refined in
/// turn and fitted jointly (a participation per channel and mode); replaces *e (variant "two
/// modes", mode 1 the lower frequency) only when the training BIC is lower and the weaker mode
/// carries ≥ 1 % of the ringing's whitened energy. Returns a clause for the evidence.
/// `start` (log f2, log ζ2), when given, replaces the search at the residual's lines (a refit);
/// e->search_state gets (log f, log ζ) of mode 1 then mode 2 when the second mode is kept.
std::string AddResonanceMode(const Context& cx, const Series& target, double f1_hz, double zeta1,
                             EffectFit* e, const double* start = nullptr, bool uncertainty = true);

}  // namespace ftstack::diag::fx
