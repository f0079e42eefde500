// The model choice of a calibration fit: the paired one-standard-error rule over candidates.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "calibration/fit/fit.hpp"

namespace ftstack::cal {

std::string CandidateName(const CandidateScore& c) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s lambda=%g", ToString(c.kind), c.lambda);
  return buf;
}

ChoiceMargin CompareCandidates(const CandidateScore& simpler, const CandidateScore& complex) {
  ChoiceMargin m;
  m.simpler = CandidateName(simpler);
  m.complex = CandidateName(complex);
  m.simpler_score = simpler.score;
  const std::size_t k = std::min(simpler.fold_score.size(), complex.fold_score.size());
  std::vector<double> d(k);
  for (std::size_t i = 0; i < k; ++i) d[i] = simpler.fold_score[i] - complex.fold_score[i];
  m.margin = std::accumulate(d.begin(), d.end(), 0.0);
  if (k >= 2) {
    const double mean = m.margin / static_cast<double>(k);
    double ss = 0.0;
    for (const double x : d) ss += (x - mean) * (x - mean);
    m.se = std::sqrt(static_cast<double>(k) * ss / static_cast<double>(k - 1));
  } else {
    m.se = std::numeric_limits<double>::infinity();  // one fold: no estimate of the spread
  }
  return m;
}

bool SimplerThan(const CandidateScore& a, const CandidateScore& b) {
  return a.features != b.features ? a.features < b.features : a.lambda < b.lambda;
}

std::size_t ChooseOneStandardError(const std::vector<CandidateScore>& candidates,
                                   ChoiceMargin* over_simplest, ChoiceMargin* challenger) {
  if (candidates.empty()) throw std::invalid_argument("no candidate model to choose from");
  // Ranks: candidates of equal complexity (same coefficients and λ, different families) share
  // one; the best-scoring of a rank stands for it.
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return SimplerThan(candidates[x], candidates[y]);
  });
  std::vector<std::size_t> reps;  // best of each rank, simplest rank first
  for (std::size_t i : order) {
    if (!reps.empty() && !SimplerThan(candidates[reps.back()], candidates[i])) {
      if (candidates[i].score < candidates[reps.back()].score) reps.back() = i;
    } else {
      reps.push_back(i);
    }
  }
  std::size_t chosen = reps.back();
  for (const std::size_t r : reps) {
    bool beaten = false;
    for (const CandidateScore& c : candidates) {
      if (SimplerThan(candidates[r], c) && CompareCandidates(candidates[r], c).Significant()) {
        beaten = true;
        break;
      }
    }
    if (!beaten) {
      chosen = r;
      break;
    }
  }
  *over_simplest = ChoiceMargin{};
  if (reps.front() != chosen)
    *over_simplest = CompareCandidates(candidates[reps.front()], candidates[chosen]);
  *challenger = ChoiceMargin{};
  double closest = -std::numeric_limits<double>::infinity();
  for (const CandidateScore& c : candidates) {
    if (!SimplerThan(candidates[chosen], c)) continue;
    const ChoiceMargin m = CompareCandidates(candidates[chosen], c);
    const double z = m.se > 0 ? m.margin / m.se : (m.margin > 0 ? 1e300 : -1e300);
    if (z > closest) {
      closest = z;
      *challenger = m;
    }
  }
  return chosen;
}

}  // namespace ftstack::cal
