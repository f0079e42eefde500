// The skeleton of the effects' nonlinear parameter searches: a coarse grid of starting points, then
// golden rounds per parameter in log space inside the parameters' bounds. The effect supplies the
// objective (its whitened training SSE); a search ends on a bound only where the data push it
// there.
#pragma once

#include <functional>
#include <vector>

namespace ftstack::diag {

/// A parameter's search interval, in log of the parameter.
struct LogBounds {
  double lo = 0.0;
  double hi = 0.0;
};

/// The objective at a point given in log of every parameter.
using LogObjective = std::function<double(const std::vector<double>& log_x)>;

/// The point of `points` (each one log value per parameter) with the least finite objective, in
/// *best; returns that objective (+inf, *best untouched, when none is finite).
double BestPoint(const LogObjective& f, const std::vector<std::vector<double>>& points,
                 std::vector<double>* best);

/// Golden rounds from *x: for round = first … last − 1, before(round) (e.g. a finer row step),
/// then for each parameter j in turn a 5-point grid x_j + step_j·k/(round + 1), k = −2 … 2,
/// clamped to its bounds, refined by 7 golden steps with the other parameters held. The objective
/// is only evaluated inside the bounds, so a fit pushed outward ends exactly on one.
void GoldenRounds(const LogObjective& f, const std::vector<LogBounds>& bounds,
                  const std::vector<double>& step, int first, int last,
                  const std::function<void(int)>& before, std::vector<double>* x);

}  // namespace ftstack::diag
