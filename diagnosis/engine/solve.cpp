#include "diagnosis/engine/solve.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "measurement/numerics.hpp"

namespace ftstack::diag {

const char* StatusName(ParamStatus s) {
  switch (s) {
    case ParamStatus::kResolved:
      return "resolved";
    case ParamStatus::kAtBound:
      return "at_bound";
    case ParamStatus::kPiecesDisagree:
      return "pieces_disagree";
    case ParamStatus::kNotIdentified:
      return "not_identified";
    case ParamStatus::kChosen:
      return "chosen";
  }
  return "not_identified";
}

double ToCoord(const ParamSpec& spec, double value) {
  return spec.scale == ParamScale::kLog ? std::log(value) : value;
}

double FromCoord(const ParamSpec& spec, double coord) {
  return spec.scale == ParamScale::kLog ? std::exp(coord) : coord;
}

std::vector<double> StartGrid(const ParamSpec& spec) {
  const double lo = ToCoord(spec, spec.lo);
  const double hi = ToCoord(spec, spec.hi);
  const int m = std::max(spec.grid_points, 2);
  std::vector<double> grid;
  for (int j = 0; j < m; ++j) grid.push_back(lo + (hi - lo) * j / (m - 1));
  return grid;
}

ParamStatus StatusOf(const ParamSpec& spec, double value) {
  if (!std::isfinite(value)) return ParamStatus::kNotIdentified;
  const bool log_scale = spec.lo > 0.0 && value > 0.0;
  const double below =
      log_scale ? std::log(value / spec.lo) : (value - spec.lo) / (spec.hi - spec.lo);
  const double above =
      log_scale ? std::log(spec.hi / value) : (spec.hi - value) / (spec.hi - spec.lo);
  return below < kOnBound || above < kOnBound ? ParamStatus::kAtBound : ParamStatus::kResolved;
}

double ProfileSigma(const Profile& f, double x, double h) {
  const double f0 = f(x);
  const double fp = f(x + h);
  const double fm = f(x - h);
  const double d2 = (fp - 2.0 * f0 + fm) / (h * h);
  return d2 > 0 ? std::sqrt(2.0 / d2) : std::numeric_limits<double>::quiet_NaN();
}

namespace {

/// σ in value units from σ in the search coordinate at `value`.
double ValueSigma(const ParamSpec& spec, double value, double coord_sigma) {
  return spec.scale == ParamScale::kLog ? value * coord_sigma : coord_sigma;
}

}  // namespace

SolvedParam SolveParameter(const ParamSpec& spec, const Profile& f, const SolveOptions& opt) {
  SearchLog::Note(spec.key, spec.lo, spec.hi);
  const std::vector<double> grid = opt.start.empty() ? StartGrid(spec) : opt.start;
  const int steps = opt.golden_steps >= 0 ? opt.golden_steps : spec.golden_steps;
  SolvedParam out;
  out.coord = numerics::MinimizeOnGrid(f, grid, steps, &out.objective);
  out.value = FromCoord(spec, out.coord);
  out.status = StatusOf(spec, out.value);
  if (opt.sigma_step > 0.0) {
    out.sigma = ValueSigma(spec, out.value, ProfileSigma(f, out.coord, opt.sigma_step));
    if (!std::isfinite(out.sigma) && out.status == ParamStatus::kResolved) {
      out.status = ParamStatus::kNotIdentified;
    }
  }
  return out;
}

double JointStart(const LogObjective& f, const std::vector<std::vector<double>>& points,
                  std::vector<double>* x) {
  return BestPoint(f, points, x);
}

std::vector<ParamStatus> JointRefine(const LogObjective& f, const std::vector<LogBounds>& bounds,
                                     const std::vector<double>& step, int first, int last,
                                     const std::function<void(int)>& before,
                                     std::vector<double>* x) {
  GoldenRounds(f, bounds, step, first, last, before, x);
  std::vector<ParamStatus> status;
  for (std::size_t j = 0; j < x->size(); ++j) {
    const double v = (*x)[j];
    const bool on = v <= bounds[j].lo + kOnBound || v >= bounds[j].hi - kOnBound;
    status.push_back(on ? ParamStatus::kAtBound : ParamStatus::kResolved);
  }
  return status;
}

std::vector<SolvedParam> SolveJoint(const LogObjective& f,
                                    const std::vector<std::vector<double>>& points,
                                    const std::vector<LogBounds>& bounds,
                                    const std::vector<double>& step, int first, int last,
                                    const std::function<void(int)>& before, double sigma_step) {
  std::vector<double> x;
  if (!std::isfinite(JointStart(f, points, &x))) return {};
  const std::vector<ParamStatus> status = JointRefine(f, bounds, step, first, last, before, &x);
  std::vector<SolvedParam> out(x.size());
  for (std::size_t j = 0; j < x.size(); ++j) {
    SolvedParam& s = out[j];
    s.coord = x[j];
    s.value = std::exp(x[j]);
    s.status = status[j];
    if (sigma_step > 0.0) {
      std::vector<double> at = x;
      const double cs = ProfileSigma(
          [&](double v) {
            at[j] = v;
            return f(at);
          },
          x[j], sigma_step);
      s.sigma = s.value * cs;
    }
  }
  return out;
}

}  // namespace ftstack::diag
