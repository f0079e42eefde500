// The engine's solve of an effect's declared nonlinear parameters: start grid, golden refinement
// inside the declared range, curvature σ and a status per parameter, one rule for every effect.
#pragma once

#include <functional>
#include <limits>
#include <utility>
#include <vector>

#include "diagnosis/engine/effect.hpp"
#include "diagnosis/engine/nonlinear_search.hpp"

namespace ftstack::diag {

/// Closeness to a bound that counts as "on" it: 2 % in log (positive ranges) or of the range.
inline constexpr double kOnBound = 0.02;

/// What the engine concludes about one fitted parameter.
enum class ParamStatus {
  kResolved,        ///< inside its range, off the bounds, with a finite σ where one was asked
  kAtBound,         ///< within kOnBound of a bound of its declared range, or outside it
  kPiecesDisagree,  ///< independent pieces of the record give it different signs or > 3 σ apart
  kNotIdentified,   ///< the profile is flat there (no finite curvature σ) or the value not finite
  kChosen,  ///< a count or label the fit chose (a model order, a tally), not a fitted number
};
/// The report's word for a status: "resolved", "at_bound", "pieces_disagree", "not_identified",
/// "chosen".
[[nodiscard]] const char* StatusName(ParamStatus s);

/// A value in spec's search coordinate (log of the value for ParamScale::kLog) and back.
[[nodiscard]] double ToCoord(const ParamSpec& spec, double value);
[[nodiscard]] double FromCoord(const ParamSpec& spec, double coord);
/// spec's start grid in its search coordinate: spec.grid_points points evenly over [lo, hi].
[[nodiscard]] std::vector<double> StartGrid(const ParamSpec& spec);
/// kAtBound when `value` is outside spec's range or within kOnBound of a bound, kNotIdentified
/// when it is not finite, else kResolved.
[[nodiscard]] ParamStatus StatusOf(const ParamSpec& spec, double value);

/// An effect's profile objective at one point of the search coordinate: the whitened training SSE
/// of its linear fit with the nonlinear parameter held there.
using Profile = std::function<double(double coord)>;

/// One solved parameter.
struct SolvedParam {
  double coord = 0.0;  ///< the optimum in the search coordinate
  double value = 0.0;  ///< the optimum, FromCoord(coord)
  double objective = std::numeric_limits<double>::infinity();  ///< the profile there
  double sigma = std::numeric_limits<double>::quiet_NaN();     ///< 1-σ of value; NaN: not asked
  ParamStatus status = ParamStatus::kResolved;
};

/// How one solve departs from its spec's defaults.
struct SolveOptions {
  /// Start grid in the search coordinate (e.g. centred on a closed-form estimate); empty:
  /// StartGrid(spec). Points outside the range are searched too: the status says so.
  std::vector<double> start = {};
  int golden_steps = -1;  ///< golden-section steps after the grid; −1: spec.golden_steps
  /// Step of the curvature σ in the search coordinate (Δχ² = 1 at one σ: the profile is a
  /// whitened SSE); 0: σ not computed (intermediate fits).
  double sigma_step = kOnBound;
};

/// Options that search exactly `start` with `golden_steps`, without σ (an intermediate search).
[[nodiscard]] inline SolveOptions GridOnly(std::vector<double> start, int golden_steps) {
  SolveOptions o;
  o.start = std::move(start);
  o.golden_steps = golden_steps;
  o.sigma_step = 0.0;
  return o;
}

/// The engine's solve of one parameter: the profile's least value on the start grid, refined by
/// golden steps, σ from the profile's curvature there (value units: value·σ_log on a log scale),
/// and its status against the declared range.
[[nodiscard]] SolvedParam SolveParameter(const ParamSpec& spec, const Profile& f,
                                         const SolveOptions& opt = {});

/// The engine's joint solve of several parameters (one coordinate each, in log): the least
/// objective over `points`, golden rounds first … last − 1 from there (GoldenRounds' contract,
/// `before(round)` e.g. a finer row step) inside `bounds`, then per parameter the curvature σ
/// (step `sigma_step`; 0: none) with the others held. Empty when no point is finite.
[[nodiscard]] std::vector<SolvedParam> SolveJoint(const LogObjective& f,
                                                  const std::vector<std::vector<double>>& points,
                                                  const std::vector<LogBounds>& bounds,
                                                  const std::vector<double>& step, int first,
                                                  int last, const std::function<void(int)>& before,
                                                  double sigma_step);

/// The first stage of a joint solve, for a family that sets its refinement from where it starts
/// (resonance's frequency step from ζ): the point of `points` with the least finite objective in
/// *x; returns that objective (+inf, *x untouched, when none is finite).
double JointStart(const LogObjective& f, const std::vector<std::vector<double>>& points,
                  std::vector<double>* x);
/// The second stage: golden rounds first … last − 1 from *x (GoldenRounds' contract) inside
/// `bounds`, then each coordinate's status (kAtBound within kOnBound of a bound, else kResolved).
std::vector<ParamStatus> JointRefine(const LogObjective& f, const std::vector<LogBounds>& bounds,
                                     const std::vector<double>& step, int first, int last,
                                     const std::function<void(int)>& before,
                                     std::vector<double>* x);

/// Curvature σ of a one-dimensional profile at x (Δχ² = 1): sqrt(2 / f''), NaN where f'' ≤ 0.
[[nodiscard]] double ProfileSigma(const Profile& f, double x, double h);

}  // namespace ftstack::diag
