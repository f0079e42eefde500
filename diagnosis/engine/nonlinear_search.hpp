// The skeleton of the effects' nonlinear parameter searches: a coarse grid of starting points, then
// golden rounds per parameter in log space inside the parameters' bounds. The effect supplies the
// objective (its whitened training SSE); a search ends on a bound only where the data push it
// there.
#pragma once

#include <functional>
#include <mutex>
#include <string>
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

/// One range an engine search covered, in value units: a one-parameter solve's declared key and
/// range (SolveParameter), or a joint search's coordinate bounds (GoldenRounds: key "").
struct SearchedRange {
  std::string key;
  double lo = 0.0;
  double hi = 0.0;
};

/// While one is alive, every engine search notes the range it covered here (one log at a time):
/// what lets a test walk the registry and see which effects search and inside which ranges.
class SearchLog {
 public:
  SearchLog();
  ~SearchLog();
  SearchLog(const SearchLog&) = delete;
  SearchLog& operator=(const SearchLog&) = delete;
  /// The ranges noted so far, in the order searched.
  [[nodiscard]] std::vector<SearchedRange> Ranges() const;
  /// Notes a search on the live log, if any (a relaxed atomic load otherwise).
  static void Note(const char* key, double lo, double hi);

 private:
  mutable std::mutex mutex_;
  std::vector<SearchedRange> ranges_;
};

}  // namespace ftstack::diag
